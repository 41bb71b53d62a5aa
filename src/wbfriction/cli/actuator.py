"""``wbfriction identify --actuator pd``: what it parses, calls and prints."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Optional

from rich.markup import escape
from rich.table import Table

from wbfriction.actuator import ActuatorIdentification, ActuatorOptions, Identified
from wbfriction.cli.common import config_text, console, out, print_whole, robot_of, stages, warn
from wbfriction.exceptions import InputError
from wbfriction.logs.options import TimeUnit
from wbfriction.pipeline.paths import check_paths
from wbfriction.rigs import rig_for


def identify_pd(log: Path, robot: str, urdf: Optional[Path], config: Optional[Path], mjcf: Optional[Path],
                json_output: Optional[Path], config_output: Optional[Path], time_unit: Optional[TimeUnit],
                wide: bool, options: ActuatorOptions) -> None:
    """Identify the actuators, print them, write the JSON and the robot's TOML (:mod:`wbfriction.pipeline.
    actuator_step`)."""
    from wbfriction.pipeline.actuator_step import identify_actuator_file, write_actuator_config

    check_paths({"LOG": log, "--urdf": urdf, "--mjcf": mjcf, "--config": config},
                {"--json": json_output, "--config-output": config_output})
    r = robot_of(robot, urdf, config, mjcf)
    rig = rig_for(r, "pd")
    if not rig.identifies_actuators:
        raise InputError(f"--actuator pd: {rig.what(r, 'pd')}: its identification is the inertia model's and the "
                         "friction's ('identify' without --actuator pd)")
    with stages() as stage:
        stage("identifying the actuators")
        result = identify_actuator_file(r, log, json_output, options, time_unit)
    print_actuators(result, wide)
    warn(result.warnings)
    if json_output is not None:
        console.print(f"wrote {json_output}")
    if config_output is not None:
        text, folder = config_text(robot, config)
        write_actuator_config(text, folder, r.urdf, config_output, result)
        console.print(f"wrote {config_output}")


def _cell(x: Identified | None, scale: float = 1.0, digits: int = 3) -> str:
    if x is None:
        return "–"
    se = f" ±{x.se * scale:.{digits}f}" if x.se < 1e300 else " ±inf"
    text = f"{x.value * scale:.{digits}f}{se}"
    return text if x.status == "ok" else f"[dim]{text}[/] [yellow]{x.status}[/]"


def print_actuators(result: ActuatorIdentification, wide: bool = False) -> None:
    """The delay, then one row per joint: armature, F_c, F_v, offset, each with its standard error and status."""
    d = result.delay
    status = "" if d.status == "ok" else f" ({d.status}: {d.reason})"
    out.print(escape(f"delay {d.value * 1e3:.2f} ms ±{d.se * 1e3:.2f} (bound {d.crb * 1e3:.2f}), "
                     f"{d.value / result.period:.2f} periods of {result.period * 1e3:.3g} ms{status}"), highlight=False)
    out.print(escape(f"model: {result.velocity_reason}"), highlight=False)
    if result.clock:
        out.print(escape(f"clock: {result.clock}"), highlight=False)
    table = Table(*map(escape, ("joint", "armature [g·m²]", "F_c [N·m]", "F_v [N·m·s/rad]", "offset [mrad]",
                                "held-out / fitted")))
    for j in result.joints:
        ratio = f"{j.held_out_rms / j.rms:.2f}" if math.isfinite(j.held_out_rms) and j.rms > 0 else "–"
        table.add_row(j.joint, _cell(j.armature, 1e3, 2), _cell(j.F_c), _cell(j.F_v), _cell(j.offset, 1e3, 1), ratio)
    print_whole(table) if wide else out.print(table)
    reasons = [f"{j.joint}: {p.reason}" for j in result.joints for p in j.parameters().values() if p.reason]
    for line in reasons:
        out.print(escape(line), highlight=False)
    if result.written is not None:
        kept = [f"{v.joint} {v.kind}" if v.joint else v.kind for v in result.written.kept]
        if kept:
            out.print(escape("the TOML's own kept by --config-output (the identified value does not predict "
                             "held-out blocks of the log better, or the log does not tell it; the JSON's 'written' "
                             f"says which): {', '.join(kept)}"), highlight=False)
