"""Which differentiation scheme serves noisy logs best (thesis 7.1-7.2, Fig. 7.2): ``wbfriction study-filters``.

The combined walk of the demo (:mod:`wbfriction.studies.simulation`, Table 6.1 friction on the leg
joints) is simulated once; sensor noise is then added at several levels
(:class:`~wbfriction.sim.sensors.SensorNoise`: position noise, a 19-bit encoder, torque
noise) and every scheme estimates and identifies the friction of the leg joints. Each row
of the result gives, for one noise level and one scheme, the RMS error of the estimate
against ``tau_f_true`` on the valid leg samples, the worst error of every identified
parameter over the 12 leg joints, and the largest standard error of F_v the fit itself
reports (relative to its estimate): what a user without the truth would see.
"""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.fit.joints import fit_joints
from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.models import PARAM_NAMES, FrictionParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import Log
from wbfriction.logs.tables import make_folder, write_json, write_table
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress
from wbfriction.report.figures import filter_curves_figure
from wbfriction.signals.options import Diff, FilterOptions
from wbfriction.sim import apply_sensor_noise, simulate_ideal
from wbfriction.sim.options import SensorNoise
from wbfriction.studies.common import ENCODER_BITS, SIMULATOR, TORQUE_STD, leg_joints, right_knee
from wbfriction.walking import walking_reference
from wbfriction.walking.options import GaitOptions
from wbfriction.workers import process_pool

LEVELS: tuple[float | None, ...] = (None, 0.0, 1e-5, 1e-4, 1e-3)
"""Position noise standard deviations [rad]; None: an exact log (no sensor model at all);
the others come with the 19-bit encoder and 0.05 N·m of torque noise."""


@dataclass(frozen=True)
class Scheme:
    """A differentiation scheme with its parameters, as the study names it."""

    label: str
    diff: Diff
    filtering: FilterOptions = FilterOptions()

    def options(self) -> EstimateOptions:
        return EstimateOptions(diff=self.diff, filtering=self.filtering, route="acceleration", check_route=False)


SCHEMES: tuple[Scheme, ...] = (
    Scheme("central", "central"),
    *(Scheme(f"savgol L={n} k=4", "savgol", FilterOptions(window=n, poly_order=4)) for n in (51, 101, 151, 201)),
    Scheme("savgol L=151 k=4 gaussian", "savgol", FilterOptions(window=151, poly_order=4, weights="gaussian")),
    *(Scheme(f"butterworth {fc:g} Hz n=6", "butterworth", FilterOptions(cutoff=fc, butter_order=6))
      for fc in (10.0, 20.0)),
)


@dataclass
class FilterStudyRow:
    """One noise level and one scheme."""

    position_std: float | None
    scheme: str
    n_samples: int  # fewest valid samples of a leg joint
    rms_error: float  # RMS of tau_f - tau_f_true over the valid leg samples [N·m]
    worst: dict[str, float]  # largest error of each parameter over the leg joints [%]
    worst_se_F_v: float = float("nan")  # largest standard error of F_v relative to its estimate [%]

    @property
    def score(self) -> float:
        """The worst error of F_v, F_c and tau_os [%]: what the best scheme minimises."""
        return max(self.worst[n] for n in ("F_v", "F_c", "tau_os"))


@dataclass
class FilterStudyResult:
    rows: list[FilterStudyRow]
    files: list[Path] = field(default_factory=list)

    def best(self, position_std: float | None) -> FilterStudyRow:
        """The scheme with the lowest :attr:`FilterStudyRow.score` at one noise level."""
        return min((r for r in self.rows if r.position_std == position_std), key=lambda r: r.score)


_Task = tuple[int, int, int, str | None]
"""One run of the grid: level index, scheme index, seed, the joint whose curve to keep (or None)."""


_STATE: dict = {}  # the robot, log and targets, shared with the worker processes (fork)


def _noisy(level: float | None, seed: int) -> Log:
    log = _STATE["log"]
    if level is None:
        return log
    return apply_sensor_noise(log, SensorNoise(level, ENCODER_BITS, TORQUE_STD, seed=seed))


def _run(task: _Task) -> tuple[FilterStudyRow, dict | None]:
    i_level, i_scheme, seed, curve_joint = task
    robot, legs, targets = _STATE["robot"], _STATE["legs"], _STATE["targets"]
    level, scheme = _STATE["levels"][i_level], _STATE["schemes"][i_scheme]
    est = estimate_log(robot, _noisy(level, seed + i_level), scheme.options())
    idx = [est.joints.index(j) for j in legs]
    fits = fit_joints(legs, est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx], targets=targets,
                        smoother=est.smoother)
    valid = est.valid[:, idx]
    err = (est.tau_f - est.tau_f_true)[:, idx][valid]
    worst = {n: max((f.error_percent() or {n: float("inf")})[n] for f in fits) for n in PARAM_NAMES}
    se_F_v = [100 * f.stderr["F_v"] / abs(f.params.F_v) if f.params is not None and f.params.F_v else float("inf")
              for f in fits]
    row = FilterStudyRow(level, scheme.label, int(valid.sum(axis=0).min()),
                         float(np.sqrt(np.mean(err**2))) if err.size else float("nan"), worst, max(se_F_v))
    curve = None
    if curve_joint is not None:
        i = est.joints.index(curve_joint)
        m = est.valid[:, i]
        fit = fits[legs.index(curve_joint)]
        curve = {"qd": est.qd[m, i], "tau_f": est.tau_f[m, i],
                 "fit": None if fit.params is None else fit.params.to_dict()}
    return row, curve


def _run_grid(tasks: list[_Task], workers: int, say: StageProgress) -> list[tuple[FilterStudyRow, dict | None]]:
    """Every run of ``tasks`` in their order, on ``workers`` forked processes or (1) in this one."""
    results: list = [None] * len(tasks)
    if workers > 1:
        with process_pool(workers, "fork") as pool:
            for k, res in enumerate(pool.map(_run, tasks)):
                results[k] = res
                say(f"{k + 1}/{len(tasks)} runs done")
    else:
        for k, task in enumerate(tasks):
            results[k] = _run(task)
            say(f"{k + 1}/{len(tasks)} runs done")
    return results


def _table(rows: list[FilterStudyRow]) -> pa.Table:
    """The rows as the study's Parquet table."""
    return pa.table({
        "position_std": pa.array([r.position_std for r in rows], pa.float64()),
        "exact_log": [r.position_std is None for r in rows],
        "scheme": [r.scheme for r in rows],
        "n_samples": [r.n_samples for r in rows],
        "rms_error": [r.rms_error for r in rows],
        **{f"worst_{n}_percent": [r.worst[n] for r in rows] for n in PARAM_NAMES},
        "worst_stderr_F_v_percent": [r.worst_se_F_v for r in rows],
    })


def _write_outputs(output_dir: Path, robot: Robot, steps: int, seed: int, schemes: tuple[Scheme, ...],
                   rows: list[FilterStudyRow], curves: dict[str, dict], knee: str, target: FrictionParams,
                   curve_level: float | None) -> list[Path]:
    """Write the study's table, JSON document and Fig. 7.2-kind curves; the files written."""
    files = [output_dir / "filter_study.parquet", output_dir / "filter_study.json", output_dir / "filter_curves.png"]
    write_table(_table(rows), files[0])
    doc = {"robot": robot.name, "gait": asdict(GaitOptions(gait="combined", steps=steps)),
           "sensor": {"encoder_bits": ENCODER_BITS, "torque_std": TORQUE_STD, "seed": seed},
           "schemes": {s.label: {"diff": s.diff, "filtering": asdict(s.filtering)} for s in schemes},
           "rows": [asdict(r) for r in rows]}
    write_json(files[1], doc)
    filter_curves_figure(curves, knee, target, curve_level, files[2])
    return files


def run_filter_study(robot: Robot, output_dir: Path, steps: int = 10, levels: tuple[float | None, ...] = LEVELS,
                     schemes: tuple[Scheme, ...] = SCHEMES, curve_level: float | None = 1e-4, seed: int = 0,
                     workers: int | None = None,
                     progress: StageProgress | None = None) -> FilterStudyResult:
    """Run the study and write ``filter_study.parquet``, ``filter_study.json`` and the
    Fig. 7.2-kind ``filter_curves.png`` (right knee at ``curve_level``) to ``output_dir``.

    Args:
        robot: a biped with thesis joint groups.
        steps: steps per direction of the combined walk.
        levels: position-noise levels (:data:`LEVELS`); schemes: :data:`SCHEMES`.
        seed: noise seed (level ``i`` uses ``seed + i``): the same seed, the same study.
        workers: processes (default: the CPUs available, at most 2 per the project's plan).
        progress: called with a label as stages start and runs end (:data:`~wbfriction.progress.StageProgress`).
    """
    say = progress or (lambda label: None)
    make_folder(output_dir)
    legs3 = leg_joints(robot)
    legs = [j for j, _, _ in legs3]
    targets = {j: THESIS_TARGETS[g] for j, _, g in legs3}
    knee = right_knee(legs3)
    say(f"simulating the combined walk ({steps} steps per direction)")
    ref = walking_reference(robot, GaitOptions(gait="combined", steps=steps))
    log = simulate_ideal(robot, ref, targets, SIMULATOR).log
    _STATE.update(robot=robot, log=log, legs=legs, targets=targets, levels=levels, schemes=schemes)
    tasks = [(il, isc, seed, knee if levels[il] == curve_level else None)
             for il in range(len(levels)) for isc in range(len(schemes))]
    workers = workers or min(2, len(os.sched_getaffinity(0)))
    say(f"estimating and fitting: {len(levels)} noise levels x {len(schemes)} schemes")
    results = _run_grid(tasks, workers, say)
    _STATE.clear()
    rows = [r for r, _ in results]
    curves = {schemes[t[1]].label: c for t, (_, c) in zip(tasks, results) if c is not None}
    files = _write_outputs(output_dir, robot, steps, seed, schemes, rows, curves, knee, targets[knee], curve_level)
    return FilterStudyResult(rows, files)
