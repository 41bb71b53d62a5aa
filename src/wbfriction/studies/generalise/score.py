"""A scenario run through the route the docs give a user and scored on what the route wrote
(:func:`run_scenario`), and scores summed per class (:func:`summarise`).

**Routes** (each command its own process, :func:`~wbfriction.studies.real_data.run_route`, with every default): an
arm ``wbfriction estimate log.parquet --config given.toml -o friction.parquet`` then ``wbfriction fit
friction.parquet -o params.json`` (``docs/how-to/your-robot.md``); a hung PD-driven robot ``wbfriction identify
log.parquet --config given.toml --actuator pd --json actuator.json --config-output identified.toml``
(``docs/how-to/pd-robots.md``).

**Scores**, from the files alone, by :mod:`wbfriction.studies.status`'s scoring (not written twice): the four counts
of fits (``ok`` and good, ``ok`` and bad, not ``ok`` and good, not ``ok`` and bad), the ±2 SE coverage, with a fit
good when F_c and F_v lie within :data:`~wbfriction.studies.status.GOOD_NOISY` (10 %) of the truth. Ten per cent,
not the noise-free 5 %: every scenario's model is off (masses, inertias, the armature unknown, a torque constant),
most logs carry sensor noise, and most laws' truth is a best approximation, so 5 % would call bad what a user
would take as right; beyond 10 % a friction compensation is visibly off. Beside them :data:`PROMISE`: the ``ok``
values (F_c, F_v of ``ok`` fits, excited) outside the promise of ``ok``, ±20 % of the truth
(:data:`~wbfriction.fit.status.PROMISE`).

For a PD-driven robot, what ``--config-output`` wrote (its ``[armature]``, ``[encoder_offset]``, ``[pd] delay``)
against the truth and against what the given TOML held (no armature, no offsets: 0; its delay): per value, whether
the written one is closer to the truth than the given one (:class:`Written`); a value not written keeps the given
one (not closer). Per scenario (:func:`toml_verdict`), whether the written TOML as a whole is closer: per quantity,
its absolute errors summed over the joints against the given TOML's (one unit per sum, no scale chosen); ``closer``
where it is closer on one quantity and farther on none, ``farther`` where it is farther on one, else ``unchanged``.
"""

from __future__ import annotations

import math
import time
import tomllib
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

from wbfriction.fit.status import PROMISE
from wbfriction.studies.generalise.scenario import CLASSES, Scenario, draw
from wbfriction.studies.generalise.simulate import GIVEN_TOML, LOG, absolute_pythonpath, write_scenario
from wbfriction.studies.status import (
    FRICTION,
    GOOD_NOISY,
    CaseScore,
    JointFit,
    fits_from_actuators,
    fits_from_params,
    log_speeds,
    log_truth,
    score_fits,
)

PARAMS, ACTUATOR_JSON, IDENTIFIED = "params.json", "actuator.json", "identified.toml"
WRITTEN_VALUES = ("armature", "offset", "delay")


def commands(sc: Scenario) -> tuple[str, ...]:
    """The route's commands for ``sc`` (module docstring), run in its folder."""
    if sc.robot_class == "pd":
        return (f"wbfriction identify {LOG} --config {GIVEN_TOML} --actuator pd --json {ACTUATOR_JSON} "
                f"--config-output {IDENTIFIED}",)
    return (f"wbfriction estimate {LOG} --config {GIVEN_TOML} -o friction.parquet",
            f"wbfriction fit friction.parquet -o {PARAMS}")


@dataclass(frozen=True)
class Written:
    """One value ``--config-output`` wrote (or kept): ``name`` (``armature`` [kg·m²], ``offset`` [rad], ``delay``
    [s]), its joint (``""`` for the delay), the truth, the given TOML's value and the written one (the given where
    not written)."""

    name: str
    joint: str
    truth: float
    given: float
    written: float
    was_written: bool

    @property
    def closer(self) -> bool:
        """Whether the written value is closer to the truth than the given one."""
        return self.was_written and abs(self.written - self.truth) < abs(self.given - self.truth)


def written_values(path: Path, truth: dict[str, Any], joints: Sequence[str]) -> tuple[Written, ...]:
    """What the identified TOML ``path`` holds against ``truth`` (the log's metadata: ``armature_true``,
    ``encoder_offset_true``, ``delay_true``, ``given``); a missing file: nothing written."""
    doc = tomllib.loads(path.read_text()) if path.is_file() else {}
    given = truth["given"]
    out = []
    for name, table, true_key in (("armature", "armature", "armature_true"),
                                  ("offset", "encoder_offset", "encoder_offset_true")):
        values = doc.get(table, {})
        for j in joints:
            g = float(given[name][j])
            out.append(Written(name, j, float(truth[true_key][j]), g, float(values.get(j, g)), j in values))
    delay = doc.get("pd", {}).get("delay")
    g = float(given["delay"])
    wrote = delay is not None and float(delay) != g
    out.append(Written("delay", "", float(truth["delay_true"]), g, float(delay) if wrote else g, wrote))
    return tuple(out)


def toml_verdict(written: Sequence[Written]) -> str:
    """``closer``, ``farther`` or ``unchanged``: the written TOML against the given one (module docstring); ``""``
    without written values (not a PD-driven robot)."""
    if not written:
        return ""
    verdicts = set()
    for name in WRITTEN_VALUES:
        values = [w for w in written if w.name == name]
        now = sum(abs(w.written - w.truth) for w in values)
        before = sum(abs(w.given - w.truth) for w in values)
        verdicts.add("closer" if now < before * (1 - 1e-9) else "farther" if now > before * (1 + 1e-9) else "")
    return "farther" if "farther" in verdicts else "closer" if "closer" in verdicts else "unchanged"


@dataclass(frozen=True)
class ScenarioScore:
    """A scenario's score: its draw's key facts, :class:`~wbfriction.studies.status.CaseScore`, the ``ok`` values
    outside :data:`PROMISE` (of ``ok_values``), the friction's (F_c, F_v) values within ±2 standard errors of the
    truth (of ``friction_scored``: the case's coverage counts a PD-driven robot's armatures, offsets and delay too),
    and for a PD-driven robot what ``--config-output`` wrote."""

    seed: int
    set: str
    robot_class: str
    robot: str
    law: str
    excitation: str
    case: CaseScore
    ok_outside: int = 0
    ok_values: int = 0
    friction_covered: int = 0
    friction_scored: int = 0
    written: tuple[Written, ...] = field(default_factory=tuple)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["case"] = self.case.to_dict()
        return d


def promise(fits: Iterable[JointFit]) -> tuple[int, int]:
    """The ``ok`` fits' judged values (F_c, F_v, excited) outside ±:data:`PROMISE` of the truth, and all of them."""
    values = [p for f in fits if f.status == "ok" for p in f.judged()]
    return sum(p.error > PROMISE for p in values), len(values)


def score_scenario(sc: Scenario, folder: Path) -> ScenarioScore:
    """Score what ``sc``'s route wrote in ``folder`` (module docstring)."""
    truth = log_truth(folder / LOG)
    written: tuple[Written, ...] = ()
    if sc.robot_class == "pd":
        speeds = log_speeds(folder / LOG, list(truth["friction_true"]))
        fits = fits_from_actuators(folder / ACTUATOR_JSON, truth, speeds)
        written = written_values(folder / IDENTIFIED, truth, list(truth["friction_true"]))
    else:
        fits = fits_from_params(folder / PARAMS, truth["friction_true"])
    outside, values = promise(fits)
    friction = [p.covered for f in fits for p in f.parameters if p.name in FRICTION and p.covered is not None]
    return ScenarioScore(sc.seed, sc.set, sc.robot_class, sc.robot, sc.law, sc.excitation,
                         score_fits(sc.name, fits, noisy=True), outside, values, sum(friction), len(friction), written)


def run_scenario(seed: int | Scenario, folder: str | Path, echo: Callable[[str], None] | None = None
                 ) -> ScenarioScore:
    """Draw ``seed``'s scenario (or take the one given), simulate it into ``folder`` (made if missing), run its route
    and score it; a simulation or a route that fails is a score with its message in the case's ``failed``."""
    from wbfriction.exceptions import WbfrictionError
    from wbfriction.studies.real_data import run_route

    sc = seed if isinstance(seed, Scenario) else draw(seed)
    folder = Path(folder)
    start = time.perf_counter()
    try:
        write_scenario(sc, folder)
        run_route(commands(sc), folder, env=absolute_pythonpath(), echo=echo)
        score = score_scenario(sc, folder)
    except (WbfrictionError, ValueError, OSError) as exc:
        return ScenarioScore(sc.seed, sc.set, sc.robot_class, sc.robot, sc.law, sc.excitation,
                             CaseScore(sc.name, GOOD_NOISY, failed=str(exc), seconds=time.perf_counter() - start))
    return replace(score, case=replace(score.case, seconds=time.perf_counter() - start))


@dataclass(frozen=True)
class Summary:
    """Scores summed over a group of scenarios (a class, or all)."""

    group: str
    scenarios: int
    failed: int
    ok_good: int
    ok_bad: int
    not_ok_good: int
    not_ok_bad: int
    covered: int
    scored: int
    ok_outside: int
    ok_values: int
    friction_covered: int
    friction_scored: int
    written: dict[str, tuple[int, int, int]]
    """per value name: (closer to the truth than the given, written but not closer, not written)"""
    tomls: tuple[int, int, int]
    """scenarios whose written TOML is closer, farther, unchanged (:func:`toml_verdict`)"""
    seconds: float

    @property
    def coverage(self) -> float:
        return self.covered / self.scored if self.scored else float("nan")


def summarise(group: str, scores: Sequence[ScenarioScore]) -> Summary:
    """:class:`Summary` of ``scores``."""
    ok = [s for s in scores if not s.case.failed]
    total = lambda name: sum(getattr(s.case, name) for s in ok)  # noqa: E731
    written = {}
    for name in WRITTEN_VALUES:
        values = [w for s in ok for w in s.written if w.name == name]
        if values:
            closer = sum(w.closer for w in values)
            kept = sum(not w.was_written for w in values)
            written[name] = (closer, len(values) - closer - kept, kept)
    verdicts = [toml_verdict(s.written) for s in ok]
    tomls = (verdicts.count("closer"), verdicts.count("farther"), verdicts.count("unchanged"))
    return Summary(group, len(scores), len(scores) - len(ok), total("ok_good"), total("ok_bad"),
                   total("not_ok_good"), total("not_ok_bad"), total("covered"), total("scored"),
                   sum(s.ok_outside for s in ok), sum(s.ok_values for s in ok), sum(s.friction_covered for s in ok),
                   sum(s.friction_scored for s in ok), written, tomls,
                   sum(s.case.seconds for s in scores if math.isfinite(s.case.seconds)))


def summaries(scores: Sequence[ScenarioScore]) -> list[Summary]:
    """Per class (:data:`~wbfriction.studies.generalise.scenario.CLASSES`, those present), then ``all``."""
    out = [summarise(c, [s for s in scores if s.robot_class == c]) for c in CLASSES
           if any(s.robot_class == c for s in scores)]
    return out + [summarise("all", scores)]


def _pct(a: int, b: int) -> str:
    return f"{100 * a / b:.0f} % ({a} of {b})" if b else "–"


def markdown(rows: Sequence[Summary], title: str) -> str:
    """The summaries as Markdown: the fits' counts, coverage and promise, then ``--config-output``'s values."""
    lines = [f"### {title}", "",
             "| class | scenarios (failed) | ok, good | ok, bad | not ok, good | not ok, bad | coverage ±2 SE, F_c and "
             f"F_v | coverage ±2 SE, every value | ok outside ±{100 * PROMISE:.0f} % | time, summed [s] |",
             "|---" * 10 + "|"]
    for r in rows:
        lines.append(f"| {r.group} | {r.scenarios} ({r.failed}) | {r.ok_good} | {r.ok_bad} | {r.not_ok_good} | "
                     f"{r.not_ok_bad} | {_pct(r.friction_covered, r.friction_scored)} | {_pct(r.covered, r.scored)} | "
                     f"{_pct(r.ok_outside, r.ok_values)} | {r.seconds:.0f} |")
    written = [r for r in rows if r.written]
    if written:
        lines += ["", "`identify --actuator pd --config-output` against the given TOML (per value: written closer to "
                  "the truth than given / written, not closer / not written; per scenario, the written TOML: closer / "
                  "farther / unchanged):", "",
                  "| class | " + " | ".join(WRITTEN_VALUES) + " | scenarios |",
                  "|---" * (2 + len(WRITTEN_VALUES)) + "|"]
        for r in written:
            cells = [("{} / {} / {}".format(*r.written[n]) if n in r.written else "–") for n in WRITTEN_VALUES]
            lines.append(f"| {r.group} | " + " | ".join(cells) + " | {} / {} / {} |".format(*r.tomls))
    return "\n".join(lines)


def breakdown(scores: Sequence[ScenarioScore], key: str) -> str:
    """A Markdown table of the fits' counts per value of ``key`` (``law``, ``excitation``, ``robot``)."""
    values = sorted({getattr(s, key) for s in scores})
    rows = [summarise(v, [s for s in scores if getattr(s, key) == v]) for v in values]
    lines = [f"| {key} | scenarios (failed) | ok, good | ok, bad | not ok, good | not ok, bad | coverage ±2 SE, F_c "
             f"and F_v | ok outside ±{100 * PROMISE:.0f} % | written TOML closer / farther / unchanged |",
             "|---" * 9 + "|"]
    for r in rows:
        tomls = "{} / {} / {}".format(*r.tomls) if any(r.tomls) else "–"
        lines.append(f"| {r.group} | {r.scenarios} ({r.failed}) | {r.ok_good} | {r.ok_bad} | {r.not_ok_good} | "
                     f"{r.not_ok_bad} | {_pct(r.friction_covered, r.friction_scored)} | "
                     f"{_pct(r.ok_outside, r.ok_values)} | {tomls} |")
    return "\n".join(lines)
