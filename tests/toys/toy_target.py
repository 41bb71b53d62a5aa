"""A toy export target, one file: a CSV of each exported joint's Coulomb and viscous friction."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from wbfriction.export.mapping import JointExport
from wbfriction.export.target import ExportReport, ExportTarget
from wbfriction.logs.tables import write_atomic
from wbfriction.model.robot import Robot


class FrictionCsv(ExportTarget):
    """``joint,F_c,F_v`` [N·m, N·m·s/rad], one row per joint whose friction is exported."""

    name = "friction-csv"
    suffixes = (".csv",)
    description = "joint, F_c, F_v"

    def write(self, path: Path, robot: Robot, joints: Mapping[str, JointExport]) -> ExportReport:
        rows = [f"{n},{e.coulomb!r},{e.viscous!r}\n" for n, e in joints.items() if e.has_friction]
        write_atomic(path, lambda tmp: tmp.write_text("joint,F_c,F_v\n" + "".join(rows)))
        return self.report(path, joints)
