"""What each gait gives a walking quadruped (issue 56): ``wbfriction study-quadruped``.

A quadruped on point feet (the built-in ``go2_walking``) walks with known friction on every joint, in the ideal
simulator (:mod:`wbfriction.sim.quadruped`: point feet welded while down) or on MuJoCo
(:mod:`wbfriction.sim.quadruped_mujoco`: soft contacts, its sensors), torque- or PD-driven. Its log is estimated
(:mod:`wbfriction.friction.point_contacts`: each joint where the contacts leave its friction determined) and every
joint's friction fitted (the injected family, (3.5) without Stribeck effect: F_c and F_v free, ``S = 0``). The study
reports, per joint, the share of samples that determine it by contact pattern, its fit's status and the fitted F_c
and F_v against the truth, with their Cramér-Rao bounds.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from wbfriction.exceptions import OptionError
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions
from wbfriction.fit.result import FitResult
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.estimated import FrictionEstimate
from wbfriction.friction.options import EstimateOptions
from wbfriction.friction.point_contacts import DeterminedShares, determined_shares
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress
from wbfriction.sim.engines import engine_names, engine_of
from wbfriction.sim.engines.registry import ENGINES
from wbfriction.sim.options import SensorNoise
from wbfriction.sim.quadruped import Drive, FootForces, QuadrupedOptions, QuadrupedRun
from wbfriction.walking.quadruped import FOOT_RADIUS, Gait, GaitOptions, quadruped_reference

REAL_NOISE = SensorNoise(encoder_bits=19, torque_std=0.05)
"""A real robot's sensors: the encoder lattice measured on the real Aliengo (2 pi / 2^19 rad at the joint, issue
55) and a joint torque sensor's 0.05 N·m of white noise; on MuJoCo also the drivers' velocity (0.02 rad/s), the IMU
(0.005 rad/s, 0.05 m/s^2) and the foot forces (2 N), :data:`~wbfriction.sim.quadruped_mujoco.UNITREE_NOISE`'s."""
FIXED = {"S": 0.0, "v_s": 0.1}
"""The injected family's parameters held in the fit: no Stribeck effect (``v_s`` then has no effect)."""


@dataclass(frozen=True)
class QuadrupedCase:
    """One simulated walk of :func:`run_quadruped`.

    Attributes:
        simulator: the engine's name (:mod:`wbfriction.sim.engines`); gait:
        :data:`~wbfriction.walking.quadruped.Gait`; drive: ``torque`` or ``pd``; foot_forces: the feet's forces
        logged (``none``, ``normal``, ``3d``); noise: a real robot's sensor noise (the simulator's), then
        differentiated (``diff="auto"``), else the true derivatives (``diff="true"``); duration [s]; seed.
    """

    simulator: str = ENGINES.loaded()[0]  # the first built in: no entry point read as the module loads
    gait: Gait = "trot"
    drive: Drive = "torque"
    foot_forces: FootForces = "none"
    noise: bool = False
    duration: float = 8.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.simulator not in ENGINES:
            raise OptionError("--simulator", self.simulator, f"one of {', '.join(engine_names())}")
        ENGINES.get(self.simulator)  # an installed package's engine loaded: one that does not load is its one line
        GaitOptions(gait=self.gait, duration=self.duration)  # what they refuse, before any simulation
        QuadrupedOptions(drive=self.drive, foot_forces=self.foot_forces)


@dataclass
class QuadrupedStudy:
    """What :func:`run_quadruped` measured.

    Attributes:
        case: the walk; run: the simulation; est: its estimate; fits: every joint's fit (against its truth);
        shares: the share of samples that determine each joint by contact pattern.
    """

    case: QuadrupedCase
    run: QuadrupedRun
    est: FrictionEstimate
    fits: list[FitResult]
    shares: DeterminedShares

    def worst_error(self) -> dict[str, float]:
        """The largest error of F_c and F_v over the fitted joints [%] (NaN: none fitted)."""
        errors = [f.error_percent() or {} for f in self.fits if f.params is not None]
        return {p: max((e.get(p, np.nan) for e in errors), default=np.nan) for p in ("F_c", "F_v")}


def case_robot(robot: Robot, case: QuadrupedCase) -> Robot:
    """The robot as ``case``'s simulator builds it: on MuJoCo, its feet are spheres of
    :data:`~wbfriction.walking.quadruped.FOOT_RADIUS` round the contact frames (the ground's force acts at their
    lowest point: :attr:`~wbfriction.model.robot.Robot.foot_radius`); the ideal simulator's are points."""
    if not engine_of(case.simulator).soft_contacts or robot.foot_radius:
        return robot
    return replace(robot, foot_radius=FOOT_RADIUS, cache={})


def simulate_case(robot: Robot, case: QuadrupedCase) -> QuadrupedRun:
    """The walk of ``case`` on ``robot``, the simulator's default friction on every joint."""
    reference = quadruped_reference(robot, GaitOptions(gait=case.gait, duration=case.duration, seed=case.seed))
    noise = REAL_NOISE if case.noise else None
    options = QuadrupedOptions(drive=case.drive, foot_forces=case.foot_forces, noise=noise, seed=case.seed)
    engine = engine_of(case.simulator)
    sensors = None
    if case.noise and engine.soft_contacts:  # a soft-contact engine's own sensors: its IMU and foot forces too
        from wbfriction.sim.quadruped_mujoco import QuadrupedNoise

        sensors = QuadrupedNoise(encoder_resolution=REAL_NOISE.resolution, torque_std=REAL_NOISE.torque_std,
                                 velocity_std=0.02, gyro_std=0.005, acc_std=0.05, force_std=2.0, seed=case.seed)
    return engine.quadruped(robot, reference, options, sensors=sensors)


def run_quadruped(robot: Robot, case: QuadrupedCase = QuadrupedCase(),
                  progress: StageProgress | None = None) -> QuadrupedStudy:
    """Simulate ``case``, estimate its friction where determined, fit every joint (module docstring)."""
    say = progress or (lambda _label: None)
    say(f"simulating a {case.gait} ({case.simulator}, {case.drive}-driven, {case.duration:g} s)")
    robot = case_robot(robot, case)
    run = simulate_case(robot, case)
    say("estimating each joint's friction where the contacts determine it")
    # noise-free: the true derivatives, the base's own (the IMU's gyro would be differentiated); else as a user's log
    options = (EstimateOptions() if case.noise else
               EstimateOptions(diff="true", route="acceleration", base_motion="logged", check_route=False))
    est = estimate_log(robot, run.log, options)
    say("fitting every joint")
    fits = fit_estimate(est, FitOptions(model="thesis"), fixed=FIXED)
    shares = determined_shares(est)
    assert shares is not None  # a robot on point feet
    return QuadrupedStudy(case, run, est, fits, shares)


def study_record(study: QuadrupedStudy) -> dict:
    """The study as JSON: the case, the shares, each joint's status, fitted F_c, F_v, their errors and bounds."""
    joints = {}
    for f in study.fits:
        errors = f.error_percent() or {}
        joints[f.joint] = {
            "status": f.verdict().status, "samples": int(f.n_samples),
            **{p: None if f.params is None else float(getattr(f.params, p)) for p in ("F_c", "F_v")},
            **{f"{p}_error_percent": errors.get(p) for p in ("F_c", "F_v")},
            **{f"{p}_bound": f.crb.get(p) if f.crb else None for p in ("F_c", "F_v")}}
    return {"case": asdict(study.case), "shares": study.shares.to_dict(), "joints": joints,
            "worst_error_percent": study.worst_error()}


def write_study(robot: Robot, study: QuadrupedStudy, output_dir: Path) -> list[Path]:
    """The study's log, friction table, parameters JSON, record (``quadruped.json``) and Markdown (``quadruped.md``)
    into ``output_dir``; ``robot`` the one the log was simulated and estimated with (:func:`case_robot`)."""
    from wbfriction.fit.params_file import write_params
    from wbfriction.friction.io import friction_table
    from wbfriction.logs.log import write_log
    from wbfriction.logs.tables import make_folder, write_atomic, write_json, write_table

    make_folder(output_dir)
    files = [output_dir / n for n in ("quadruped_log.parquet", "quadruped_friction.parquet", "quadruped_params.json",
                                      "quadruped.json", "quadruped.md")]
    write_log(study.run.log, robot, files[0])
    write_table(friction_table(study.est), files[1])
    write_params(files[2], study.fits, {"robot": robot.name, "case": asdict(study.case)})
    write_json(files[3], study_record(study))
    write_atomic(files[4], lambda tmp: tmp.write_text(quadruped_markdown(study)))
    return files


def quadruped_markdown(study: QuadrupedStudy) -> str:
    """The study as Markdown: the share of samples that determine each joint by feet on the ground, then each
    joint's fit (status, F_c and F_v against the truth, their bounds)."""
    shares, case = study.shares, study.case
    feet = [p.replace("_foot", "") for p in shares.patterns]
    lines = [f"# A {case.gait} ({case.simulator}, {case.drive}-driven, foot forces: {case.foot_forces}, "
             f"{'a real robot' + chr(39) + 's noise' if case.noise else 'noise-free'}, {case.duration:g} s)", "",
             "Share of samples [%] that determine each joint's friction, by feet on the ground (samples):", "",
             "| joint | " + " | ".join(f"{p} ({n})" for p, n in zip(feet, shares.samples)) + f" | all "
             f"({int(shares.samples.sum())}) |", "|---" * (len(feet) + 2) + "|"]
    for i, j in enumerate(shares.joints):
        lines.append(f"| {j} | " + " | ".join(f"{100 * s:.0f}" for s in shares.share[:, i])
                     + f" | {100 * shares.overall[i]:.0f} |")
    return "\n".join(lines) + "\n\n" + fits_markdown(study)


def fits_markdown(study: QuadrupedStudy) -> str:
    """Each joint's fit as Markdown: status, samples, F_c and F_v against the injected friction, the worst."""
    route = study.est.metadata.get("route", {}).get("route", "acceleration")
    lines = [f"Fits ({route} route), errors against the injected friction:", "",
             "| joint | status | samples | F_c error [%] | F_v error [%] |", "|---|---|---|---|---|"]
    for f in study.fits:
        e = f.error_percent() or {}
        lines.append(f"| {f.joint} | {f.verdict().status} | {f.n_samples} | {_pct(e.get('F_c'))} | "
                     f"{_pct(e.get('F_v'))} |")
    worst = study.worst_error()
    lines += ["", f"Worst: F_c {_pct(worst['F_c'])} %, F_v {_pct(worst['F_v'])} %."]
    return "\n".join(lines) + "\n"


def _pct(x: float | None) -> str:
    return "–" if x is None or not np.isfinite(x) else f"{x:.1f}"
