"""The thesis's simulation study (ch. 6) on a built-in robot: ``wbfriction demo``.

1. **Support phases and derivative schemes** (6.1.1, 6.1.2; Fig. 6.1-6.3): a forward walk
   with friction on the right knee only. The estimate with the true accelerations
   recovers it exactly in single support and is not unique in double support (Fig. 6.1);
   central differences, and backward differences with and without delay compensation,
   show the sensitivity to phase delays, largest while the leg is in stance (Fig. 6.2, 6.3).
2. **Identification** (6.2.2; Tables 6.1, 6.2): the combined walk (forward, sideways and
   turning) with the targets of Table 6.1 on every leg joint; central differences; the
   fit of (3.5) per leg joint on its swing-phase samples; the HTML report of that estimate
   (:mod:`wbfriction.report`).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .energy import energy_consistency
from .estimate import EstimateOptions, estimate_log
from .friction import PARAM_NAMES, THESIS_TARGETS, FrictionParams
from .identify import FitResult, fit_estimate, fitted_offsets
from .log import write_atomic, write_log, write_table
from .plots import derivative_schemes_figure, friction_curves_figure, support_phases_figure
from .report import make_report, write_report
from .robot import Robot
from .sim import IdealOptions, SimulationResult, simulate_ideal
from .thesis import TABLE_6_1, TABLE_6_2, thesis_number
from .walking import GaitOptions, walking_reference

DERIVATIVE_SCHEMES = {
    "true acceleration": EstimateOptions(diff="true", mask="single"),
    "central (6.2)": EstimateOptions(diff="central", mask="single"),
    "backward, delay compensated": EstimateOptions(diff="backward", compensate_delay=True, mask="single"),
    "backward, not compensated": EstimateOptions(diff="backward", compensate_delay=False, mask="single"),
}

SIMULATOR = IdealOptions(substeps=10)
"""The study's simulator: the controller at 1 kHz, physics at 10 kHz (semi-implicit Euler).

The log then samples a trajectory close to continuous time, as a robot's log does. With
one Euler step per sample the discrete trajectory leaves an O(dt) ambiguity between the
state's velocity and the position differences the estimator sees (semi-implicit Euler:
``(q[k] - q[k-1]) / dt`` is ``qd[k]`` exactly, the central difference is half an
acceleration step off), which biases the Coriolis terms and the fitted F_v: measured on
the combined walk, F_v off by 3.7 % at one step per sample, 1.8 % at 5, 0.9 % at 10,
0.4 % at 20 (the thesis's forward Euler at 1 kHz: 25 %)."""


@dataclass
class LegRow:
    """One leg joint of the identification table."""

    joint: str
    side: str
    group: str
    number: int  # thesis numbering (1-6 right, 7-12 left)
    fit: FitResult
    thesis_6_1: tuple[float, ...] | None
    thesis_6_2: tuple[float, ...] | None


@dataclass
class StudyResult:
    """What :func:`run_study` measured; files written are listed in ``files``."""

    rows: list[LegRow]
    truth_max_error: float  # max |tau_f - tau_f_true| in single support with true accelerations [N·m]
    knee_rms: dict[str, float]  # RMS error of the right knee per scheme, leg in swing / stance [N·m]
    pulls: int  # samples where a welded foot pulled on the ground, both walks
    files: list[Path] = field(default_factory=list)
    generating_share: dict[str, float] = field(default_factory=dict)  # per leg joint, swing phase (eq. 7.9)


def _leg_joints(robot: Robot) -> list[tuple[str, str, str]]:
    """(joint, side, group) of the leg joints with a thesis group, in thesis order."""
    out = []
    for c, frame in enumerate(robot.contact_frames):
        side = "left" if "left" in frame else "right" if "right" in frame else str(c)
        for joint in robot.limb(frame):
            group = robot.group_of(joint)
            if group in THESIS_TARGETS and joint in robot.torque_controlled:
                out.append((joint, side, group))
    return sorted(out, key=lambda x: thesis_number(x[1], x[2]) if x[1] in ("left", "right") else 0)


def _simulate(robot: Robot, gait: GaitOptions, friction: dict[str, FrictionParams], progress=None) -> SimulationResult:
    ref = walking_reference(robot, gait)
    return simulate_ideal(robot, ref, friction, SIMULATOR, progress=progress)


def run_study(robot: Robot, output_dir: Path, steps: int = 10, knee_steps: int = 5,
              progress=None) -> StudyResult:
    """Run the study and write its logs, estimates, parameters and figures to ``output_dir``.

    Args:
        robot: a biped with thesis joint groups (``hip_roll`` ... ``ankle_pitch``).
        steps: steps per direction of the combined walk.
        knee_steps: steps of the right-knee walk (Fig. 6.1-6.3).
        progress: optional callable(label) called as each stage starts.
    """
    say = progress or (lambda label: None)
    output_dir.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    legs = _leg_joints(robot)
    knee = next(j for j, side, g in legs if side == "right" and g == "knee")

    # 1. right knee only: Fig. 6.1-6.3
    say("simulating a forward walk, friction on the right knee")
    knee_sim = _simulate(robot, GaitOptions(gait="forward", steps=knee_steps), {knee: THESIS_TARGETS["knee"]})
    write_log(knee_sim.log, robot, output_dir / "knee_log.parquet")
    say("estimating with four differentiation schemes")
    schemes = {label: estimate_log(robot, knee_sim.log, opts) for label, opts in DERIVATIVE_SCHEMES.items()}
    truth = schemes["true acceleration"]
    truth_err = float(np.nanmax(np.abs(truth.tau_f - truth.tau_f_true)[truth.unique]))
    i_knee = truth.joints.index(knee)
    foot = robot.contact_of(knee)
    # valid single-support samples (skip windows applied), same for every scheme
    swing_k = truth.valid[:, i_knee] & ~truth.contact[:, foot]
    stance_k = truth.valid[:, i_knee] & truth.contact[:, foot]
    knee_rms = {}
    for label, est in schemes.items():
        e = est.tau_f[:, i_knee] - est.tau_f_true[:, i_knee]
        knee_rms[label] = (float(np.sqrt(np.nanmean(e[swing_k] ** 2))), float(np.sqrt(np.nanmean(e[stance_k] ** 2))))
    support_phases_figure(truth, [j for j, side, _ in legs if side == "right"], output_dir / "fig6_1_support_phases.png")
    derivative_schemes_figure(schemes, knee, foot, output_dir / "fig6_2_schemes_time.png",
                              output_dir / "fig6_3_schemes_velocity.png")
    files += [output_dir / n for n in ("knee_log.parquet", "fig6_1_support_phases.png",
                                       "fig6_2_schemes_time.png", "fig6_3_schemes_velocity.png")]

    # 2. combined walk, Table 6.1 friction on all leg joints: identification
    say(f"simulating the combined walk ({steps} steps forward, sideways, turning)")
    friction = {j: THESIS_TARGETS[g] for j, _, g in legs}
    walk = _simulate(robot, GaitOptions(gait="combined", steps=steps), friction)
    write_log(walk.log, robot, output_dir / "walk_log.parquet")
    say("estimating (central differences)")
    est = estimate_log(robot, walk.log, EstimateOptions(), companion=True)
    write_table(est.to_table(), output_dir / "walk_friction.parquet")
    say("fitting the friction model of every leg joint")
    idx = [est.joints.index(j) for j, _, _ in legs]
    fits = fit_estimate([j for j, _, _ in legs], est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx],
                        tau_f_true=est.tau_f_true[:, idx], targets=friction, smoother=est.smoother)
    rows = [LegRow(j, side, g, thesis_number(side, g), f, TABLE_6_1.get((side, g)), TABLE_6_2.get((side, g)))
            for (j, side, g), f in zip(legs, fits)]
    doc = {"robot": robot.name, "gait": asdict(GaitOptions(gait="combined", steps=steps)),
           "joints": {r.joint: {**r.fit.to_dict(), "thesis_number": r.number, "group": r.group,
                                "thesis_error_percent_table_6_1": r.thesis_6_1,
                                "thesis_error_percent_table_6_2": r.thesis_6_2} for r in rows}}
    write_atomic(output_dir / "walk_params.json", lambda tmp: tmp.write_text(json.dumps(doc, indent=2)))
    friction_curves_figure(est, fits, output_dir / "friction_curves.png")
    say("writing the report")
    write_report(make_report(output_dir / "walk_friction.parquet", output_dir / "walk_params.json"),
                 output_dir / "report.html")
    files += [output_dir / n for n in ("walk_log.parquet", "walk_friction.parquet", "walk_params.json",
                                       "friction_curves.png", "report.html")]
    pulls = sum(p.samples for p in knee_sim.pulls() + walk.pulls())
    energy = energy_consistency(est, fitted_offsets(fits))
    legs_only = {j for j, _, _ in legs}
    share = {e.joint: e.generating_share for e in energy if e.joint in legs_only}
    return StudyResult(rows, truth_err, knee_rms, pulls, files, share)


def worst_errors(rows: list[LegRow]) -> dict[str, float]:
    """Largest error [%] of each parameter over the leg joints."""
    return {n: max(r.fit.error_percent()[n] for r in rows) for n in PARAM_NAMES}
