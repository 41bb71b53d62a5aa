"""Files in, files out: fitted friction (and armature) exported where simulators read them, in the
format each output's name says (:mod:`wbfriction.export`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Literal

from wbfriction.exceptions import InputError
from wbfriction.export.isaac import write_isaac_yaml
from wbfriction.export.mjcf import write_mjcf
from wbfriction.export.urdf import write_friction_urdf
from wbfriction.friction.io import read_params
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


def export_files(robot: Robot, params: str | Path, outputs: Sequence[str | Path],
                 armature: Mapping[str, float] | None = None) -> list[tuple[Path, ExportFormat]]:
    """Write the fitted friction of ``params`` (``wbfriction fit``) for ``robot`` into each output,
    in the format its suffix names; the robot's inertias are its URDF's (give an identified URDF
    to export identified inertias) and its armature the robot model's unless ``armature`` is given.

    Every output name is checked before anything is written; each file is written whole or not at all.

    Returns:
        the outputs and their formats, in order.

    Raises:
        InputError: an unknown suffix, a .urdf output for a robot loaded from an MJCF, unreadable parameters,
            friction that is not dissipative (:mod:`wbfriction.export.mapping`), a joint the robot does not actuate.
    """
    if not outputs:
        raise InputError("export: give at least one output (-o FILE.urdf, .xml or .yaml)")
    formats = [export_format(p) for p in outputs]
    if "urdf" in formats:
        robot.require_urdf("a .urdf export (the robot's URDF with <dynamics>)")
    fits = read_params(params)
    friction = {j: f for j, f in fits.items() if f.params is not None}
    done = []
    for path, fmt in zip(outputs, formats):
        if fmt == "urdf":
            write_friction_urdf(robot, friction, path, armature)
        elif fmt == "mjcf":
            write_mjcf(robot, friction, path, armature)
        else:
            write_isaac_yaml(path, friction, armature, robot)
        done.append((Path(path), fmt))
    return done
