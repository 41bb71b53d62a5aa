"""``wbfriction identify --actuator pd``: a hung PD-driven robot's actuators from a log file, written as JSON and as
the robot's TOML for the model identified (:mod:`wbfriction.actuator`)."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import Any

from wbfriction.actuator import ActuatorIdentification, ActuatorOptions, identify_actuators
from wbfriction.exceptions import InputError
from wbfriction.logs.options import ReadOptions, TimeUnit
from wbfriction.logs.source import read_log
from wbfriction.logs.tables import json_text, write_atomic
from wbfriction.logs.torque import torque_kind
from wbfriction.model.robot import Robot
from wbfriction.pipeline.identify_step import identified_config
from wbfriction.pipeline.paths import check_paths


def identify_actuator_file(robot: Robot, log: str | Path, json_output: str | Path | None = None,
                           options: ActuatorOptions = ActuatorOptions(), time_unit: TimeUnit | None = None
                           ) -> ActuatorIdentification:
    """Identify the actuators of ``robot`` from the log file ``log`` and write the JSON (``to_dict``) to
    ``json_output`` whole or not at all; paths checked before the work.

    Raises:
        InputError: an unreadable or invalid log, an output that cannot be written or is the log, what
            :func:`~wbfriction.actuator.identification.identify_actuators` raises.
    """
    check_paths({"log": Path(log)}, {"json_output": None if json_output is None else Path(json_output)})
    data = read_log(log, robot, read=ReadOptions(time_unit=time_unit))
    result = identify_actuators(robot, data, options)
    if json_output is not None:
        text = json_text(result.to_dict(), indent=1, sort_keys=True) + "\n"  # a value not finite: null
        write_atomic(Path(json_output), lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return result


def written_values(result: ActuatorIdentification) -> tuple[dict[str, float], dict[str, float], float | None]:
    """The armature [kg·m²] and encoder offsets [rad] by joint, and the delay [s] (None: the TOML's kept), that
    ``--config-output`` writes from the identification: each chosen against the robot TOML's own on held-out blocks
    of the log (:attr:`~wbfriction.actuator.identification.ActuatorIdentification.written`,
    :mod:`wbfriction.actuator.written`); nothing for a result without that choice, or whose delay lies beyond the
    search."""
    choice = result.written
    if choice is None:
        return {}, {}, None
    return choice.of("armature"), choice.of("offset"), choice.written_delay


def actuator_config(text: str, source_dir: Path, urdf: Path, output: Path, result: ActuatorIdentification) -> str:
    """The robot's configuration (TOML ``text`` read from ``source_dir``) with the identified actuators
    (:func:`written_values`): its ``[armature]`` and ``[encoder_offset]`` tables merged with them, its ``[pd]``
    ``delay`` set; every other line as it was, paths made relative to ``output``.

    Raises:
        InputError: a configuration that does not read back as the one intended (tables as inline tables or
            dotted keys), naming ``output``.
    """
    armature, offsets, delay = written_values(result)
    given = tomllib.loads(text)
    merged_armature = {**given.get("armature", {}), **armature}
    merged = identified_config(text, source_dir, urdf, output, merged_armature or None).replace(
        "identified by wbfriction identify --armature identify", "identified by wbfriction identify --actuator pd")
    lines, skipping, in_pd = [], False, False
    for line in merged.splitlines():
        header = re.match(r"\s*\[([^\]]+)\]", line)
        if header:
            skipping = header.group(1).strip() == "encoder_offset"
            in_pd = header.group(1).strip() == "pd"
        if skipping or (in_pd and delay is not None and re.match(r"\s*delay\s*=", line)):
            continue
        lines.append(line)
        if in_pd and delay is not None and re.match(r"\s*delayed(_known)?\s*=", line):
            lines.pop()
        if header and in_pd and delay is not None:
            lines.append(f"delay = {delay!r}   # identified by wbfriction identify --actuator pd [s]")
            if result.options.delayed != "auto":
                lines.append(f'delayed = "{result.options.delayed}"   # what the delay holds back (identified)')
            if not result.delayed_known:
                lines.append("delayed_known = false   # the log closes the balance as well with the other: the "
                             "friction's F_v is known only to within kp delay")
    offsets = {**given.get("encoder_offset", {}), **offsets}
    if offsets:
        lines += ["", "[encoder_offset]   # identified by wbfriction identify --actuator pd [rad]"]
        lines += [f"{joint} = {value!r}" + _status_comment(result, joint, "offset") for joint, value in offsets.items()]
    written = "\n".join(lines) + "\n"
    expected: dict[str, Any] = tomllib.loads(merged)
    if offsets:
        expected["encoder_offset"] = offsets
    if delay is not None:
        expected.setdefault("pd", {})["delay"] = delay
        if result.options.delayed != "auto":
            expected["pd"]["delayed"] = result.options.delayed
        expected["pd"].pop("delayed_known", None)
        if not result.delayed_known:
            expected["pd"]["delayed_known"] = False
    if tomllib.loads(written) != expected:
        raise InputError(f"{output}: the robot's configuration could not be rewritten line by line (its [pd] or "
                         "[encoder_offset] is not a plain table): copy the values printed into it instead")
    return written


def _status_comment(result: ActuatorIdentification, joint: str, kind: str) -> str:
    """`` # <status>: <reason>`` of an identified value written that is not ``ok`` ("" otherwise, or where the TOML's
    own is kept): a value written because it predicts better is not called good."""
    choice = result.written
    if choice is None or joint not in choice.of(kind) or joint not in [j.joint for j in result.joints]:
        return ""
    p = result.joint(joint).parameters().get(kind)
    if p is None or p.status == "ok":
        return ""
    return f"   # {p.status}: {p.reason}; written as it predicts held-out blocks of the log better than the TOML's"


def write_actuator_config(text: str, source_dir: Path, urdf: Path, output: str | Path,
                          result: ActuatorIdentification) -> None:
    """Write :func:`actuator_config` to ``output``, whole or not at all.

    Raises:
        InputError: what :func:`actuator_config` raises.
        OutputError: the system refused the write.
    """
    output = Path(output)
    written = actuator_config(text, source_dir, urdf, output, result)
    write_atomic(output, lambda tmp: tmp.write_text(written, encoding="utf-8"))


LAW_CHECK_SECONDS = 20.0
"""The first seconds of a log on which ``estimate`` checks the robot TOML's PD law (:func:`pd_law_warnings`): a
hung robot's ramps reverse every 0.2-2 s, so 20 s hold tens of reversals, and the check costs a second or two."""


def pd_law_warnings(robot: Robot, log: str | Path, time_unit: TimeUnit | None = None) -> list[str]:
    """The robot TOML's PD law against the first :data:`LAW_CHECK_SECONDS` of the log file ``log`` of a hung
    PD-driven robot whose torque is the PD law's (:mod:`wbfriction.actuator.law_check`: its delay and gains against
    what the log shows; a delay beyond the search), one warning line each; none where the check does not apply (a
    floating base, no ``[pd]``, a measured torque, a log the identification refuses)."""
    if robot.pd is None or robot.floating_base:
        return []
    data = read_log(log, robot, read=ReadOptions(time_unit=time_unit))
    if not torque_kind(data.torque_source).pd_law:
        return []
    import numpy as np

    stop = int(np.searchsorted(data.time - data.time[0], LAW_CHECK_SECONDS))
    # the positions' velocity and the TOML's delayed: one identification, not identify's two to four
    options = ActuatorOptions(holdout=0.0, velocity="positions", delayed=robot.pd.delayed)
    try:
        result = identify_actuators(robot, data.rows(0, stop) if stop < len(data.time) else data, options)
    except InputError:
        return []
    return list(result.warnings)
