"""Files in, files out: fitted friction (and armature) exported where simulators read them, in the
format each output's name says (:mod:`wbfriction.export`: the target of each suffix,
:func:`~wbfriction.export.registry.target_for`)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from wbfriction.choices import spoken
from wbfriction.exceptions import InputError
from wbfriction.export.drive import DEFAULT_PHYSICS_DT, DriveExport, drive_export
from wbfriction.export.mapping import FitSelection, joint_exports, select_fits
from wbfriction.export.registry import target_for, targets
from wbfriction.export.target import ExportOptions, ExportReport
from wbfriction.fit.params_file import read_robot_params
from wbfriction.model.robot import Robot


@dataclass(frozen=True)
class Exported:
    """What :func:`export_files` wrote: one report per output, in order
    (:class:`~wbfriction.export.target.ExportReport`), and which fits went into them
    (:class:`~wbfriction.export.mapping.FitSelection`: the joints left out, by status), and the robot's drivers as
    written (:class:`~wbfriction.export.drive.DriveExport`; None for a robot without PD-driven joints)."""

    reports: tuple[ExportReport, ...]
    selection: FitSelection
    drive: DriveExport | None = None

    @property
    def outputs(self) -> tuple[tuple[Path, str], ...]:
        """Each output written and the name of its format (``urdf``, ``mjcf``, ``isaac``), in order."""
        return tuple((report.path, report.target) for report in self.reports)


def export_files(robot: Robot, params: str | Path, outputs: Sequence[str | Path],
                 armature: Mapping[str, float] | None = None, include: Iterable[str] = (),
                 physics_dt: float = DEFAULT_PHYSICS_DT) -> Exported:
    """Write the fitted friction of ``params`` (``wbfriction fit``) for ``robot`` into each output,
    in the format its suffix names (:func:`~wbfriction.export.registry.target_for`); the robot's inertias are
    its URDF's (give an identified URDF to export identified inertias) and its armature the robot model's unless
    ``armature`` is given. A robot with PD-driven joints (:attr:`Robot.pd`) gets its drivers too (gains, torque
    limits, delay, encoder offsets, the fits' constant torques as set-point offsets: :mod:`wbfriction.export.drive`),
    the delay counted in physics steps of ``physics_dt`` [s] where a format counts it so (Isaac Lab); each report's
    warnings say what was rounded.

    Only fits whose status is ``ok`` are exported, and those ``include`` names (``weak``, ``at-bound``;
    :func:`~wbfriction.export.mapping.select_fits`); the other actuated joints hold no friction (a URDF's
    ``<dynamics>`` set to 0 in the ``.urdf``, none in the ``.xml``; an MJCF model file's own values kept).
    Every output name and the parameters are checked before anything is written; each file is written whole
    or not at all.

    Raises:
        InputError: a ``physics_dt`` that is not > 0, an unknown suffix
            (:class:`~wbfriction.export.registry.UnknownExportFormat`), a .urdf output
            for a robot loaded from an MJCF, unreadable parameters, parameters fitted for another robot
            (:func:`~wbfriction.fit.params_file.read_robot_params`), parameters without joints or without a fit
            that qualifies, an unknown ``include`` choice, friction that is not dissipative
            (:mod:`wbfriction.export.mapping`), a joint the robot does not actuate; for a .yaml output of a robot
            with PD-driven joints, exported friction of a joint that is not PD-driven.
    """
    if not outputs:
        names = spoken(tuple(target.suffixes[0] for target in targets()))
        raise InputError(f"export: give at least one output (-o FILE{names})")
    options = ExportOptions(physics_dt)
    chosen = [target_for(path).configure(options) for path in outputs]
    for target in {id(t): t for t in chosen}.values():
        target.check(robot)
    fits = read_robot_params(params, robot.name, robot.actuated, robot.urdf)
    selection = select_fits(fits, robot, include, str(params))
    joints = {name: replace(exp, instead=selection.instead_note(name))
              for name, exp in joint_exports(selection.exported, armature, robot).items()}
    reports = tuple(target.write(Path(path), robot, joints) for path, target in zip(outputs, chosen))
    return Exported(reports, selection, drive_export(robot, joints))
