"""Files in, files out: a log's inertia model and friction identified together (the closed loop of
:func:`wbfriction.inertia.closed_loop.identify`), the corrected URDF and the identification JSON written.

A URDF has no place for the drives' rotor inertia: an identified armature is in the JSON and in
:attr:`IdentifiedFile.armature`, as the ``[armature]`` table of the robot's TOML would hold it."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.closed_loop import ClosedLoop, identify
from wbfriction.inertia.document import Identification
from wbfriction.inertia.io import identification_of, write_identification
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.urdf import write_urdf
from wbfriction.logs.clock import TimeUnit
from wbfriction.logs.source import read_log
from wbfriction.model.robot import Robot
from wbfriction.pipeline.paths import check_paths
from wbfriction.pipeline.provenance import log_provenance
from wbfriction.progress import StageProgress


@dataclass
class IdentifiedFile:
    """What :func:`identify_file` did.

    Attributes:
        loop: the closed loop's routes and passes.
        identification: the typed result, the JSON's content (:func:`~wbfriction.inertia.io.identification_of`).
        moved: the joints whose whole identified body went to their child link
            (:func:`~wbfriction.inertia.urdf.write_urdf`).
        armature: with ``options.armature = "identify"``, the identified armature per
            torque-controlled joint [kg·m^2] (the robot TOML's ``[armature]``); else None.
    """

    loop: ClosedLoop
    identification: Identification
    moved: tuple[str, ...]
    armature: dict[str, float] | None = None

    def armature_toml(self) -> str | None:
        """The identified armature as a TOML ``[armature]`` table (None if it was not identified)."""
        if self.armature is None:
            return None
        return "[armature]\n" + "".join(f"{joint} = {value!r}\n" for joint, value in self.armature.items())


def identify_file(robot: Robot, log: str | Path, urdf_output: str | Path, json_output: str | Path | None = None, *,
                  estimate_options: EstimateOptions = EstimateOptions(), options: InertialOptions = InertialOptions(),
                  stribeck: float | Literal["auto"] | None = "auto", passes: int = 2,
                  progress: StageProgress | None = None, workers: int = 1,
                  time_unit: TimeUnit | None = None) -> IdentifiedFile:
    """Identify the inertia model and the friction of ``robot`` from a log file (the closed loop,
    :func:`~wbfriction.inertia.closed_loop.identify`), write the corrected URDF to ``urdf_output``
    and, if given, the identification JSON to ``json_output``, each whole or not at all; the
    outputs are checked before the work (:func:`~wbfriction.pipeline.paths.check_paths`).
    ``time_unit``: the unit of a numeric time column (:func:`~wbfriction.logs.source.read_log`).

    Raises:
        InputError: an output that cannot be written or is the log, an unreadable or invalid
            log, what the identification raises.
    """
    check_paths({"log": Path(log)}, {"urdf_output": Path(urdf_output),
                                     "json_output": None if json_output is None else Path(json_output)})
    data = read_log(log, robot, time_unit=time_unit)
    loop = identify(robot, data, estimate_options, options, stribeck, passes, progress=progress, workers=workers)
    moved = write_urdf(robot, loop.final.identification.pi, urdf_output)
    result = identification_of(loop, moved, log_provenance(log, robot))
    if json_output is not None:
        write_identification(json_output, result)
    ident = loop.final.identification
    armature = (dict(zip(robot.torque_controlled, map(float, ident.armature)))
                if ident.armature_mode == "identify" else None)
    return IdentifiedFile(loop, result, moved, armature)
