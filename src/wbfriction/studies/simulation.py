"""The thesis's simulation study (ch. 6) on a built-in robot: ``wbfriction demo``.

1. **Support phases and derivative schemes** (6.1.1, 6.1.2; Fig. 6.1-6.3): a forward walk
   with friction on the right knee only. The estimate with the true accelerations
   recovers it exactly in single support and is not unique in double support (Fig. 6.1);
   central differences, and backward differences with and without delay compensation,
   show the sensitivity to phase delays, largest while the leg is in stance (Fig. 6.2, 6.3).
2. **Identification** (6.2.2; Tables 6.1, 6.2): the combined walk (forward, sideways and
   turning) with the targets of Table 6.1 on every leg joint; central differences; the
   fit of (3.5) per leg joint on its swing-phase samples; the HTML report of that estimate
   (:mod:`wbfriction.report.html`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from wbfriction.fit.energy import energy_consistency
from wbfriction.fit.params_file import write_params
from wbfriction.fit.result import fitted_offsets
from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.io import friction_table
from wbfriction.friction.models import FrictionParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import write_log
from wbfriction.logs.tables import make_folder, write_table
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress, Steps
from wbfriction.report.build import make_report
from wbfriction.report.figures import derivative_schemes_figure, support_phases_figure
from wbfriction.report.friction_figures import friction_curves_figure
from wbfriction.report.html import write_report
from wbfriction.sim import Pull, SimulationResult, simulate_ideal
from wbfriction.studies.common import (
    SIMULATOR,
    LegJoint,
    LegRow,
    fit_legs,
    leg_joints,
    leg_params_extra,
    leg_rows,
    right_knee,
)
from wbfriction.walking import walking_reference
from wbfriction.walking.options import GaitOptions

DERIVATIVE_SCHEMES = {
    "true acceleration": EstimateOptions(diff="true", mask="single", route="acceleration", check_route=False),
    "central (6.2)": EstimateOptions(diff="central", mask="single", route="acceleration", check_route=False),
    "backward, delay compensated": EstimateOptions(diff="backward", compensate_delay=True, mask="single",
                                                   route="acceleration", check_route=False),
    "backward, not compensated": EstimateOptions(diff="backward", compensate_delay=False, mask="single",
                                                 route="acceleration", check_route=False),
}

@dataclass
class StudyResult:
    """What :func:`run_study` measured; files written are listed in ``files``."""

    rows: list[LegRow]
    truth_max_error: float  # max |tau_f - tau_f_true| in single support with true accelerations [N·m]
    knee_rms: dict[str, tuple[float, float]]  # RMS error of the right knee per scheme: leg in swing, stance [N·m]
    pulls: int  # samples where a welded foot pulled on the ground, both walks
    files: list[Path] = field(default_factory=list)
    generating_share: dict[str, float] = field(default_factory=dict)  # per leg joint, swing phase (eq. 7.9)
    pulls_double_support: int = 0  # of the pulls' samples, those in double support (never valid: not estimated)


def _simulate(robot: Robot, gait: GaitOptions, friction: dict[str, FrictionParams], label: str,
              steps: Steps | None = None) -> SimulationResult:
    """The walk ``gait`` simulated with ``friction``, its samples counted to ``steps`` as a stage called ``label``."""
    ref = walking_reference(robot, gait)
    progress = None if steps is None else steps(label, len(ref), "samples")
    return simulate_ideal(robot, ref, friction, SIMULATOR, progress=progress)


def _derivative_schemes(robot: Robot, legs: list[LegJoint], knee: str, knee_steps: int, output_dir: Path,
                        say: StageProgress, steps: Steps | None = None
                        ) -> tuple[float, dict[str, tuple[float, float]], list[Pull], list[Path]]:
    """Sub-study 1 (Fig. 6.1-6.3): the truth's error, the knee's RMS per scheme, the walk's pulls, the files written."""
    say("planning a forward walk")
    knee_sim = _simulate(robot, GaitOptions(gait="forward", steps=knee_steps), {knee: THESIS_TARGETS["knee"]},
                         "simulating the forward walk, friction on the right knee", steps)
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
    assert truth.tau_f_true is not None and foot is not None  # a simulated log; a leg joint
    knee_rms: dict[str, tuple[float, float]] = {}
    for label, est in schemes.items():
        assert est.tau_f_true is not None
        e = est.tau_f[:, i_knee] - est.tau_f_true[:, i_knee]
        knee_rms[label] = (float(np.sqrt(np.nanmean(e[swing_k] ** 2))), float(np.sqrt(np.nanmean(e[stance_k] ** 2))))
    support_phases_figure(truth, [j for j, side, _ in legs if side == "right"],
                          output_dir / "fig6_1_support_phases.png")
    derivative_schemes_figure(schemes, knee, foot, output_dir / "fig6_2_schemes_time.png",
                              output_dir / "fig6_3_schemes_velocity.png")
    files = [output_dir / n for n in ("knee_log.parquet", "fig6_1_support_phases.png",
                                      "fig6_2_schemes_time.png", "fig6_3_schemes_velocity.png")]
    return truth_err, knee_rms, knee_sim.pulls(), files


def _identification(robot: Robot, legs: list[LegJoint], steps: int, output_dir: Path,
                    say: StageProgress, counted: Steps | None = None
                    ) -> tuple[list[LegRow], list[Pull], dict[str, float], list[Path]]:
    """Sub-study 2 (Tables 6.1, 6.2, report): the rows, the walk's pulls, the legs' power shares, the files written."""
    say(f"planning the combined walk ({steps} steps forward, sideways, turning)")
    friction = {j: THESIS_TARGETS[g] for j, _, g in legs}
    walk = _simulate(robot, GaitOptions(gait="combined", steps=steps), friction, "simulating the combined walk",
                     counted)
    write_log(walk.log, robot, output_dir / "walk_log.parquet")
    say("estimating (central differences)")
    est = estimate_log(robot, walk.log, EstimateOptions(diff="central", route="acceleration"), companion=True)
    write_table(friction_table(est), output_dir / "walk_friction.parquet")
    if counted is None:  # else its stages say themselves, the joints counted
        say("fitting the friction model of every leg joint")
    fits = fit_legs(est, legs, friction, progress=counted)
    rows = leg_rows(legs, fits)
    write_params(output_dir / "walk_params.json", fits,
                 {"robot": robot.name, "gait": asdict(GaitOptions(gait="combined", steps=steps))},
                 leg_params_extra(rows))
    friction_curves_figure(est, fits, output_dir / "friction_curves.png")
    say("writing the report")
    write_report(make_report(output_dir / "walk_friction.parquet", output_dir / "walk_params.json"),
                 output_dir / "report.html")
    files = [output_dir / n for n in ("walk_log.parquet", "walk_friction.parquet", "walk_params.json",
                                      "friction_curves.png", "report.html")]
    energy = energy_consistency(est, fitted_offsets(fits))
    legs_only = {j for j, _, _ in legs}
    share = {e.joint: e.generating_share for e in energy if e.joint in legs_only}
    return rows, walk.pulls(), share, files


def run_study(robot: Robot, output_dir: Path, steps: int = 10, knee_steps: int = 5,
              progress: StageProgress | None = None, steps_done: Steps | None = None) -> StudyResult:
    """Run the study and write its logs, estimates, parameters and figures to ``output_dir``.

    Args:
        robot: a biped with thesis joint groups (``hip_roll`` ... ``ankle_pitch``).
        steps: steps per direction of the combined walk.
        knee_steps: steps of the right-knee walk (Fig. 6.1-6.3).
        progress: called with a label as each stage starts (:data:`~wbfriction.progress.StageProgress`).
        steps_done: told of the stages of counted items (the walks' samples simulated, the legs' joints fitted;
            :data:`~wbfriction.progress.Steps`).
    """
    say = progress or (lambda label: None)
    make_folder(output_dir)
    legs = leg_joints(robot)
    knee = right_knee(legs)
    # 1. right knee only: Fig. 6.1-6.3
    truth_err, knee_rms, knee_pulls, knee_files = _derivative_schemes(robot, legs, knee, knee_steps, output_dir, say,
                                                                        steps_done)
    # 2. combined walk, Table 6.1 friction on all leg joints: identification
    rows, walk_pulls, share, walk_files = _identification(robot, legs, steps, output_dir, say, steps_done)
    pulls = sum(p.samples for p in knee_pulls + walk_pulls)
    in_double = sum(p.double_support for p in knee_pulls + walk_pulls)
    return StudyResult(rows, truth_err, knee_rms, pulls, knee_files + walk_files, share, in_double)
