"""Files in, files out: fitted friction (and armature) exported where simulators read them, in the
format each output's name says (:mod:`wbfriction.export`)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from wbfriction.exceptions import InputError
from wbfriction.export.isaac import write_isaac_yaml
from wbfriction.export.mapping import FitSelection, select_fits
from wbfriction.export.mjcf import write_mjcf
from wbfriction.export.urdf import write_friction_urdf
from wbfriction.fit.params_file import read_params
from wbfriction.model.robot import Robot

ExportFormat = Literal["urdf", "mjcf", "isaac"]
"""What an export is: a URDF with ``<dynamics>``, a MuJoCo MJCF, an Isaac Lab actuator YAML."""
SUFFIXES: dict[str, ExportFormat] = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf", ".yaml": "isaac",
                                     ".yml": "isaac"}


def export_format(path: str | Path) -> ExportFormat:
    """The format an output's suffix names (:data:`SUFFIXES`).

    Raises:
        InputError: another suffix, naming the file.
    """
    fmt = SUFFIXES.get(Path(path).suffix.lower())
    if fmt is None:
        raise InputError(f"{path}: unknown export format: name it .urdf (URDF <dynamics>), .xml (MuJoCo MJCF) "
                         "or .yaml (Isaac Lab actuators)")
    return fmt


@dataclass(frozen=True)
class Exported:
    """What :func:`export_files` wrote: the outputs and their formats, in order, and which fits went into
    them (:class:`~wbfriction.export.mapping.FitSelection`: the joints left out, by status)."""

    outputs: tuple[tuple[Path, ExportFormat], ...]
    selection: FitSelection


def export_files(robot: Robot, params: str | Path, outputs: Sequence[str | Path],
                 armature: Mapping[str, float] | None = None, include: Iterable[str] = ()) -> Exported:
    """Write the fitted friction of ``params`` (``wbfriction fit``) for ``robot`` into each output,
    in the format its suffix names; the robot's inertias are its URDF's (give an identified URDF
    to export identified inertias) and its armature the robot model's unless ``armature`` is given.

    Only fits whose status is ``ok`` are exported, and those ``include`` names (``weak``, ``at-bound``;
    :func:`~wbfriction.export.mapping.select_fits`); the other joints keep what the robot's model file has.
    Every output name and the parameters are checked before anything is written; each file is written whole
    or not at all.

    Raises:
        InputError: an unknown suffix, a .urdf output for a robot loaded from an MJCF, unreadable parameters,
            parameters without joints or without a fit that qualifies, an unknown ``include`` choice,
            friction that is not dissipative (:mod:`wbfriction.export.mapping`), a joint the robot does not actuate.
    """
    if not outputs:
        raise InputError("export: give at least one output (-o FILE.urdf, .xml or .yaml)")
    formats = [export_format(p) for p in outputs]
    if "urdf" in formats:
        robot.require_urdf("a .urdf export (the robot's URDF with <dynamics>)")
    selection = select_fits(read_params(params), robot, include, str(params))
    friction = selection.exported
    done = []
    for path, fmt in zip(outputs, formats):
        if fmt == "urdf":
            write_friction_urdf(robot, friction, path, armature)
        elif fmt == "mjcf":
            write_mjcf(robot, friction, path, armature)
        else:
            write_isaac_yaml(path, friction, armature, robot)
        done.append((Path(path), fmt))
    return Exported(tuple(done), selection)
