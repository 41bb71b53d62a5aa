"""Every model family on noisy logs (issue 38): ``wbfriction study-noise``.

Friction of each family (:data:`FAMILIES`) is simulated with sensor noise, and the log is estimated and fitted
as a user would, with the default options (the route chosen from the noise, ``--model auto``):

* **the arm**: the Panda of ``wbfriction simulate --robot panda`` (:mod:`wbfriction.sim.arm`: a Fourier excitation,
  10 kHz physics, 1 kHz log, motor currents), friction on every joint; its noise is the log's (positions before
  the encoder, torques), seeded per run, on one simulation per family (the controller tracks the true positions);
* **the humanoid**: TALOS on MuJoCo (soft contacts, ankle wrenches, IMU), the combined walk, friction on every
  leg, torso and arm joint; the noise is in the loop (the controller acts on it), one simulation per seed. The
  ``frictionloss`` family is MuJoCo's own dry friction, a constraint (a joint sticks), with its damping.

Per joint: the fitted model, its status, the error of F_c and F_v against the injected values, and their
Cramér-Rao bounds (:mod:`~wbfriction.fit.bound`). Each log is fitted twice: ``--model auto``, as a user runs
it (the accuracy tables), and the true family named, whose RMS error over the seeds is compared with its bound
(:func:`bound_table`): an efficient estimator is at the bound, a biased one above it.

A joint counts as moving (scored) when it is not ``not excited``; it is *determined* when the log lets an unbiased
estimator reach the tolerance at all, its bound at most half of it (F_c's :data:`TOLERANCES` / 2): the others are
listed with their bounds, out of reach of any method.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, cast, get_args

import numpy as np

from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions, ModelChoice
from wbfriction.fit.result import FitResult
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.families.names import BuiltinName
from wbfriction.friction.families.registry import family as model_family
from wbfriction.friction.models import FrictionParams, ModelName, ModelParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import Log, log_from_table
from wbfriction.logs.tables import make_folder, write_atomic
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress
from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm
from wbfriction.sim.options import FrictionMode, MujocoOptions, SensorNoise
from wbfriction.sim.sensors import apply_sensor_noise
from wbfriction.studies.common import ENCODER_BITS, TORQUE_STD
from wbfriction.walking import walking_reference
from wbfriction.walking.options import GaitOptions

Family = Literal[BuiltinName, "frictionloss"]
"""The friction injected: a built-in family of :mod:`~wbfriction.friction.families`, or MuJoCo's ``frictionloss``
(humanoid)."""
FAMILIES: tuple[Family, ...] = get_args(Family)
FRICTIONLOSS_MODEL: ModelName = "coulomb-viscous"
"""The model family MuJoCo's ``frictionloss`` (a dry friction, with its damping) belongs to."""
TRUE_MODEL: dict[Family, ModelName] = {f: FRICTIONLOSS_MODEL if f == "frictionloss" else f for f in FAMILIES}
"""The model family each friction belongs to."""
SHAPE = {"F_s": 1.5, "S": 0.3, "v_s": 0.05, "a": 40.0}
"""The injected friction's shape beyond its levels: a static level ``F_s`` 1.5 times the Coulomb level (Stribeck
model), ``S`` 0.3 ((3.5)), decaying at ``v_s`` [rad/s], a tanh slope ``a`` [s/rad]; each family takes its own."""
TOLERANCES = {1e-4: (2.0, 5.0), 3e-4: (5.0, 10.0)}
"""Issue 38's targets [%] of F_c and F_v per position noise [rad]."""
HUMANOID_GROUPS = {"waist": (0.3, 0.5), "arm_right": (0.1, 0.3), "arm_left": (0.1, 0.3)}
"""(F_v, F_c) of the humanoid's joints beside the legs (the legs: the thesis's Table 6.1)."""


def family_friction(robot: Robot, family: Family) -> dict[str, ModelParams]:
    """The friction of ``family`` per torque-controlled joint: on an arm, the arm simulator's default values
    (:func:`~wbfriction.sim.arm.default_arm_friction`), on a humanoid the thesis's Table 6.1 on the legs and
    :data:`HUMANOID_GROUPS`; the Stribeck effect of :data:`SHAPE`, an offset of 0.1 N·m, none with MuJoCo's
    ``frictionloss``."""
    from wbfriction.fit.targets import friction_by_group
    if robot.floating_base:
        base = friction_by_group(robot.groups) | {j: FrictionParams(F_v=v, F_c=c, S=0.2, v_s=0.05, tau_os=0.1)
                                                  for g, (v, c) in HUMANOID_GROUPS.items()
                                                  for j in robot.groups.get(g, ()) if j in robot.torque_controlled}
    else:
        base = default_arm_friction(robot)
    model = model_family(TRUE_MODEL[family])
    tau_os = 0.0 if family == "frictionloss" else 0.1
    return {joint: cast(ModelParams, model.from_quantities({"F_v": p.F_v, "F_c": p.F_c, "F_s": SHAPE["F_s"] * p.F_c,
                                                            "S": SHAPE["S"], "v_s": SHAPE["v_s"], "tau_os": tau_os,
                                                            "a": SHAPE["a"]}))
            for joint, p in base.items()}


@dataclass(frozen=True)
class NoiseRow:
    """One joint of one run.

    Attributes:
        robot, family, noise, seed: the run (position noise [rad]).
        fit: ``auto`` (``--model auto``, as a user runs it) or ``true`` (the true family named: what the bound
            table compares, an estimator of the model that made the data).
        joint: the joint; speed: the 95th percentile of its speed [rad/s].
        model, status: the model fitted and the fit's status.
        error: ``|fitted - true| / true`` [%] of F_c and F_v (against the true values under the fitted model's
            names: :meth:`~wbfriction.friction.models.ModelParamsBase.values_in`).
        value, bound, stderr: F_c's and F_v's fitted value, Cramér-Rao standard deviation and standard error.
        true: their true values.
    """

    robot: str
    family: str
    noise: float
    seed: int
    fit: str
    joint: str
    speed: float
    model: str
    status: str
    error: dict[str, float]
    value: dict[str, float]
    bound: dict[str, float]
    stderr: dict[str, float]
    true: dict[str, float]

    @property
    def determined(self) -> bool:
        """The bound of F_c within half its tolerance at this noise (module docstring)."""
        tol = TOLERANCES.get(self.noise, TOLERANCES[1e-4])[0]
        return math.isfinite(self.bound["F_c"]) and 100 * self.bound["F_c"] <= 0.5 * tol * abs(self.true["F_c"])


SCORED = ("F_c", "F_v")


def _row(robot: Robot, family: Family, noise: float, seed: int, choice: str, fit: FitResult) -> NoiseRow | None:
    if fit.params is None or fit.target is None:
        return None
    values, true = fit.params.to_dict(), fit.target.values_in(fit.model)
    err = fit.error_percent() or {}
    return NoiseRow(robot.name, family, noise, seed, choice, fit.joint, float(fit.speed or 0.0), fit.model,
                    fit.verdict().status, {n: float(err.get(n, math.nan)) for n in SCORED},
                    {n: float(values[n]) for n in SCORED}, {n: float(fit.crb.get(n, math.nan)) for n in SCORED},
                    {n: float(fit.stderr.get(n, math.nan)) for n in SCORED}, {n: float(true[n]) for n in SCORED})


def simulate_family(robot: Robot, family: Family, noise: float, seed: int, *, duration: float, steps: int,
                    cache: dict) -> Log:
    """The log of one run (module docstring); ``cache`` keeps the arm's noise-free simulation per family."""
    friction = family_friction(robot, family)
    sensors = SensorNoise(position_std=noise, encoder_bits=ENCODER_BITS, torque_std=TORQUE_STD, seed=seed)
    if not robot.floating_base:
        if family not in cache:
            sim = simulate_arm(robot, friction, options=ArmOptions(duration=duration, encoder_bits=None))
            cache[family] = log_from_table(sim.table, robot, f"arm_{family}")
        return apply_sensor_noise(cache[family], sensors)
    mode: FrictionMode = "mujoco" if family == "frictionloss" else "model"
    reference = cache.setdefault("reference", walking_reference(robot, GaitOptions(gait="combined", steps=steps)))
    from wbfriction.sim import simulate_mujoco
    return simulate_mujoco(robot, reference, friction, MujocoOptions(friction=mode, sensors=sensors)).log


def run_noise_study(robots: Sequence[Robot], output_dir: Path, *, families: Sequence[Family] = FAMILIES,
                    noises: Sequence[float] = (1e-4, 3e-4), seeds: int = 10, duration: float = 20.0, steps: int = 10,
                    workers: int = 2, progress: StageProgress | None = None) -> list[NoiseRow]:
    """Run every (robot, family, noise) case, ``seeds`` noise seeds at the first noise level and one at the others
    (module docstring); write ``noise.json`` (every row) and ``noise.md`` (:func:`noise_markdown`) into
    ``output_dir``. ``duration``: the arm's excitation [s]; ``steps``: the humanoid's steps per direction.

    Raises:
        SimulationError: the humanoid fell.
        OutputError: an output the system refuses.
    """
    say = progress or (lambda label: None)
    make_folder(output_dir)
    rows: list[NoiseRow] = []
    for robot in robots:
        cache: dict = {}
        for family in families:
            if family == "frictionloss" and not robot.floating_base:
                continue  # MuJoCo's friction: the humanoid's simulator
            for k, noise in enumerate(noises):
                for seed in range(seeds if k == 0 else 1):
                    say(f"{robot.name}, {family} friction, {noise:g} rad, seed {seed}")
                    log = simulate_family(robot, family, noise, seed, duration=duration, steps=steps, cache=cache)
                    est = estimate_log(robot, log, EstimateOptions())
                    for choice, model in (("auto", "auto"), ("true", TRUE_MODEL[family])):
                        fits = fit_estimate(est, FitOptions(model=cast(ModelChoice, model)), workers=workers)
                        rows += [r for f in fits if (r := _row(robot, family, noise, seed, choice, f)) is not None]
    write_atomic(output_dir / "noise.json",
                 lambda tmp: tmp.write_text(json.dumps([dataclasses.asdict(r) for r in rows], indent=1)))
    write_atomic(output_dir / "noise.md", lambda tmp: tmp.write_text(noise_markdown(rows)))
    return rows


def _cases(rows: Sequence[NoiseRow]) -> list[tuple[str, str, float]]:
    return list(dict.fromkeys((r.robot, r.family, r.noise) for r in rows))


def accuracy_table(rows: Sequence[NoiseRow]) -> list[dict]:
    """Per (robot, family, noise), seed 0: the joints scored (status not ``not excited``), those determined, the
    worst error of F_c and F_v over the determined ones and the share of them within the targets, the models
    chosen."""
    out = []
    for robot, family, noise in _cases(rows):
        case = [r for r in rows if (r.robot, r.family, r.noise, r.seed, r.fit) == (robot, family, noise, 0, "auto")
                and r.status != "not excited"]
        determined = [r for r in case if r.determined]
        tol = TOLERANCES.get(noise, TOLERANCES[1e-4])
        within = [r for r in determined if r.error["F_c"] <= tol[0] and r.error["F_v"] <= tol[1]]
        models = {m: sum(r.model == m for r in determined) for m in dict.fromkeys(r.model for r in determined)}
        true_model = TRUE_MODEL[cast(Family, family)]
        out.append({"robot": robot, "family": family, "noise": noise, "scored": len(case),
                    "determined": len(determined), "within": len(within),
                    "worst_F_c": max((r.error["F_c"] for r in determined), default=math.nan),
                    "worst_F_v": max((r.error["F_v"] for r in determined), default=math.nan),
                    "median_F_c": float(np.median([r.error["F_c"] for r in determined])) if determined else math.nan,
                    "median_F_v": float(np.median([r.error["F_v"] for r in determined])) if determined else math.nan,
                    "true_model": sum(r.model == true_model for r in determined), "models": models})
    return out


def bound_table(rows: Sequence[NoiseRow]) -> list[dict]:
    """Per (robot, family, joint) at the first noise level, over its seeds, the true family fitted: each parameter's
    mean Cramér-Rao standard deviation, its RMS error against the true value, and their ratio (the joints determined
    at seed 0)."""
    out = []
    for robot, family, noise in _cases(rows):
        case = [r for r in rows if (r.robot, r.family, r.noise, r.fit) == (robot, family, noise, "true")]
        seeds = {r.seed for r in case}
        if len(seeds) < 2:
            continue
        for joint in dict.fromkeys(r.joint for r in case):
            runs = [r for r in case if r.joint == joint]
            first = next((r for r in runs if r.seed == min(seeds)), None)
            if first is None or not first.determined or first.status == "not excited":
                continue
            entry: dict = {"robot": robot, "family": family, "noise": noise, "joint": joint, "seeds": len(runs)}
            for n in SCORED:
                bound = float(np.mean([r.bound[n] for r in runs]))
                rms = float(np.sqrt(np.mean([(r.value[n] - r.true[n]) ** 2 for r in runs])))
                entry[n] = {"bound": bound, "rms": rms, "ratio": rms / bound if bound > 0 else math.inf,
                            "true": first.true[n]}
            out.append(entry)
    return out


def noise_markdown(rows: Sequence[NoiseRow]) -> str:
    """The study's tables in Markdown: accuracy per case, every joint of seed 0, the bound table."""
    lines = ["# Every model family on noisy logs (default options: the route chosen from the noise, --model auto)",
             "", "## Accuracy (seed 0): errors [%] over the joints the log determines (F_c bound <= half its target)",
             "", "| robot | friction | noise [rad] | scored | determined | within target | worst F_c | worst F_v | "
                 "median F_c | median F_v | true family chosen |", "|" + "---|" * 11]
    for a in accuracy_table(rows):
        lines.append(f"| {a['robot']} | {a['family']} | {a['noise']:g} | {a['scored']} | {a['determined']} | "
                     f"{a['within']} | {a['worst_F_c']:.2f} | {a['worst_F_v']:.2f} | {a['median_F_c']:.2f} | "
                     f"{a['median_F_v']:.2f} | {a['true_model']} of {a['determined']} |")
    lines += ["", "## Every joint (seed 0): model, status, error [%] and Cramér-Rao bound [% of the true value]", "",
              "| robot | friction | noise | joint | speed [rad/s] | model | status | F_c err | F_c bound | F_v err | "
              "F_v bound |", "|" + "---|" * 11]
    for r in rows:
        if r.seed or r.fit != "auto":
            continue
        pct = {n: 100 * r.bound[n] / abs(r.true[n]) if r.true[n] else math.nan for n in SCORED}
        lines.append(f"| {r.robot} | {r.family} | {r.noise:g} | {r.joint} | {r.speed:.2f} | {r.model} | {r.status} | "
                     f"{r.error['F_c']:.2f} | {pct['F_c']:.2f} | {r.error['F_v']:.2f} | {pct['F_v']:.2f} |")
    lines += ["", "## Over the seeds: RMS error against the Cramér-Rao standard deviation", "",
              "| robot | friction | joint | seeds | F_c bound | F_c RMS error | ratio | F_v bound | F_v RMS error | "
              "ratio |", "|" + "---|" * 10]
    for b in bound_table(rows):
        c, v = b["F_c"], b["F_v"]
        lines.append(f"| {b['robot']} | {b['family']} | {b['joint']} | {b['seeds']} | {c['bound']:.3g} | "
                     f"{c['rms']:.3g} | {c['ratio']:.2f} | {v['bound']:.3g} | {v['rms']:.3g} | {v['ratio']:.2f} |")
    return "\n".join(lines) + "\n"


def rows_from_json(text: str) -> list[NoiseRow]:
    """The rows ``noise.json`` holds (:func:`run_noise_study`)."""
    return [NoiseRow(**d) for d in json.loads(text)]

