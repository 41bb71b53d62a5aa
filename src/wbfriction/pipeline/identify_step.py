"""Files in, files out: a log's inertia model and friction identified together (the closed loop of
:func:`wbfriction.inertia.closed_loop.identify`), the corrected URDF and the identification JSON written.

A URDF has no place for the drives' rotor inertia: an identified armature is in the JSON and in
:attr:`IdentifiedFile.armature`, as the ``[armature]`` table of the robot's TOML would hold it, and
:func:`identified_config` writes the robot's configuration with it and the corrected URDF (``identify
--config-output``), the one file a later ``estimate --config`` needs."""

from __future__ import annotations

import os
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from wbfriction.exceptions import InputError
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.closed_loop import ClosedLoop, identify
from wbfriction.inertia.document import Identification
from wbfriction.inertia.io import identification_of, write_identification
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.urdf import write_urdf
from wbfriction.logs.clock import TimeUnit
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.source import read_log
from wbfriction.logs.tables import write_atomic
from wbfriction.model.robot import Robot
from wbfriction.pipeline.paths import check_paths
from wbfriction.pipeline.provenance import log_provenance
from wbfriction.progress import StageProgress, Steps


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


def rotor_inertia_notes(robot: Robot, log: str | Path, options: InertialOptions) -> tuple[str, ...]:
    """What :func:`identify_file` says before the work of a log whose torques come from the motors' currents on a
    robot without ``[armature]`` (:func:`~wbfriction.logs.torque.rotor_inertia_warnings`, from the log's column names
    alone): one line, unless the armature is identified (``options.armature = "identify"``); () for a log whose
    columns cannot be read here (a bag: :func:`identify_file` reads it, and refuses what it must)."""
    from wbfriction.logs.tables import TableFile
    from wbfriction.logs.torque import rotor_inertia_warnings

    if options.armature == "identify":
        return ()
    try:
        names = set(TableFile(Path(log)).schema().names)
    except (InputError, OSError, ValueError):
        return ()
    return rotor_inertia_warnings(robot, names, str(log))


def identify_file(robot: Robot, log: str | Path, urdf_output: str | Path, json_output: str | Path | None = None, *,
                  estimate_options: EstimateOptions = EstimateOptions(), options: InertialOptions = InertialOptions(),
                  stribeck: float | Literal["auto"] | None = "auto", passes: int = 2,
                  progress: StageProgress | None = None, workers: int = 1,
                  time_unit: TimeUnit | None = None, steps: Steps | None = None) -> IdentifiedFile:
    """Identify the inertia model and the friction of ``robot`` from a log file (the closed loop,
    :func:`~wbfriction.inertia.closed_loop.identify`), write the corrected URDF to ``urdf_output``
    and, if given, the identification JSON to ``json_output``, each whole or not at all; the
    outputs are checked before the work (:func:`~wbfriction.pipeline.paths.check_paths`).
    ``time_unit``: the unit of a numeric time column (:func:`~wbfriction.logs.source.read_log`); ``progress`` and
    ``steps``: told of the loop's stages (:func:`~wbfriction.inertia.closed_loop.identify`).

    Raises:
        InputError: an output that cannot be written or is the log, an unreadable or invalid
            log, what the identification raises.
    """
    check_paths({"log": Path(log)}, {"urdf_output": Path(urdf_output),
                                     "json_output": None if json_output is None else Path(json_output)})
    data = read_log(log, robot, read=ReadOptions(time_unit=time_unit))
    loop = identify(robot, data, estimate_options, options, stribeck, passes, progress=progress, workers=workers,
                    steps=steps)
    moved = write_urdf(robot, loop.final.identification.pi, urdf_output)
    result = identification_of(loop, moved, log_provenance(log, robot))
    if json_output is not None:
        write_identification(json_output, result)
    ident = loop.final.identification
    armature = (dict(zip(robot.torque_controlled, map(float, ident.armature)))
                if ident.armature_mode == "identify" else None)
    return IdentifiedFile(loop, result, moved, armature)


MOVED_PATHS = ("srdf",)
"""Keys of a robot TOML that name a file relative to the TOML: rewritten relative to the configuration written."""


def identified_config(text: str, source_dir: Path, urdf: Path, output: Path,
                      armature: dict[str, float] | None) -> str:
    """A robot configuration (TOML ``text``, read from the folder ``source_dir``) rewritten for an identified model:
    its ``urdf`` (or ``mjcf``) key replaced by ``urdf`` (relative to ``output``'s folder), its ``[armature]`` table
    by ``armature`` (kept as it is when None), the paths of :data:`MOVED_PATHS` made relative to ``output``'s folder;
    every other line, comments included, as it was.

    Raises:
        InputError: a configuration whose rewriting does not read back as the same configuration (an armature
            given as dotted keys or an inline table, say), naming ``output``.
    """
    here = output.parent.resolve()

    def relative(path: Path) -> str:
        return Path(os.path.relpath(path.resolve(), here)).as_posix()

    lines: list[str] = []
    skipping = False
    for line in text.splitlines():
        header = re.match(r"\s*\[([^\]]+)\]", line)
        if header:
            skipping = armature is not None and header.group(1).strip() == "armature"
        if skipping or (not header and re.match(r"\s*(urdf|mjcf)\s*=", line) and not _in_table(lines)):
            continue
        path_key = re.match(r"\s*(\w+)\s*=\s*\"([^\"]*)\"", line)
        if path_key and path_key.group(1) in MOVED_PATHS and not _in_table(lines) and ":" not in path_key.group(2):
            line = f'{path_key.group(1)} = "{relative(source_dir / path_key.group(2))}"'
        lines.append(line)
    out = [f'urdf = "{relative(urdf)}"   # the identified model (wbfriction identify)'] + lines
    if armature is not None:
        out += ["", "[armature]   # identified by wbfriction identify --armature identify [kg·m^2]"]
        out += [f"{joint} = {value!r}" for joint, value in armature.items()]
    written = "\n".join(out) + "\n"
    expected: dict[str, Any] = {k: v for k, v in tomllib.loads(text).items() if k not in ("urdf", "mjcf")}
    expected["urdf"] = relative(urdf)
    if armature is not None:
        expected["armature"] = dict(armature)
    for name in MOVED_PATHS:
        if isinstance(expected.get(name), str) and ":" not in expected[name]:
            expected[name] = relative(source_dir / expected[name])
    try:
        same = tomllib.loads(written) == expected
    except tomllib.TOMLDecodeError:
        same = False
    if not same:
        raise InputError(f"{output}: the robot's configuration could not be rewritten line by line (its [armature] "
                         "or urdf is not a plain table or key): copy the [armature] table printed into it instead")
    return written


def _in_table(lines: list[str]) -> bool:
    """Whether the lines so far opened a table (a key after them is the table's, not top-level)."""
    return any(re.match(r"\s*\[", line) for line in lines)


def write_identified_config(text: str, source_dir: Path, urdf: Path, output: str | Path,
                            armature: dict[str, float] | None) -> None:
    """Write :func:`identified_config` to ``output``, whole or not at all.

    Raises:
        InputError: what :func:`identified_config` raises.
        OutputError: the system refused the write.
    """
    output = Path(output)
    written = identified_config(text, source_dir, urdf, output, armature)
    write_atomic(output, lambda tmp: tmp.write_text(written, encoding="utf-8"))
