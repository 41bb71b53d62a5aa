"""A walking robot's log as its logger writes it, against the simulated twin's truth (``bench_walking_logs.py``).

Each case (a trot and a walk, noise-free and with a Unitree-like robot's noise) simulates the MuJoCo Go2 writing
the raw log a real robot's logger writes (:mod:`wbfriction.sim.logger`: no contact flag, no foot force, no base
pose, an IMU without accelerometer, torques from motor currents with torque constants a few per cent off, a logger
repeating samples, no stamps), then scores each step of :mod:`wbfriction.pipeline.raw_log` against the truth the
simulator wrote beside it:

* **repeats**: whether the samples kept are exactly the drives' distinct samples (``sample_true``);
* **contacts**: the share of samples (and feet) whose inferred state is the simulator's (``contact_true.<frame>``),
  the share left out as not confident, and how many of the samples that differ the friction's fit used (a foot
  grazing the ground with a few newtons near its lift-off or touch-down differs, inside the margins no fit uses);
* **base velocity**: the RMS error of the base's linear velocity over its RMS speed (``base_qd_true``);
* **friction**: ``estimate`` and ``fit`` run on the raw log as a user runs them, each fit scored against the
  injected friction (:func:`~wbfriction.studies.status.fits_from_params`): good when F_c and F_v lie within 5 %
  (noise-free) or 10 % (noisy);
* **the inference's cost**: the same log with the simulator's contact flags and base pose given, estimated and
  fitted the same way: where both fits are ``ok``, the largest relative difference of F_c and F_v;
* **the self-consistency check** a user can run without truth (:mod:`wbfriction.fit.stance_check`): the base's
  balance on the stances with no friction, with the ``ok`` fits' friction (the fits a user would export), with the
  true friction of the same joints and with the true friction of every joint.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa

from wbfriction.logs.columns import BASE_COLUMNS

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.studies.status import JointFit

TWIN_ROBOT = "go2_logged"
"""The twin's robot (``--robot``): the built-in ``go2_logged``."""
DURATION = 8.0
"""Simulated seconds per case."""
RATE = "819.672131"
"""The twin logger's nominal rate [Hz] (its 1.22 ms period), given as a user gives it (``--rate``): the raw log has
no stamps."""
ROUTE: tuple[str, ...] = ()
"""The route options the cases take: none, the defaults a user runs."""


@dataclass(frozen=True)
class WalkingCase:
    """One case: the gait, whether the sensors are a real robot's (noisy), and the twin's MuJoCo contacts
    (``simulate --contacts``: ``soft``, MuJoCo's default, whose stance feet creep about 1.5 cm/s; ``firm``, feet that
    hold)."""

    gait: str
    noisy: bool
    contacts: str = "soft"

    @property
    def name(self) -> str:
        """``trot``, ``walk-noisy``, ... (``-firm`` after on firm contacts)."""
        return self.gait + ("-noisy" if self.noisy else "") + ("" if self.contacts == "soft" else f"-{self.contacts}")


CASES = tuple(WalkingCase(g, n) for g in ("trot", "walk") for n in (False, True))
"""The benchmark's cases."""


@dataclass(frozen=True)
class WalkingScore:
    """One case's scores (module docstring); fits: per joint ``(status, F_c error, F_v error)`` (shares),
    given_gap: the largest relative difference between the raw and the given route's values where both are ``ok``
    (NaN: none both ``ok``); stance: the base's RMS moment residual on the stances [N·m] without friction, with the
    ``ok`` fits' friction, with the true friction of the same joints, with every joint's true friction
    (:mod:`wbfriction.fit.stance_check`; NaN where no fit is ``ok``); fitted_disagreement: the samples whose inferred
    contact state differs from the simulator's at a foot whose leg's friction the fit used there."""

    case: str
    rows: int
    samples: int
    repeats_exact: bool
    contact_agreement: float
    contact_agreement_confident: float
    unsure_share: float
    velocity_error: float
    fits: dict[str, tuple[str, float, float]]
    given_fits: dict[str, tuple[str, float, float]]
    given_gap: float
    stance: tuple[float, float, float, float] = (float("nan"),) * 4
    fitted_disagreement: int = 0

    def good(self, tolerance: float) -> tuple[int, int]:
        """``(ok and within tolerance, ok)``."""
        ok = [f for f in self.fits.values() if f[0] == "ok"]
        return sum(1 for f in ok if max(f[1], f[2]) <= tolerance), len(ok)


def _run(args: list[str], cwd: Path) -> None:
    """``wbfriction <args>`` in ``cwd`` (:func:`~wbfriction.studies.real_data.run_route`)."""
    from wbfriction.studies.real_data import run_route

    run_route([shlex.join(["wbfriction", *args])], cwd)


def simulate(case: WalkingCase, folder: Path, seed: int = 0, robot: str = TWIN_ROBOT) -> Path:
    """The raw log of ``case`` in ``folder`` (``wbfriction simulate ... --logger raw``) of the twin ``robot``'s
    TOML (default the Go2's, :data:`TWIN_ROBOT`)."""
    out = folder / f"{case.name}_raw.parquet"
    noise = ["--sensor-noise", "unitree", "--noise-seed", str(seed + 1)] if case.noisy else []
    _run(["simulate", "--robot", str(robot), "--simulator", "mujoco", "--gait", case.gait, "--duration",
          str(DURATION), "--logger", "raw", "--contacts", case.contacts, *noise, "-o", str(out)], folder)
    return out


MARGINS = 0.15
"""[s] The thesis's lift-off and touch-down margins together (6.2.1, the estimate's defaults): a phase no longer is
not estimated, so a flag's run shorter than them is a bounce, merged into the phase around it (:func:`debounced`)."""


def debounced(flags: np.ndarray, dt: float, shortest: float = MARGINS) -> np.ndarray:
    """``flags`` (N,) bool with every run shorter than ``shortest`` [s] between two runs of the other state merged
    into them: the simulator's contact state (a nonzero normal force) bounces on a soft contact's touch-down, a
    user's flags (from a force or a toe's height, with hysteresis) do not."""
    out = flags.copy()
    edges = np.flatnonzero(np.diff(out.astype(np.int8))) + 1
    bounds = np.r_[0, edges, out.size]
    for a, b in zip(bounds[1:-2], bounds[2:-1]):  # inner runs only: a log's first and last are kept
        if (b - a) * dt < shortest:
            out[a:b] = out[a - 1]
    return out


def given_log(prepared: pa.Table, robot_frames: tuple[str, ...], dt: float) -> pa.Table:
    """The prepared log with the simulator's contact flags (:func:`debounced`) and base pose in place of the inferred
    ones (and no ``unsure`` row): the route a user with flags and a pose made outside the tool would take."""
    names = [c for c in prepared.column_names if c != "unsure" and not c.startswith(("contact.", "base."))]
    out = prepared.select(names)
    for f in robot_frames:
        flags = debounced(np.asarray(prepared.column(f"contact_true.{f}")) > 0, dt)
        out = out.append_column(f"contact.{f}", pa.array(flags.astype(np.int8)))
    for c in BASE_COLUMNS:
        out = out.append_column(c, prepared.column(c.replace("base.", "base_true.")))
    return out.replace_schema_metadata(prepared.schema.metadata)


def _estimate_fit(log: Path, robot: str, stem: str, folder: Path, truth: dict) -> dict[str, JointFit]:
    """``estimate`` and ``fit`` of ``log`` as a user runs them, each joint's fit against the truth."""
    from wbfriction.studies.status import fits_from_params

    friction, params = folder / f"{stem}_friction.parquet", folder / f"{stem}_params.json"
    rate = ["--rate", RATE] if "_raw" in log.name else []
    _run(["estimate", str(log), "--robot", str(robot), *rate, *ROUTE, "-o", str(friction)], folder)
    _run(["fit", str(friction), "-o", str(params)], folder)
    return {f.joint: f for f in fits_from_params(params, truth["friction_true"])}


def _summary(fits: dict[str, JointFit]) -> dict[str, tuple[str, float, float]]:
    """Per joint ``(status, F_c error, F_v error)``."""
    out = {}
    for joint, fit in fits.items():
        errors = {p.name: p.error for p in fit.parameters}
        out[joint] = (fit.status, errors.get("F_c", float("nan")), errors.get("F_v", float("nan")))
    return out


def _gap(fits: dict[str, JointFit], given: dict[str, JointFit]) -> float:
    """The largest relative difference of F_c and F_v between the raw route's fits and the given route's, where
    both are ``ok`` (NaN: none)."""
    gaps = []
    for joint, fit in fits.items():
        other = given.get(joint)
        if fit.status != "ok" or other is None or other.status != "ok":
            continue
        theirs = {p.name: p.value for p in other.parameters}
        gaps += [abs(p.value - theirs[p.name]) / abs(theirs[p.name]) for p in fit.parameters
                 if p.name in theirs and theirs[p.name] != 0]
    return max(gaps) if gaps else float("nan")


def score_case(case: WalkingCase, folder: Path, twin: str = TWIN_ROBOT) -> WalkingScore:
    """Simulate, prepare, estimate and fit ``case`` in ``folder`` (module docstring) on the twin robot's TOML
    ``twin`` (default the Go2's)."""
    import pyarrow.parquet as pq

    from wbfriction.logs.options import ReadOptions
    from wbfriction.model.loading import RobotSpec
    from wbfriction.pipeline.raw_log import prepare_raw
    from wbfriction.studies.status import log_truth

    raw = simulate(case, folder, robot=twin)
    robot = RobotSpec.given(str(twin)).load()
    table = pq.read_table(raw)
    prepared = prepare_raw(table, robot, str(raw), ReadOptions(rate=float(RATE)))
    out = prepared.table
    sample = np.asarray(out.column("sample_true"))
    raw_sample = np.asarray(table.column("sample_true"))
    exact = bool(np.array_equal(sample, raw_sample[np.r_[True, np.diff(raw_sample) != 0]]))
    truth_c = np.column_stack([np.asarray(out.column(f"contact_true.{f}")) for f in robot.contact_frames]) > 0
    inferred, confident = prepared.contacts.contact, prepared.contacts.confident
    true_v = np.column_stack([np.asarray(out.column(f"base_qd_true.{a}")) for a in ("vx", "vy", "vz")])
    error = prepared.base.twist[:, :3] - true_v
    velocity_error = float(np.sqrt(np.mean(np.sum(error ** 2, axis=1)) / np.mean(np.sum(true_v ** 2, axis=1))))
    truth = log_truth(raw)
    fits = _estimate_fit(raw, twin, case.name, folder, truth)
    given = folder / f"{case.name}_given.parquet"
    t = np.asarray(out.column("time"))
    pq.write_table(given_log(out, robot.contact_frames, float(np.median(np.diff(t)))), given)
    given_fits = _estimate_fit(given, twin, case.name + "_given", folder, truth)
    return WalkingScore(case.name, len(table), len(sample), exact, float(np.mean(inferred == truth_c)),
                        float(np.mean((inferred == truth_c)[confident])) if confident.any() else float("nan"),
                        float(prepared.contacts.unconfident_rows().mean()), velocity_error, _summary(fits),
                        _summary(given_fits), _gap(fits, given_fits),
                        _stance(robot, out, folder / f"{case.name}_params.json", truth),
                        _fitted_disagreement(robot, folder / f"{case.name}_friction.parquet", inferred != truth_c))


def _fitted_disagreement(robot: Robot, friction: Path, disagree: np.ndarray) -> int:
    """Of ``disagree`` (N, n_c), the samples at a foot whose leg has a joint the friction table ``friction`` marks
    valid there (the samples a fit of that leg uses)."""
    import pyarrow.parquet as pq

    table = pq.read_table(friction)
    valid = np.column_stack([np.asarray(table.column(f"valid.{j}")) > 0 for j in robot.torque_controlled])
    return int(sum((disagree[:, c] & valid[:, leg].any(axis=1)).sum() for c, leg in enumerate(robot.limb_mask)))


def _stance(robot: Robot, prepared: pa.Table, params: Path, truth: dict) -> tuple[float, float, float, float]:
    """:attr:`WalkingScore.stance`."""
    from wbfriction.fit.params_file import read_params
    from wbfriction.fit.stance_check import log_stance_checks, trusted_friction
    from wbfriction.friction.models import target_from_dict
    from wbfriction.logs.log import log_from_table

    log = log_from_table(prepared, robot, "prepared")
    true = {j: target_from_dict(p) for j, p in truth["friction_true"].items()}
    ok = trusted_friction(read_params(params))
    if not ok:
        every = log_stance_checks(robot, log, [true])[0]
        return every.moment_without, float("nan"), float("nan"), every.moment_with
    every, fitted, theirs = log_stance_checks(robot, log, [true, ok, {j: true[j] for j in ok}])
    return every.moment_without, fitted.moment_with, theirs.moment_with, every.moment_with


def markdown(scores: list[WalkingScore]) -> str:
    """The benchmark's table (one row per case) and the per-joint fits."""
    lines = ["| case | rows → samples | repeats exact | contacts agree | (confident) | left out | base velocity "
             "error | fits ok | ok within 5 % / 10 % | given vs raw (both ok) | stance moment [N·m]: none / ok fits "
             "/ their truth / all truth | contacts differing where fitted |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for s in scores:
        tol = 0.10 if "-noisy" in s.case else 0.05
        good, ok = s.good(tol)
        gap = "–" if np.isnan(s.given_gap) else f"{s.given_gap:.1%}"
        lines.append(f"| {s.case} | {s.rows} → {s.samples} | {'yes' if s.repeats_exact else 'NO'} | "
                     f"{s.contact_agreement:.1%} | {s.contact_agreement_confident:.1%} | {s.unsure_share:.1%} | "
                     f"{s.velocity_error:.1%} | {ok}/{len(s.fits)} | {good}/{ok} | {gap} | "
                     f"{' / '.join('–' if np.isnan(x) else f'{x:.3f}' for x in s.stance)} | {s.fitted_disagreement} |")
    return "\n".join(lines)
