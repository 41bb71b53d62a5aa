"""The thesis's realistic-simulator study (6.2, Fig. 6.4-6.5) on MuJoCo: ``wbfriction demo --simulator mujoco``.

The estimator meets a world it did not write: soft foot contacts, contact flags from
measured forces, and (last case) sensor noise that the controller acts on.

1. **Swing and stance** (Fig. 6.4): a forward walk with friction (3.5) on the right knee
   only; the knee's estimate over the whole single-support time (its leg standing too) and
   over its swing phase only.
2. **No interference** (Fig. 6.5): the same walk with friction on every leg joint; the
   right knee's swing-phase estimate is unchanged.
3. **Identification** on the combined walk, swing-phase samples, per leg joint, on the route the log allows
   (issue 23: its ankle wrenches and IMU, every sample), the thesis's (rigid stance contact, no wrenches)
   beside it as the comparison in the first two cases:

   * friction (3.5) with Table 6.1's targets, noise off, central differences;
   * MuJoCo's own ``frictionloss`` and ``damping`` (Table 6.1's F_c and F_v), a Coulomb-viscous
     model fitted (S, v_s and tau_os held at 0, 0.1, 0);
   * friction (3.5) with the filter study's default sensor noise (1e-4 rad, 19-bit encoder,
     0.05 N·m) in the loop, estimated with the default options: the route the log allows (issue 23's ankle
     wrenches and IMU, every sample) and the one its noise calls for (issue 38's momentum route).

The first case's friction table and HTML report (``report.html``) are written as a user would make them.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wbfriction.fit.params_file import write_params
from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import FrictionEstimate, estimate_log
from wbfriction.friction.io import friction_table
from wbfriction.friction.models import FrictionParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.contacts import normal_forces, sensed_contacts
from wbfriction.logs.log import Log, write_log
from wbfriction.logs.tables import make_folder, write_table
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress
from wbfriction.report.build import make_report
from wbfriction.report.figures import velocity_panels_figure
from wbfriction.report.friction_figures import friction_curves_figure
from wbfriction.report.html import write_report
from wbfriction.sim import SimulationResult, simulate_mujoco
from wbfriction.sim.mujoco_model import MujocoRobot, build_mujoco_robot
from wbfriction.sim.options import MujocoOptions, SensorNoise
from wbfriction.studies.common import (
    ENCODER_BITS,
    TORQUE_STD,
    LegJoint,
    LegRow,
    fit_legs,
    leg_joints,
    leg_params_extra,
    leg_rows,
    right_knee,
    worst_errors,
)
from wbfriction.walking import walking_reference
from wbfriction.walking.options import GaitOptions

THESIS_ROUTE = EstimateOptions(diff="central", route="acceleration", base_motion="contact", wrenches=False)
"""The thesis's route: central differences of the accelerations, base motion from the rigid stance contact, the
ankle sensors' wrenches left out (the study reproduces 6.2; :mod:`wbfriction.friction.measured` is the route that
uses them)."""
NOISE = SensorNoise(position_std=1e-4, encoder_bits=ENCODER_BITS, torque_std=TORQUE_STD, seed=0)
"""The filter study's default noise level (its 1e-4 rad row)."""
MEASURED_ROUTE = EstimateOptions(diff="central", route="acceleration")
"""The route the simulated log allows, noise off: the ankle sensors' wrenches and the IMU (issue 23), central
differences of the accelerations."""
DEFAULTS = EstimateOptions()
"""The default options: the noisy case's (the route and closure the log allows, chosen from it)."""
COULOMB_VISCOUS = {"S": 0.0, "v_s": 0.1, "tau_os": 0.0}
"""Parameters held in the fit of MuJoCo's own friction, which has no Stribeck term or offset."""


@dataclass
class Case:
    """One identification of the leg joints on the combined walk."""

    name: str
    label: str
    rows: list[LegRow]
    scored: tuple[str, ...]  # the parameters the case's targets are about
    thesis_rows: list[LegRow] | None = None  # the same log on the thesis's route (rigid contacts), the comparison


@dataclass
class RealisticResult:
    """What :func:`run_realistic_study` measured; files written are listed in ``files``."""

    cases: list[Case]
    knee_rms: dict[str, float]  # RMS error of the right knee [N·m]: whole single-support time, swing only
    files: list[Path] = field(default_factory=list)


def _swing(est: FrictionEstimate, robot: Robot, joint: str, log: Log | None = None) -> np.ndarray:
    """Valid samples of ``joint`` while its leg swings: its foot's contact flag off and, when ``log`` has the
    ankle sensors' wrenches, the ground not pushing its sole (a landing foot can carry up to the flag's
    threshold, 50 N, for tens of milliseconds before its flag rises: that is the flag's lag, not the swing)."""
    c = robot.contact_of(joint)
    swing = est.valid[:, est.joints.index(joint)] & ~est.contact[:, c]
    if log is not None and log.wrench is not None and sensed_contacts(robot):
        swing &= normal_forces(robot, log.wrench)[:, c] <= 0.0  # in the air: minus the plate's weight
    return swing


@dataclass(frozen=True)
class _CaseSpec:
    """One identification case to run: the simulated friction and options, the fit's held parameters."""

    name: str
    label: str
    friction: dict[str, FrictionParams]
    options: MujocoOptions
    estimate: EstimateOptions
    fixed: dict[str, float] | None
    scored: tuple[str, ...]
    compare: bool = False  # also the thesis's route (THESIS_ROUTE) on the same log


def _simulate(robot: Robot, mjr: MujocoRobot, gait: GaitOptions, friction: dict[str, FrictionParams],
              options: MujocoOptions) -> SimulationResult:
    """Walk ``gait`` on MuJoCo with ``friction``."""
    return simulate_mujoco(robot, walking_reference(robot, gait), friction, options, mjr=mjr)


def _swing_and_stance(robot: Robot, mjr: MujocoRobot, knee: str, table_6_1: dict[str, FrictionParams],
                      knee_steps: int, options: MujocoOptions, output_dir: Path,
                      say: StageProgress) -> tuple[dict[str, float], list[Path]]:
    """Fig. 6.4 and 6.5 (steps 1-2 of the module docstring): the right knee's RMS error and the figures written."""
    forward = GaitOptions(gait="forward", steps=knee_steps)
    whole = dataclasses.replace(THESIS_ROUTE, mask="single")
    say("MuJoCo: a forward walk, friction on the right knee")
    knee_log = _simulate(robot, mjr, forward, {knee: table_6_1[knee]}, options).log
    knee_only = estimate_log(robot, knee_log, whole)
    say("MuJoCo: the same walk, friction on every leg joint")
    legs_log = _simulate(robot, mjr, forward, table_6_1, options).log
    all_legs = estimate_log(robot, legs_log, whole)
    i = knee_only.joints.index(knee)
    standing, swinging = knee_only.valid[:, i], _swing(knee_only, robot, knee, knee_log)
    assert knee_only.tau_f_true is not None  # simulated: the log has the true friction
    err = knee_only.tau_f[:, i] - knee_only.tau_f_true[:, i]
    knee_rms = {"whole step": float(np.sqrt(np.mean(err[standing] ** 2))),
                "swing only": float(np.sqrt(np.mean(err[swinging] ** 2)))}
    fig_6_4, fig_6_5 = output_dir / "fig6_4_knee_swing_stance.png", output_dir / "fig6_5_knee_interference.png"
    velocity_panels_figure([("whole step (single support)", knee_only, standing),
                            ("swing phase only", knee_only, swinging)],
                           knee, table_6_1[knee], fig_6_4,
                           "Fig. 6.4 (MuJoCo): right knee friction, central differences")
    velocity_panels_figure([("friction on the right knee only", knee_only, swinging),
                            ("friction on every leg joint", all_legs, _swing(all_legs, robot, knee, legs_log))],
                           knee, table_6_1[knee], fig_6_5,
                           "Fig. 6.5 (MuJoCo): right knee friction in swing, alone and with every leg joint's")
    return knee_rms, [fig_6_4, fig_6_5]


def _case_specs(table_6_1: dict[str, FrictionParams], options: MujocoOptions) -> list[_CaseSpec]:
    """The identification cases of step 3 of the module docstring, in order."""
    native = {j: dataclasses.replace(p, S=0.0, tau_os=0.0) for j, p in table_6_1.items()}
    return [
        _CaseSpec("model", "friction (3.5), noise off, central differences, ankle wrenches and IMU", table_6_1,
                  options, MEASURED_ROUTE, None, ("F_c", "F_v", "tau_os"), compare=True),
        _CaseSpec("mujoco", "MuJoCo frictionloss + damping, noise off, central differences, ankle wrenches and IMU, "
                            "Coulomb-viscous fit",
                  native, dataclasses.replace(options, friction="mujoco"), MEASURED_ROUTE, COULOMB_VISCOUS,
                  ("F_c", "F_v"), compare=True),
        _CaseSpec("noisy", "friction (3.5), sensor noise 1e-4 rad / 19 bit / 0.05 N·m, default options (the "
                           "momentum route, the ankle wrenches and the IMU)",
                  table_6_1, dataclasses.replace(options, sensors=NOISE), DEFAULTS, None,
                  ("F_c", "F_v", "tau_os")),
    ]


def _identify(robot: Robot, mjr: MujocoRobot, legs: list[LegJoint], spec: _CaseSpec, combined: GaitOptions,
              output_dir: Path) -> tuple[Case, list[Path]]:
    """One identification case on the combined walk: its fitted legs and the files written."""
    sim = _simulate(robot, mjr, combined, spec.friction, spec.options)
    est = estimate_log(robot, sim.log, spec.estimate)
    fits = fit_legs(est, legs, spec.friction, spec.fixed)
    rows = leg_rows(legs, fits)
    thesis_rows = (leg_rows(legs, fit_legs(estimate_log(robot, sim.log, THESIS_ROUTE), legs, spec.friction,
                                           spec.fixed)) if spec.compare else None)
    log_path = output_dir / f"mujoco_{spec.name}_log.parquet"
    params_path = output_dir / f"mujoco_{spec.name}_params.json"
    write_log(sim.log, robot, log_path)
    write_params(params_path, fits, {"robot": robot.name, "case": spec.label, "gait": dataclasses.asdict(combined)},
                 leg_params_extra(rows, thesis_errors=False))
    files = [log_path, params_path]
    if spec.name == "model":  # the figure and the report a user would make of this log
        friction_curves_figure(est, fits, output_dir / "mujoco_friction_curves.png")
        friction_path, report_path = output_dir / "mujoco_model_friction.parquet", output_dir / "report.html"
        write_table(friction_table(est), friction_path)
        write_report(make_report(friction_path, params_path), report_path)
        files += [output_dir / "mujoco_friction_curves.png", friction_path, report_path]
    return Case(spec.name, spec.label, rows, spec.scored, thesis_rows), files


KNEE_STEPS = 5
"""Steps of the forward walks of Fig. 6.4 and 6.5 (:func:`run_realistic_study`'s default; ``demo --simulator mujoco
--steps N`` takes ``min(N, KNEE_STEPS)``)."""


def run_realistic_study(robot: Robot, output_dir: Path, steps: int = 10, knee_steps: int = KNEE_STEPS,
                        options: MujocoOptions = MujocoOptions(),
                        progress: StageProgress | None = None) -> RealisticResult:
    """Run the study (module docstring) and write its parameters and figures to ``output_dir``.

    Args:
        robot: a biped with thesis joint groups.
        steps: steps per direction of the combined walk.
        knee_steps: steps of the forward walk of Fig. 6.4 and 6.5.
        options: the simulator's options (friction mode and sensors are set per case).
        progress: called with a label as each stage starts (:data:`~wbfriction.progress.StageProgress`).

    Raises:
        SimulationError: the robot fell in one of the walks.
        OutputError: an output folder or file the system refuses (a path under a file, a full disk).
    """
    say = progress or (lambda label: None)
    make_folder(output_dir)
    legs = leg_joints(robot)
    knee = right_knee(legs)
    table_6_1 = {j: THESIS_TARGETS[g] for j, _, g in legs}
    mjr = build_mujoco_robot(robot)

    # 1-2. right knee only, then every leg joint: Fig. 6.4, 6.5
    knee_rms, files = _swing_and_stance(robot, mjr, knee, table_6_1, knee_steps, options, output_dir, say)

    # 3. identification on the combined walk
    combined = GaitOptions(gait="combined", steps=steps)
    results = []
    for spec in _case_specs(table_6_1, options):
        say(f"MuJoCo: the combined walk ({steps} steps per direction), {spec.label}")
        case, written = _identify(robot, mjr, legs, spec, combined, output_dir)
        results.append(case)
        files += written
    return RealisticResult(results, knee_rms, files)


def worst_scored(case: Case, rows: list[LegRow] | None = None) -> dict[str, float]:
    """Largest error [%] over the leg joints (``rows``, default the case's) of each parameter the case is scored
    on."""
    return worst_errors(case.rows if rows is None else rows, case.scored)
