"""What ``demo`` shows of a biped: the thesis's simulation study, walk, estimate, fit (Tables 6.1/6.2, Fig. 6.1-6.3:
:func:`~wbfriction.studies.simulation.run_study`), or on soft contacts the realistic simulator's (Fig. 6.4-6.5:
:func:`~wbfriction.studies.realistic.run_realistic_study`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from wbfriction.report.printed import Printed
from wbfriction.rigs.base import DemoOutput, RigProgress

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot


def thesis_demo(robot: Robot, output_dir: Path, steps: int, progress: RigProgress) -> DemoOutput:
    """The thesis's study on the ideal simulator: its fits not ``ok`` and why, Table 6.1's layout, the worst
    errors, the true accelerations' error, the knee's RMS errors, the pulls and the power-generating share."""
    from wbfriction.friction.models import PARAM_NAMES
    from wbfriction.studies.common import worst_errors
    from wbfriction.studies.simulation import run_study
    from wbfriction.studies.tables import not_ok_printed, pulls_note, study_table, worst_printed

    result = run_study(robot, output_dir, steps=steps, progress=progress.say, steps_done=progress.count)
    printed = not_ok_printed(result.rows)  # before the table: its error figures of those joints measure the walk
    printed.append(Printed(study_table(result.rows, "Identified friction (3.5) of the leg joints, combined walk, "
                                                    "central differences")))
    printed += worst_printed(result.rows, worst_errors([row for row in result.rows if row.fit.verdict().ok]),
                             PARAM_NAMES)
    worst_joint = max(result.generating_share, key=lambda j: result.generating_share[j])
    printed += [Printed(line) for line in (
        f"true accelerations: max |tau_f - tau_f_true| in single support = {result.truth_max_error:.2e} N·m",
        "right knee, RMS error [N·m] with the leg in swing / in stance: " + "; ".join(
            f"{k} {a:.4f} / {b:.4f}" for k, (a, b) in result.knee_rms.items()),
        pulls_note(result.pulls, result.pulls_double_support),
        f"friction generating power (eq. 7.9), leg joints in swing: at most "
        f"{100 * result.generating_share[worst_joint]:.2f} % of the samples ({worst_joint})")]
    return DemoOutput(tuple(printed), tuple(result.files))


def realistic_demo(robot: Robot, output_dir: Path, steps: int, progress: RigProgress) -> DemoOutput:
    """The realistic simulator's study (a short combined walk, short forward walks too: the full size's are 5
    steps): per case its fits not ``ok``, its table, its worst errors and the thesis's route's on the same log; the
    knee's RMS errors."""
    from wbfriction.studies.realistic import KNEE_STEPS, run_realistic_study, worst_scored
    from wbfriction.studies.tables import not_ok_printed, study_table, worst_printed

    result = run_realistic_study(robot, output_dir, steps=steps, knee_steps=min(steps, KNEE_STEPS),
                                 progress=progress.say)
    printed: list[Printed] = []
    for k, case in enumerate(result.cases):
        if k:
            printed.append(Printed(""))
        printed += not_ok_printed(case.rows)
        printed.append(Printed(study_table(case.rows, f"MuJoCo, combined walk, swing phase: {case.label}",
                                           case.scored)))
        ok = [row for row in case.rows if row.fit.verdict().ok]
        printed += worst_printed(case.rows, worst_scored(case, ok), case.scored)
        if case.thesis_rows is not None:  # the thesis's comparison: the same log, rigid contacts, no wrenches
            thesis = worst_scored(case, [row for row in case.thesis_rows if row.fit.verdict().ok])
            printed.append(Printed("  the thesis's route on the same log (rigid stance contact, no wrenches) [%]: "
                                   + ", ".join(f"{n} {thesis[n]:.2f}" for n in case.scored)))
    printed.append(Printed("right knee alone, RMS error [N·m] (central differences): " + "; ".join(
        f"{k} {v:.4f}" for k, v in result.knee_rms.items())))
    return DemoOutput(tuple(printed), tuple(result.files))
