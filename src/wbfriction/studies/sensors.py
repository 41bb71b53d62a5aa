"""The sensors a humanoid carries, on MuJoCo (issue 23): ``wbfriction study-sensors``.

The combined walk on MuJoCo's soft contacts, Table 6.1 friction (3.5) on every leg joint, sensor noise
off (``--noise``: the studies' sensor noise in the loop), the ankle force-torque sensors and the base pose
logged. Each leg joint's model is fitted twice per closure of the base's equations, on its swing samples (its
foot in the air) and, separately, on its stance samples (its foot on the ground):

* ``contact``: the thesis's (rigid stance contact, swing-only single support), as in Table 6.2;
* ``wrench``: the ankle wrenches and the logged base (:mod:`wbfriction.friction.measured`).

Both by the route ``route`` (``auto``: the momentum route where the positions are noisy, issue 38); each fit
carries its Cramér-Rao bound and its status, so that an error is read against what the walk allows.

A joint pressed against its URDF position limit receives the stop's torque, which no friction model has:
the samples where a leg joint is within :data:`AT_LIMIT` of a limit are left out and counted (the
combined walk's reference takes the right hip roll 0.0175 rad beyond its limit, and MuJoCo holds it there).
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import FrictionEstimate, estimate_log
from wbfriction.friction.options import EstimateOptions, RouteOption
from wbfriction.logs.log import Log, write_log
from wbfriction.logs.tables import make_folder, write_atomic
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress
from wbfriction.signals.options import Diff, FilterOptions
from wbfriction.sim import simulate_mujoco
from wbfriction.sim.options import MujocoOptions, SensorNoise
from wbfriction.studies.common import LegJoint, fit_legs, leg_joints
from wbfriction.studies.thesis import TABLE_6_2
from wbfriction.walking import walking_reference
from wbfriction.walking.options import GaitOptions

SUBSTEPS = 16
"""MuJoCo physics steps per control period in this study. The simulator applies friction (3.5) from each
step's starting velocity, half a step behind the motion: at the simulator's default 4 steps per 1 ms period
that lag (0.125 ms), across the tanh's slope ``a F_c`` at the velocity reversals, moved the barely moving hip
yaws' fitted F_v by 8.6 % (right, swing) and 7.3 % (left, stance); at 16 steps, 4.3 and 1.8 % (measured). It is
the simulator's discretisation, not the estimator's: a real joint's friction has no such lag."""
AT_LIMIT = 1e-3
"""How close to a URDF position limit a leg joint's sample is left out [rad]."""
SCORED = ("F_c", "F_v", "tau_os")
"""The parameters the study scores."""


@dataclass(frozen=True)
class SensorsRow:
    """One leg joint: its error [%] per parameter of :data:`SCORED` and its samples, per route and part.

    Attributes:
        joint, side, group: the leg joint.
        errors: ``(route, part) -> {parameter: |error| [%]}``, ``part`` ``swing`` or ``stance``.
        samples: ``(route, part) -> samples fitted``.
        usable: ``route -> share of the walk's samples with a valid estimate``.
        bounds: ``(route, part) -> {parameter: Cramér-Rao standard deviation [% of the true value]}`` (NaN:
            no bound).
        statuses: ``(route, part) -> the fit's status``.
    """

    joint: str
    side: str
    group: str
    errors: dict[tuple[str, str], dict[str, float]]
    samples: dict[tuple[str, str], int]
    usable: dict[str, float]
    bounds: dict[tuple[str, str], dict[str, float]] = dataclasses.field(default_factory=dict)
    statuses: dict[tuple[str, str], str] = dataclasses.field(default_factory=dict)


@dataclass(frozen=True)
class SensorsResult:
    """What :func:`run_sensors_study` measured: one :class:`SensorsRow` per leg joint, the rows left out at a
    joint limit, the differentiation scheme, and the files written."""

    rows: list[SensorsRow]
    at_limit: int
    diff: str
    files: list[Path]

    def worst(self, route: str, part: str) -> dict[str, float]:
        """The largest error [%] of each scored parameter over the leg joints, for one route and part."""
        return {n: max(r.errors[(route, part)][n] for r in self.rows) for n in SCORED}


PARTS = {"contact": ("swing",), "wrench": ("swing", "stance")}
"""The parts each route is scored on: the thesis's route has no stance estimate."""


def run_sensors_study(robot: Robot, output_dir: Path, steps: int = 3, diff: Diff = "central",
                      filtering: FilterOptions = FilterOptions(), noise: SensorNoise = SensorNoise(),
                      substeps: int = SUBSTEPS, progress: StageProgress | None = None,
                      route: RouteOption = "auto") -> SensorsResult:
    """Simulate, estimate by both routes, fit swing and stance (module docstring); write the log, a JSON of the
    table and ``sensors.md`` into ``output_dir``. ``noise``: the sensors' noise in the loop (off by
    default), ``diff`` and ``filtering`` the acceleration route's differentiation, ``route`` the route
    (:data:`~wbfriction.friction.options.RouteOption`), ``substeps`` MuJoCo's physics steps per period
    (:data:`SUBSTEPS`).

    Raises:
        SimulationError: the robot fell.
        OutputError: an output folder or file the system refuses (a path under a file, a full disk).
    """
    say = progress or (lambda label: None)
    make_folder(output_dir)
    legs = leg_joints(robot)
    friction = {j: THESIS_TARGETS[g] for j, _, g in legs}
    say(f"MuJoCo: the combined walk, {steps} steps per direction, the ankle sensors logged")
    log = simulate_mujoco(robot, walking_reference(robot, GaitOptions(gait="combined", steps=steps)), friction,
                          MujocoOptions(sensors=noise, substeps=substeps)).log
    free = _off_limits(robot, log, legs)
    estimates = {}
    for closure, options in (("contact", EstimateOptions(diff=diff, filtering=filtering, base_motion="contact",
                                                         wrenches=False, route=route)),
                             ("wrench", EstimateOptions(diff=diff, filtering=filtering, base_motion="logged",
                                                        route=route))):
        say(f"estimate: the {closure} closure")
        estimates[closure] = estimate_log(robot, log, options)
    errors: dict[str, dict] = {j: {} for j, _, _ in legs}
    samples: dict[str, dict] = {j: {} for j, _, _ in legs}
    bounds: dict[str, dict] = {j: {} for j, _, _ in legs}
    statuses: dict[str, dict] = {j: {} for j, _, _ in legs}
    for closure, est in estimates.items():
        for part in PARTS[closure]:
            say(f"fit: the {closure} closure, {part} samples")
            part_est = est.keeping(_foot_down(robot, est, part == "stance") & free[:, None])
            for (joint, _, _), fit in zip(legs, fit_legs(part_est, legs, friction)):
                e = fit.error_percent() or {}
                errors[joint][(closure, part)] = {n: abs(e.get(n, np.inf)) for n in SCORED}
                samples[joint][(closure, part)] = fit.n_samples
                values = {} if fit.params is None else fit.params.to_dict()
                bounds[joint][(closure, part)] = {n: 100 * fit.crb.get(n, np.nan) / abs(friction[joint].to_dict()[n])
                                                  if friction[joint].to_dict()[n] else np.nan for n in SCORED
                                                  if n in values}
                statuses[joint][(closure, part)] = fit.verdict().status
    rows = [SensorsRow(j, side, g, errors[j], samples[j],
                       {c: float(est.valid[:, est.joints.index(j)].mean()) for c, est in estimates.items()},
                       bounds[j], statuses[j])
            for j, side, g in legs]
    routes = {c: est.estimation_route for c, est in estimates.items()}
    label = ", ".join(f"{c}: {r} route" for c, r in routes.items()) + "; acceleration: " + diff
    label += f" L={filtering.window}" if diff == "savgol" else ""
    label += "" if not noise.active else f", sensor noise {noise.position_std:g} rad / {noise.encoder_bits} bit"
    result = SensorsResult(rows, int((~free).sum()), label, [])
    files = [output_dir / "mujoco_sensors_walk.parquet", output_dir / "sensors.json", output_dir / "sensors.md"]
    write_log(log, robot, files[0])
    for file, text in ((files[1], json.dumps(_as_json(result), indent=1)), (files[2], sensors_markdown(result))):
        write_atomic(file, lambda tmp, text=text: tmp.write_text(text))
    return dataclasses.replace(result, files=files)


def _off_limits(robot: Robot, log: Log, legs: list[LegJoint]) -> np.ndarray:
    """(N,) the rows where no leg joint is within :data:`AT_LIMIT` of its URDF position limit."""
    lo, hi = robot.angle_limits
    i = [robot.actuated.index(j) for j, _, _ in legs]
    return ~np.any((log.q[:, i] < lo[i] + AT_LIMIT) | (log.q[:, i] > hi[i] - AT_LIMIT), axis=1)


def _foot_down(robot: Robot, est: FrictionEstimate, down: bool) -> np.ndarray:
    """(N, n_tc) a joint's foot on the ground (``down``) or in the air; joints of no foot: False."""
    out = np.zeros(est.valid.shape, dtype=bool)
    for i, joint in enumerate(est.joints):
        c = robot.contact_of(joint)
        if c is not None:
            out[:, i] = est.contact[:, c] == down
    return out


def _as_json(result: SensorsResult) -> dict:
    return {"diff": result.diff, "rows_at_a_limit": result.at_limit,
            "joints": {r.joint: {"side": r.side, "group": r.group, "usable_share": r.usable,
                                 **{f"{route}_{part}": {"error_percent": r.errors[(route, part)],
                                                        "samples": r.samples[(route, part)],
                                                        "bound_percent": r.bounds.get((route, part), {}),
                                                        "status": r.statuses.get((route, part))}
                                    for route, parts in PARTS.items() for part in parts}}
                       for r in result.rows}}


def sensors_markdown(result: SensorsResult) -> str:
    """The study's tables in Markdown: per leg joint the |error| [%] of F_c / F_v / tau_os by route and
    part, the thesis's Table 6.2 beside them, and the share of usable samples."""
    head = ["joint", "Table 6.2 (thesis)", "contact, swing", "wrench, swing", "wrench, stance"]
    lines = [f"Errors [%] of F_c / F_v / tau_os ({result.diff}; {result.at_limit} rows with a "
             "leg joint at its position limit left out)", "", "| " + " | ".join(head) + " |",
             "|" + "---|" * len(head)]
    names = ("F_c", "F_v", "tau_os")
    index = {"F_v": 0, "F_c": 1, "tau_os": 4}  # in the thesis's order (F_v, F_c, S, v_s, tau_os, a)
    for r in result.rows:
        thesis = TABLE_6_2.get((r.side, r.group))
        cells = [r.joint, " / ".join(f"{thesis[index[n]]:.2f}" for n in names) if thesis else "-"]
        cells += [" / ".join(f"{r.errors[(route, part)][n]:.2f}" for n in names)
                  for route, parts in PARTS.items() for part in parts]
        lines.append("| " + " | ".join(cells) + " |")
    parts = [(c, p) for c, ps in PARTS.items() for p in ps]
    lines += ["", "Cramér-Rao bound [% of the true value] of F_c / F_v, and the fit's status", "",
              "| joint | " + " | ".join(f"{c}, {p}" for c, p in parts) + " |", "|" + "---|" * (len(parts) + 1)]
    for r in result.rows:
        cells = [" / ".join(f"{r.bounds.get(k, {}).get(n, np.nan):.2f}" for n in ("F_c", "F_v"))
                 + f" {r.statuses.get(k, '')}" for k in parts]
        lines.append(f"| {r.joint} | " + " | ".join(cells) + " |")
    lines += ["", "Share of the walk's samples with a valid estimate", "", "| joint | contact | wrench |",
              "|---|---|---|"]
    lines += [f"| {r.joint} | {100 * r.usable['contact']:.1f} % | {100 * r.usable['wrench']:.1f} % |"
              for r in result.rows]
    return "\n".join(lines) + "\n"
