"""The robot's URDF with the identified friction in ``<dynamics>``, and identified inertias if given.

Each exported joint gets ``<dynamics damping="F_v" friction="F_c"/>`` (:mod:`wbfriction.export.mapping`:
viscous [N·m·s/rad] and Coulomb [N·m] friction of model (3.5); the Stribeck bump, its tanh slope
and the offset tau_os have no URDF field), after a comment with its fit's status when it comes from a fit
(:func:`~wbfriction.export.mapping.status_note`; one written by an earlier export is replaced). URDF has no
armature field either: the armature is not written (MJCF and Isaac Lab hold it). The robot's other actuated joints
hold no friction, as in the MJCF: their ``<dynamics>``, where they have one, get ``damping="0.0" friction="0.0"``
(its other attributes kept; the URDF's values are its author's simulator settings, not measurements: TALOS's
1.0 N·m on 18 joints whatever the joint, the real KUKA LWR4+'s file negative frictions). Everything else is the
given URDF's: joints the robot does not actuate (fixed, locked) keep their ``<dynamics>``, comments and meshes
stay. Identified inertias go in through
:func:`wbfriction.inertia.urdf.write_urdf` (bodies merged by Pinocchio split back over their links).

Pinocchio reads the written file's ``<dynamics>`` into ``model.damping`` and ``model.friction``
(no algorithm of Pinocchio uses them); MuJoCo's URDF import into ``damping`` and ``frictionloss``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin
from lxml import etree as ET

from wbfriction.exceptions import InputError, OutputError
from wbfriction.export.catalog import URDF
from wbfriction.export.mapping import NOTE_PREFIX, FrictionLike, JointExport, joint_exports, status_note
from wbfriction.export.target import ExportReport, ExportTarget
from wbfriction.inertia.regressor import body_parameters
from wbfriction.inertia.urdf import write_urdf
from wbfriction.logs.tables import write_atomic
from wbfriction.model.mjspec import read_urdf
from wbfriction.model.robot import Robot

REQUIREMENT = "a .urdf export (the robot's URDF with <dynamics>)"
"""What a robot loaded from an MJCF is refused for (:meth:`Robot.require_urdf`)."""


def identified_parameters(robot: Robot, inertias: pin.Model) -> np.ndarray:
    """The body parameters (n_bodies, 10) of ``inertias``, a model of ``robot`` with identified
    inertias (e.g. :func:`wbfriction.inertia.regressor.with_body_parameters` of it).

    Raises:
        InputError: a model whose joints are not ``robot.model``'s.
    """
    if list(inertias.names) != list(robot.model.names):
        raise InputError(f"inertias: the model's joints are not those of robot '{robot.name}'")
    return body_parameters(inertias)


def set_dynamics(root: ET._Element, joints: Mapping[str, JointExport], others: Sequence[str] = ()) -> None:
    """Set ``<dynamics damping friction>`` of every joint of ``joints`` with friction (in place),
    after its other children for a joint that had none, with its :func:`status_note` as a comment
    before it (replacing one an earlier export wrote in that joint); ``others``, joints without exported friction
    (the robot's other actuated joints), get ``damping="0.0" friction="0.0"`` where they have ``<dynamics>`` (as the
    MJCF: no friction but the fitted one; their other attributes kept).

    Raises:
        InputError: a joint the URDF does not have.
    """
    elements = {j.get("name"): j for j in root.findall("joint")}
    for name in others:
        dyn = None if name in joints and joints[name].has_friction else elements.get(name)
        dyn = None if dyn is None else dyn.find("dynamics")
        if dyn is not None:
            for key in ("damping", "friction"):
                if key in dyn.attrib:
                    dyn.set(key, "0.0")
    for name, exp in joints.items():
        if not exp.has_friction:
            continue
        joint = elements.get(name)
        if joint is None:
            raise InputError(f"the URDF has no joint '{name}'")
        for old in [c for c in joint if c.tag is ET.Comment and (c.text or "").strip().startswith(NOTE_PREFIX)]:
            joint.remove(old)  # its tail (the indentation after it) goes with it
        dyn = joint.find("dynamics")
        if dyn is None:
            dyn = ET.SubElement(joint, "dynamics")
            previous = dyn.getprevious()
            if previous is not None:  # indented as the joint's other children
                dyn.tail, previous.tail = previous.tail, joint.text
        dyn.set("damping", repr(float(exp.viscous or 0.0)))
        dyn.set("friction", repr(float(exp.coulomb or 0.0)))
        note = status_note(exp)
        if note is not None:
            comment = ET.Comment(f" {note} ")
            previous = dyn.getprevious()
            comment.tail = previous.tail if previous is not None else joint.text  # indented as <dynamics>
            dyn.addprevious(comment)


def write_friction_urdf(robot: Robot, friction: Mapping[str, FrictionLike], path: str | Path,
                        armature: Mapping[str, float] | None = None,
                        inertias: pin.Model | None = None) -> tuple[str, ...]:
    """Write ``robot``'s URDF with the identified friction (module docstring), atomically.

    Args:
        robot: the robot (its :attr:`Robot.urdf` is the file rewritten).
        friction: joint -> fitted friction of model (3.5) (:func:`wbfriction.fit.params_file.read_params`).
        path: the URDF to write.
        armature: joint -> [kg·m^2]: only checked (URDF has no field for it).
        inertias: a model of ``robot`` with identified inertias, or None (the URDF's kept).

    Returns:
        what :func:`wbfriction.inertia.urdf.write_urdf` returns with ``inertias`` (the joints whose
        body went whole to the child link), else ().

    Raises:
        InputError: friction that is not dissipative, a joint the robot does not actuate, an
            inertia model of another robot, an unreadable URDF (or a robot loaded from an MJCF), an output
            folder that does not exist.
        OutputError: the system refused the write (a full disk, ``ulimit -f``:
            :func:`~wbfriction.logs.tables.write_atomic`), nothing written.
    """
    robot.require_urdf(REQUIREMENT)
    return write_dynamics(path, robot, joint_exports(friction, armature, robot), inertias)


def write_dynamics(path: str | Path, robot: Robot, joints: Mapping[str, JointExport],
                   inertias: pin.Model | None = None) -> tuple[str, ...]:
    """:func:`write_friction_urdf` of the joints' simulator parameters (joint -> :class:`JointExport`,
    :func:`~wbfriction.export.mapping.joint_exports`): same returns and errors."""
    robot.require_urdf(REQUIREMENT)
    pi = None if inertias is None else identified_parameters(robot, inertias)
    moved: tuple[str, ...] = ()

    def write(tmp: Path) -> None:
        nonlocal moved
        if pi is not None:
            try:
                moved = write_urdf(robot, pi, tmp)
            except OutputError as exc:  # refused beside ours: the same refusal, reported for the output named
                raise (OSError(exc.errno, exc.reason) if exc.errno is not None else OSError(exc.reason)) from exc
        tree = read_urdf(tmp if pi is not None else robot.urdf)
        set_dynamics(tree.getroot(), joints, robot.actuated)
        # serialised in memory, then written by Python: a refused write is the OSError write_atomic reports in one
        # line (lxml's own file writing raised its SerialisationError on a full disk, a traceback)
        tmp.write_bytes(ET.tostring(tree, xml_declaration=True, encoding="utf-8"))

    write_atomic(path, write)
    return moved


class UrdfTarget(ExportTarget, kind=URDF):
    """``.urdf``: the robot's URDF with ``<dynamics damping friction>`` (module docstring); a robot loaded from an
    MJCF is refused (:meth:`check`)."""


    def check(self, robot: Robot) -> None:
        """Refuse a robot loaded from an MJCF (it has no URDF to rewrite).

        Raises:
            InputError: a robot loaded from an MJCF.
        """
        robot.require_urdf(REQUIREMENT)

    def write(self, path: Path, robot: Robot, joints: Mapping[str, JointExport]) -> ExportReport:
        """:func:`write_dynamics` (the URDF's inertias kept)."""
        write_dynamics(path, robot, joints)
        return self.report(path, joints)
