"""Whether a fit's status holds against the truth (issue 63): ``benchmarks/bench_status.py``.

Simulated logs carry the friction (and, for a hung PD-driven robot, the armature, encoder offsets and delay) their
simulator injected, in the log's metadata (``friction_true``, ``armature_true``, ``encoder_offset_true``,
``delay_true``). Each case (:data:`CASES`) runs the route the docs give a user, with defaults, each command its own
process (:func:`~wbfriction.studies.real_data.run_route`), and is scored from what the route wrote alone: the
parameters JSON of ``fit`` (per joint ``status``, ``params``, ``stderr``, ``crb``, ``speed``) or the JSON of
``identify --actuator pd --json`` (per value ``value``, ``se``, ``crb``, ``status``). So the score does not depend
on how the statuses are decided, only on what the files say.

Per case (:class:`CaseScore`):

* four counts of fits: ``ok`` and good, ``ok`` and bad, not ``ok`` and good, not ``ok`` and bad. A fit is good
  when F_c and F_v are within :data:`GOOD_NOISE_FREE` of the truth (relative error) on a noise-free log,
  :data:`GOOD_NOISY` on a noisy one; a parameter the log does not excite is left out of that judgement (a joint
  that did not move: its F_v, and on a PD-driven robot its armature and the delay; :func:`excited`);
* the coverage of ±:data:`SE_WIDTH` standard errors: the share of the fitted parameters (F_c, F_v; for ``identify
  --actuator pd`` also the armature, the offset and the delay), excited and with a finite standard error, whose
  truth lies within two standard errors of the value;
* the number of standard errors below their Cramér-Rao bound (where both are finite);
* the parameters not excited, and how many of them belong to an ``ok`` fit (a value called ``ok`` that the log does
  not determine).

The issue's targets (:meth:`CaseScore.targets_met`): no ``ok`` fit that is bad, a coverage of at least
:data:`COVERAGE_TARGET`, no standard error below its bound.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from wbfriction.fit.route_spread import route_spread as route_spread_of
from wbfriction.fit.status import MIN_SPEED, joint_speed, read_error

GOOD_NOISE_FREE = 0.05
"""A fit on a noise-free log is good when F_c and F_v lie within this share of the truth (the issue's 5 %)."""
GOOD_NOISY = 0.10
"""... on a noisy log (sensor or driver noise), within this share (the issue's 10 %)."""
SE_WIDTH = 2.0
"""A parameter's truth is covered when it lies within so many standard errors of the value."""
COVERAGE_TARGET = 0.90
"""The issue's target: at least this share of the parameters covered."""
FRICTION = ("F_c", "F_v")
"""The friction parameters every fit is judged on (the same names in every family)."""
ACTUATOR = ("armature", "offset")
"""The per-joint values of ``identify --actuator pd`` scored beside F_c and F_v (and the delay, once per log)."""
NOT_OK = "not ok"


@dataclass(frozen=True)
class ParameterFit:
    """One fitted parameter against its truth.

    Attributes:
        name: ``F_c``, ``F_v``, ``armature``, ``offset`` or ``delay``.
        value, se, crb: the fitted value, its standard error and its Cramér-Rao bound, in the parameter's unit
            (N·m, N·m·s/rad, kg·m², rad, s); ``se`` and ``crb`` NaN where the file gives none (``null``: not
            identifiable).
        truth: the value the simulator injected.
        excited: whether the log excites it (False: "not excited", left out of the judgement and the coverage).
    """

    name: str
    value: float
    se: float
    crb: float
    truth: float
    excited: bool = True

    @property
    def error(self) -> float:
        """The relative error ``|value - truth| / |truth|`` (NaN for a truth of zero)."""
        return abs(self.value - self.truth) / abs(self.truth) if self.truth != 0 else float("nan")

    @property
    def covered(self) -> bool | None:
        """Whether the truth lies within :data:`SE_WIDTH` standard errors; None: not scored (not excited, or no
        finite standard error)."""
        if not self.excited or not math.isfinite(self.se):
            return None
        return abs(self.value - self.truth) <= SE_WIDTH * self.se

    @property
    def below_crb(self) -> bool | None:
        """Whether the standard error is below its Cramér-Rao bound; None: one of them not finite."""
        if not (math.isfinite(self.se) and math.isfinite(self.crb)):
            return None
        return self.se < self.crb


@dataclass(frozen=True)
class JointFit:
    """One joint's fit as a file gave it: its status and its parameters against the truth."""

    joint: str
    status: str
    parameters: tuple[ParameterFit, ...]

    def judged(self) -> tuple[ParameterFit, ...]:
        """The friction parameters (:data:`FRICTION`) the log excites: those the fit is judged on."""
        return tuple(p for p in self.parameters if p.name in FRICTION and p.excited)

    def good(self, tolerance: float) -> bool:
        """Whether every judged parameter lies within ``tolerance`` (a share) of its truth; a fit without
        parameters, or none excited, is not good."""
        judged = self.judged()
        return bool(judged) and all(p.error <= tolerance for p in judged)

    def worst_error(self) -> float:
        """The largest relative error of the judged parameters (NaN: none)."""
        return max((p.error for p in self.judged()), default=float("nan"))


@dataclass(frozen=True)
class CaseScore:
    """A case's fits counted (module docstring); ``tolerance`` the share a good fit is within."""

    case: str
    tolerance: float
    ok_good: int = 0
    ok_bad: int = 0
    not_ok_good: int = 0
    not_ok_bad: int = 0
    covered: int = 0
    scored: int = 0
    below_crb: int = 0
    with_crb: int = 0
    not_excited: int = 0
    ok_not_excited: int = 0
    worst_ok_error: float = float("nan")
    ok_bad_joints: tuple[str, ...] = ()
    failed: str = ""
    seconds: float = float("nan")

    @property
    def coverage(self) -> float:
        """The share of the scored parameters whose truth lies within ±2 standard errors (NaN: none scored)."""
        return self.covered / self.scored if self.scored else float("nan")

    def targets_met(self) -> dict[str, bool]:
        """The issue's targets: ``ok`` fits within the tolerance, coverage >= :data:`COVERAGE_TARGET`, no
        standard error below its Cramér-Rao bound (a case that failed meets none)."""
        if self.failed:
            return {"ok within tolerance": False, "coverage": False, "no SE below CRB": False}
        return {"ok within tolerance": self.ok_bad == 0,
                "coverage": bool(self.scored) and self.coverage >= COVERAGE_TARGET,
                "no SE below CRB": self.below_crb == 0}

    def to_dict(self) -> dict[str, Any]:
        """The score as JSON (NaN as null)."""
        d = asdict(self)
        d["coverage"], d["targets_met"] = self.coverage, self.targets_met()
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}


def score_fits(case: str, fits: Iterable[JointFit], noisy: bool) -> CaseScore:
    """Count ``fits`` (module docstring): good within :data:`GOOD_NOISY` if ``noisy``, else
    :data:`GOOD_NOISE_FREE`; a parameter shared by every joint (the delay) is given once, on any one of them."""
    tolerance = GOOD_NOISY if noisy else GOOD_NOISE_FREE
    counts = {"ok_good": 0, "ok_bad": 0, "not_ok_good": 0, "not_ok_bad": 0}
    covered = scored = below = with_crb = not_excited = ok_not_excited = 0
    worst, bad = float("nan"), []
    for fit in fits:
        good, ok = fit.good(tolerance), fit.status == "ok"
        counts[("ok_" if ok else "not_ok_") + ("good" if good else "bad")] += 1
        if ok:
            worst = max((e for e in (worst, fit.worst_error()) if math.isfinite(e)), default=float("nan"))
            if not good:
                bad.append(fit.joint)
        for p in fit.parameters:
            not_excited += not p.excited
            ok_not_excited += ok and not p.excited
            if p.covered is not None:
                scored += 1
                covered += p.covered
            if p.below_crb is not None:
                with_crb += 1
                below += p.below_crb
    return CaseScore(case, tolerance, counts["ok_good"], counts["ok_bad"], counts["not_ok_good"], counts["not_ok_bad"],
                     covered=covered, scored=scored, below_crb=below, with_crb=with_crb, not_excited=not_excited,
                     ok_not_excited=ok_not_excited, worst_ok_error=worst, ok_bad_joints=tuple(bad))


def _number(x: Any) -> float:
    """A JSON number, ``null`` as NaN."""
    return float("nan") if x is None else float(x)


def excited(speed: float | None, status: str) -> bool:
    """Whether a joint moved enough for its velocity's parameters (F_v) to be in the log: its 95th percentile of
    ``|qd|`` (the parameters JSON's ``speed``, :func:`~wbfriction.fit.status.joint_speed`) at least
    :data:`~wbfriction.fit.status.MIN_SPEED`, the threshold of the status ``not excited``; a speed not given
    counts as moved unless the status says ``not excited``."""
    if status == "not excited":
        return False
    return speed is None or speed >= MIN_SPEED


def fits_from_params(path: str | Path, truth: Mapping[str, Mapping[str, float]]) -> list[JointFit]:
    """Every joint of a parameters JSON (``wbfriction fit -o``) that has a truth, as :class:`JointFit`: its
    ``status``, and F_c and F_v with their ``stderr`` (the larger of it and ``block_spread``, with ``model_spread``
    and ``route_spread`` in quadrature, as a user reads them: :func:`~wbfriction.fit.status.read_error`)
    and ``crb`` (a joint without parameters: none; with terms
    kept, the velocity model refitted with them, ``terms.params`` and ``terms.stderr``, as the status judges it and
    :meth:`~wbfriction.fit.result.FitResult.reported` shows it, without a bound); ``truth``:
    per joint the injected parameters (the log's ``friction_true``). F_v is not excited on a joint that did not
    move (:func:`excited`).

    Raises:
        ValueError: a file without a ``joints`` object (naming the file).
    """
    doc = json.loads(Path(path).read_text())
    if not isinstance(doc, dict) or not isinstance(doc.get("joints"), dict):
        raise ValueError(f"{path}: no 'joints' object: not a parameters JSON of 'wbfriction fit'")
    out = []
    for joint, d in doc["joints"].items():
        if joint not in truth:
            continue
        status, params = str(d.get("status", "")), d.get("params") or {}
        moved = excited(None if d.get("speed") is None else float(d["speed"]), status)
        stderr, crb = d.get("stderr") or {}, d.get("crb") or {}
        terms = d.get("terms") or {}
        blocks, routes = d.get("block_spread") or {}, d.get("route_spread") or {}
        if terms.get("kept"):  # the model the status judges and predictions use: refitted with its terms, no bound
            params, stderr, crb = terms.get("params") or {}, terms.get("stderr") or {}, {}
            blocks, other = terms.get("block_spread") or {}, (terms.get("check") or {}).get("coefficients") or {}
            routes = {n: route_spread_of(params, other, (n,)).get(n, 0.0) for n in FRICTION}
        family = d.get("model_spread") or {}  # the standard error a user reads: the family's spread in quadrature
        out.append(JointFit(joint, status, tuple(
            ParameterFit(n, float(params[n]), read_error(_number(stderr.get(n)), float(family.get(n) or 0.0),
                                                         float(blocks.get(n) or 0.0), float(routes.get(n) or 0.0)),
                         _number(crb.get(n)), float(truth[joint][n]), moved or n != "F_v")
            for n in FRICTION if n in params and n in truth[joint])))
    return out


def fits_from_actuators(path: str | Path, truth: Mapping[str, Any], speeds: Mapping[str, float]) -> list[JointFit]:
    """Every joint of ``identify --actuator pd --json``'s document as :class:`JointFit`, its status ``ok`` when
    F_c and F_v are both ``ok`` (the friction it identified), else the first other of theirs; its parameters F_c,
    F_v, the armature and the offset (those it fitted), and on the first joint the delay. ``truth``: the log's
    metadata (``friction_true``, ``armature_true``, ``encoder_offset_true``, ``delay_true``); ``speeds``: each
    joint's 95th percentile of ``|qd|`` in the log [rad/s]: a joint that did not move excites neither its F_v nor
    its armature, and a log in which none moved not the delay.

    Raises:
        ValueError: a file that is not such a document (naming the file).
    """
    doc = json.loads(Path(path).read_text())
    if not isinstance(doc, dict) or doc.get("kind") != "pd actuators":
        raise ValueError(f"{path}: not the JSON of 'wbfriction identify --actuator pd --json'")
    true = {"F_c": {j: p["F_c"] for j, p in truth["friction_true"].items()},
            "F_v": {j: p["F_v"] for j, p in truth["friction_true"].items()},
            "armature": truth.get("armature_true", {}), "offset": truth.get("encoder_offset_true", {})}
    any_moved = any(s >= MIN_SPEED for s in speeds.values())
    out = []
    for i, (joint, d) in enumerate(doc["joints"].items()):
        moved = speeds.get(joint, math.inf) >= MIN_SPEED
        params = [ParameterFit(n, float(d[n]["value"]), _number(d[n].get("se")), _number(d[n].get("crb")),
                               float(true[n][joint]), moved or n in ("F_c", "offset"))
                  for n in (*FRICTION, *ACTUATOR) if isinstance(d.get(n), dict) and joint in true[n]]
        if i == 0 and "delay_true" in truth:
            delay = doc["delay"]
            params.append(ParameterFit("delay", float(delay["value"]), _number(delay.get("se")),
                                       _number(delay.get("crb")), float(truth["delay_true"]), any_moved))
        statuses = [str(d[n]["status"]) for n in FRICTION if isinstance(d.get(n), dict)]
        status = next((s for s in statuses if s != "ok"), "ok" if statuses else NOT_OK)
        out.append(JointFit(joint, status, tuple(params)))
    return out


def log_truth(path: str | Path) -> dict[str, Any]:
    """The simulator's metadata of a Parquet log (``friction_true`` and the rest: what it injected).

    Raises:
        ValueError: a log without the simulator's metadata (naming the file).
    """
    import pyarrow.parquet as pq

    meta = pq.read_schema(path).metadata or {}
    if b"wbfriction" not in meta:
        raise ValueError(f"{path}: no 'wbfriction' metadata: not a log of 'wbfriction simulate'")
    doc = json.loads(meta[b"wbfriction"])
    if "friction_true" not in doc:
        raise ValueError(f"{path}: its metadata has no 'friction_true': the simulator's friction is not known")
    return doc


SPEED_WINDOW = 0.1
"""The span [s] over which :func:`log_speeds` differentiates the positions: a hung robot's drivers log a velocity
with white noise (a real driver's 0.08 rad/s, :data:`~wbfriction.sim.pd_options.REAL_DRIVER`) whose 95th percentile,
0.16 rad/s, is above :data:`~wbfriction.fit.status.MIN_SPEED` on a joint held still; over 0.1 s, 19-bit encoder steps
(1.2e-5 rad) leave 1e-4 rad/s, while the slowest ramp the hung simulator sends (0.2 s or more between reversals) keeps
its speed."""


def log_speeds(path: str | Path, joints: Sequence[str]) -> dict[str, float]:
    """Each joint's 95th percentile of ``|qd|`` in the log [rad/s] (:func:`~wbfriction.fit.status.joint_speed`), its
    ``q.<joint>`` differentiated over :data:`SPEED_WINDOW` against the log's ``time``; joints without such a column
    left out."""
    from wbfriction.logs.tables import TableFile

    log = TableFile(path)  # any log format (the registry's)
    names = set(log.schema().names)
    columns = [f"q.{j}" for j in joints if f"q.{j}" in names]
    table = log.read(["time", *columns])
    t = table.column("time").to_numpy()
    w = max(1, int(round(0.5 * SPEED_WINDOW / float(np.median(np.diff(t)))))) if t.size > 1 else 1
    if t.size <= 2 * w:
        return {c[2:]: 0.0 for c in columns}
    out = {}
    for c in columns:
        q = table.column(c).to_numpy()
        out[c[2:]] = joint_speed((q[2 * w:] - q[:-2 * w]) / (t[2 * w:] - t[:-2 * w]))
    return out


@dataclass(frozen=True)
class Case:
    """One simulated case of the benchmark: the route's commands (``wbfriction ...`` lines, run in the case's
    folder), the log they simulate, the file the route's last step writes (a parameters JSON, or with ``pd`` the
    JSON of ``identify --actuator pd``), whether the log is noisy (the tolerance), and ``still``: the log is written
    by :func:`write_still_log` instead of a ``simulate`` command (no option of the command line holds the
    set-points still)."""

    name: str
    what: str
    commands: tuple[str, ...]
    log: str
    result: str
    noisy: bool
    pd: bool = False
    still: bool = False
    notes: tuple[str, ...] = field(default_factory=tuple)


def _fit_route(stem: str, simulate: str, robot: str) -> tuple[str, ...]:
    """``simulate``, then the README's estimate and fit with every default, for a log ``stem.parquet``."""
    return (f"wbfriction simulate {simulate} -o {stem}.parquet",
            f"wbfriction estimate {stem}.parquet --robot {robot} -o {stem}_friction.parquet",
            f"wbfriction fit {stem}_friction.parquet -o {stem}_params.json")


def _fit_case(name: str, what: str, simulate: str, robot: str, noisy: bool) -> Case:
    stem = name.replace("-", "_")
    return Case(name, what, _fit_route(stem, simulate, robot), f"{stem}.parquet", f"{stem}_params.json", noisy)


def _pd_case(name: str, what: str, simulate: str, still: bool = False) -> Case:
    stem = name.replace("-", "_")
    commands = (() if still else (f"wbfriction simulate --robot go2 {simulate} -o {stem}.parquet",)) + (
        f"wbfriction identify {stem}.parquet --robot go2 --actuator pd --json {stem}_actuator.json",)
    return Case(name, what, commands, f"{stem}.parquet", f"{stem}_actuator.json", True, pd=True, still=still)


CRAWL = "--robot go2_walking --gait walk --simulator mujoco --duration 6"
CASES: tuple[Case, ...] = (
    _fit_case("crawl", "Go2 crawl on point feet, MuJoCo, 6 s, no foot forces", CRAWL, "go2_walking", False),
    _fit_case("crawl-3d", "the crawl with 3-D foot forces", CRAWL + " --foot-forces 3d", "go2_walking", False),
    _fit_case("crawl-noisy", "the crawl, 19-bit encoders, 0.05 N·m torque noise",
              CRAWL + " --encoder-bits 19 --torque-noise 0.05", "go2_walking", True),
    _fit_case("arm-noisy", "Panda 30 s, 1e-4 rad position noise, 19-bit encoders",
              "--robot panda --duration 30 --position-noise 1e-4 --encoder-bits 19", "panda", True),
    _fit_case("walk", "the README's tour: TALOS, combined walk, 2 steps, ideal", "--gait combined --steps 2", "talos",
              False),
    _pd_case("pd", "hung Go2, ramps and chirps, a real driver's noise", ""),
    _pd_case("pd-still", "hung Go2, set-points held still (amplitude 0)", "", still=True),
    _pd_case("pd-late", "hung Go2, drivers 80 ms late", "--delay 80"),
)
"""The simulated cases of the benchmark (issue 63, item 7); the seeds are the simulators' defaults (0)."""


def write_still_log(path: str | Path) -> None:
    """The hung Go2 as ``wbfriction simulate --robot go2`` writes it (25 s, a real driver's noise), but its
    set-points held at the posture (:class:`~wbfriction.sim.pd_options.SetpointOptions` amplitude 0)."""
    from wbfriction.logs.tables import write_table
    from wbfriction.model.loading import load_robot
    from wbfriction.sim.hung import simulate_hung
    from wbfriction.sim.pd_options import REAL_DRIVER, HungOptions, SetpointOptions

    options = HungOptions(setpoints=SetpointOptions(amplitude=0.0), noise=REAL_DRIVER)
    write_table(simulate_hung(load_robot("go2"), options).table, Path(path))


def score_case(case: Case, folder: str | Path) -> CaseScore:
    """Score what ``case``'s route wrote in ``folder`` (module docstring)."""
    folder = Path(folder)
    truth = log_truth(folder / case.log)
    if case.pd:
        speeds = log_speeds(folder / case.log, list(truth["friction_true"]))
        fits = fits_from_actuators(folder / case.result, truth, speeds)
    else:
        fits = fits_from_params(folder / case.result, truth["friction_true"])
    return score_fits(case.name, fits, case.noisy)


def run_case(case: Case, folder: str | Path, echo: Callable[[str], None] | None = None) -> CaseScore:
    """Run ``case``'s route in ``folder`` (made if missing; each command its own process, timed:
    :func:`~wbfriction.studies.real_data.run_route`) and score it; a route that fails is a score with its message in
    :attr:`CaseScore.failed`."""
    from wbfriction.exceptions import WbfrictionError
    from wbfriction.studies.real_data import run_route

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    try:
        if case.still:
            if echo is not None:
                echo(f"(wbfriction.studies.status.write_still_log: {case.log})")
            write_still_log(folder / case.log)
        run_route(case.commands, folder, echo=echo)
        score = score_case(case, folder)
    except (WbfrictionError, ValueError, OSError) as exc:
        return CaseScore(case.name, GOOD_NOISY if case.noisy else GOOD_NOISE_FREE, failed=str(exc),
                         seconds=time.perf_counter() - start)
    return replace(score, seconds=time.perf_counter() - start)


@dataclass(frozen=True)
class RealScore:
    """A real set (no truth) through its route (:func:`~wbfriction.studies.real_data.run_dataset`): its ``ok``
    count beside ``bench_real.py``'s summary (:class:`~wbfriction.studies.real_data.Summary`)."""

    name: str
    joints: int
    ok: int
    statuses: dict[str, int]
    ok_within_error: int
    worst_error: float
    better_than_peer: int
    peers: int
    seconds: float
    failed: str = ""

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in d.items()}


REAL_TARGET_ERROR = {"ur10e": 0.05, "panda": 0.15}
"""``bench_real.py``'s curve targets: every joint (UR10e), every ``ok`` joint (Panda) within this share."""


def run_real(name: str, folder: str | Path, echo: Callable[[str], None] | None = None) -> RealScore:
    """The real set ``name`` through its route in ``folder``, counted as ``bench_real.py`` counts it."""
    from wbfriction.studies.real_data import run_dataset, summarise

    run = run_dataset(name, folder, echo=echo)
    s = summarise(run, REAL_TARGET_ERROR.get(name, math.inf))
    statuses: dict[str, int] = {}
    for j in run.joints:
        statuses[j.status] = statuses.get(j.status, 0) + 1
    return RealScore(name, s.joints, s.ok, statuses, s.ok_within_error, s.worst_error, s.better_than_peer, s.peers,
                     s.seconds, run.failed)


def _cell(x: float, fmt: str) -> str:
    return "–" if not math.isfinite(x) else format(x, fmt)


def cases_markdown(scores: Sequence[CaseScore]) -> str:
    """The simulated cases as a Markdown table, then one line per case with the issue's targets."""
    lines = ["| case | tolerance | ok, good | ok, bad | not ok, good | not ok, bad | coverage ±2 SE | "
             "SE below CRB | not excited (of ok fits) | worst ok [%] | time [s] |", "|---" * 11 + "|"]
    for s in scores:
        if s.failed:
            lines.append(f"| {s.case} | (failed) | {s.failed} | | | | | | | | {_cell(s.seconds, '.0f')} |")
            continue
        lines.append(f"| {s.case} | {100 * s.tolerance:.0f} % | {s.ok_good} | {s.ok_bad} | {s.not_ok_good} | "
                     f"{s.not_ok_bad} | {_cell(100 * s.coverage, '.0f')} % ({s.covered} of {s.scored}) | "
                     f"{s.below_crb} of {s.with_crb} | {s.not_excited} ({s.ok_not_excited}) | "
                     f"{_cell(100 * s.worst_ok_error, '.1f')} | "
                     f"{_cell(s.seconds, '.0f')} |")
    lines.append("")
    for s in scores:
        met = s.targets_met()
        verdicts = ", ".join(f"{k} {'yes' if v else 'NO'}" for k, v in met.items())
        bad = f" (ok and bad: {', '.join(s.ok_bad_joints)})" if s.ok_bad_joints else ""
        lines.append(f"- {s.case}: {verdicts}{bad}")
    return "\n".join(lines)


def real_markdown(scores: Sequence[RealScore]) -> str:
    """The real sets as a Markdown table: the ``ok`` count and the statuses beside ``bench_real.py``'s columns."""
    lines = ["| dataset | ok | statuses | ok within target | worst curve | better than peer | time [s] |",
             "|---|---|---|---|---|---|---|"]
    for s in scores:
        if s.failed:
            lines.append(f"| {s.name} | (failed) | {s.failed} | | | | {_cell(s.seconds, '.0f')} |")
            continue
        statuses = ", ".join(f"{k} {v}" for k, v in sorted(s.statuses.items()))
        target = (f"{s.ok_within_error} ({100 * REAL_TARGET_ERROR[s.name]:.0f} %)" if s.name in REAL_TARGET_ERROR
                  else "–")
        peer = f"{s.better_than_peer} of {s.peers}" if s.peers else "–"
        lines.append(f"| {s.name} | {s.ok} of {s.joints} | {statuses} | {target} | "
                     f"{_cell(100 * s.worst_error, '.1f')} % | {peer} | {_cell(s.seconds, '.0f')} |")
    return "\n".join(lines)


def results_json(cases: Sequence[CaseScore], real: Sequence[RealScore], header: Mapping[str, Any]) -> str:
    """Every case's and real set's score as a JSON document (``header`` first: the commit, the date...)."""
    doc = {**header, "cases": {s.case: s.to_dict() for s in cases}, "real": {s.name: s.to_dict() for s in real}}
    return json.dumps(doc, indent=1, sort_keys=True, allow_nan=False) + "\n"
