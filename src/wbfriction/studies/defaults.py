"""Defaults chosen across the data: every real dataset and the simulators together, one dataset left out (issue 52).

A default picked by looking at data must be picked across all of it. Each default under study is a :class:`Knob`
(an option of a stage: the identification's link margin and prior tolerance, the estimate's noise target, the fit's
selection tolerance and terms, the statuses' thresholds) with a few candidate values around today's. Each
:class:`~wbfriction.studies.default_cases.Case` runs the route a user is given for it
(:mod:`~wbfriction.studies.real_data`) with one knob set to one value and every other at its default, and scores it
(:mod:`~wbfriction.studies.default_cases`: the cases, their losses and when a fit is *good*).

A knob's candidates are compared per case by the loss over the default's (:func:`choose`): the value whose mean
ratio over the cases is lowest is the best, and for each case the value best **without** it is scored on it (leave
one dataset out): a default that only one dataset asks for shows there. A value replaces today's default only where
it is the best over every case *and* without any one of them, and lowers the mean by more than :data:`MARGIN`:
otherwise one dataset, or the noise of a few percent, would have chosen it. The statuses' thresholds are scored by
how well ``ok`` predicts *good*: the share of fits called ``ok`` that are not good (counted twice: a plausible
wrong number is worse than a missing one) and of good fits not called ``ok``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from wbfriction.fit.options import TermOptions
from wbfriction.studies.default_cases import CASES, Case, Setting

Stage = Literal["identify", "estimate", "fit", "status"]
"""Where a knob acts: what must run again for a new value."""


@dataclass(frozen=True)
class Knob:
    """A default under study: its name, the stage it acts in, the candidates (today's included) and how a value is
    set into a :class:`~wbfriction.studies.default_cases.Setting`."""

    name: str
    stage: Stage
    values: tuple[Any, ...]
    default: Any
    set: Callable[[Setting, Any], Setting] = field(repr=False, compare=False)


def _inertial(name: str) -> Callable[[Setting, Any], Setting]:
    return lambda s, v: replace(s, inertial=replace(s.inertial, **{name: v}))


def _thresholds(name: str) -> Callable[[Setting, Any], Setting]:
    return lambda s, v: replace(s, thresholds=replace(s.thresholds, **{name: v}))


KNOBS: tuple[Knob, ...] = (
    Knob("link_margin", "identify", (0.0, 0.1, 0.25, 0.5), 0.25, _inertial("link_margin")),
    Knob("prior_tolerance", "identify", (0.0, 0.02, 0.05, 0.1), 0.02, _inertial("prior_tolerance")),
    Knob("noise_target", "estimate", (0.01, 0.03, 0.1), 0.03,
         lambda s, v: replace(s, estimate=replace(s.estimate, noise_target=v))),
    Knob("selection_tolerance", "fit", (0.0, 0.02, 0.05, 0.1), 0.02,
         lambda s, v: replace(s, fit=replace(s.fit, selection_tolerance=v))),
    Knob("pass_rows", "fit", (0.0, 2.0, 5.0, math.inf), math.inf,
         lambda s, v: replace(s, fit=replace(s.fit, pass_rows=v))),
    Knob("stick_floor", "fit", (0.003, 0.01, 0.02, 0.05), 0.003,
         lambda s, v: replace(s, fit=replace(s.fit, stick_floor=v))),
    Knob("score_slow", "fit", (False, True), True, lambda s, v: replace(s, fit=replace(s.fit, score_slow=v))),
    Knob("terms", "fit", ("none", "auto"), "auto",
         lambda s, v: replace(s, fit=replace(s.fit, terms=TermOptions() if v == "auto" else TermOptions(terms=())))),
    Knob("term_min_torque", "fit", (0.005, 0.01, 0.02), 0.01,
         lambda s, v: replace(s, fit=replace(s.fit, terms=replace(s.fit.terms, min_torque=v)))),
    Knob("term_tolerance", "fit", (0.01, 0.02, 0.05), 0.02,
         lambda s, v: replace(s, fit=replace(s.fit, terms=replace(s.fit.terms, tolerance=v)))),
    Knob("weak", "status", (0.1, 0.125, 0.25, 0.5), 0.1, _thresholds("weak")),
    Knob("holdout_excess", "status", (0.02, 0.05, 0.1, 0.2), 0.05, _thresholds("holdout_excess")),
    Knob("holdout_friction", "status", (0.02, 0.05, 0.1), 0.05, _thresholds("holdout_friction")),
    Knob("route_rel", "status", (0.02, 0.05, 0.1), 0.02, _thresholds("route_rel")),
)
"""The defaults under study (module docstring)."""


MARGIN = 0.01
"""A new default must lower the mean loss ratio by more than this (module docstring)."""


@dataclass(frozen=True)
class KnobChoice:
    """A knob's candidates scored on every case, the value chosen and each case left out (module docstring).

    Attributes:
        knob: the knob.
        losses: value -> case -> loss (lower is better; the statuses':
            :meth:`~wbfriction.studies.default_cases.CaseScore.misjudged`).
        scores: value -> its mean over the cases (of the loss over the default's, or of the statuses' loss).
        best: the value of the lowest score (the default where it ties).
        left_out: case -> (the value best without it, its loss on it over the default's, or the statuses' loss).
        chosen: ``best`` where it is also the best without any one case and beats the default's score by more than
            :data:`MARGIN`, else the default (module docstring).
    """

    knob: Knob
    losses: dict[Any, dict[str, float]]
    scores: dict[Any, float]
    best: Any
    left_out: dict[str, tuple[Any, float]]
    chosen: Any


def choose(knob: Knob, losses: dict[Any, dict[str, float]]) -> KnobChoice:
    """The choice of module docstring from ``losses`` (value -> case -> loss): numeric knobs by the mean ratio to the
    default's loss, the statuses' by the mean of their loss; cases where the knob changes nothing count all the
    same (a ratio of 1)."""
    cases = list(next(iter(losses.values())))
    default = losses[knob.default]

    def relative(value: Any, case: str) -> float:
        x = losses[value][case]
        if knob.stage == "status":
            return x
        return x / default[case] if default[case] > 0 else (1.0 if x == 0 else math.inf)

    def best(among: Sequence[str]) -> Any:
        if not among:  # nothing to choose on: today's
            return knob.default
        means = {v: float(np.mean([relative(v, c) for c in among])) for v in knob.values}
        low = min(means.values())
        return knob.default if means[knob.default] <= low + 1e-12 else min(means, key=lambda v: means[v])

    scores = {v: float(np.mean([relative(v, c) for c in cases])) for v in knob.values}
    left = {}
    for case in cases:
        value = best([c for c in cases if c != case])
        left[case] = (value, relative(value, case))
    overall = best(cases)
    margin = MARGIN if knob.stage != "status" else MARGIN * max(abs(scores[knob.default]), 1e-12)
    robust = all(v == overall for v, _ in left.values()) and scores[overall] < scores[knob.default] - margin
    return KnobChoice(knob, losses, scores, overall, left, overall if robust else knob.default)


def run_study(folder: Path, knobs: Sequence[Knob] = KNOBS, cases: Sequence[type[Case]] = CASES,
              say: Callable[[str], None] = lambda s: None) -> list[KnobChoice]:
    """Every knob of ``knobs`` over every case (module docstring), one knob at a time, the others at their
    defaults."""
    folder.mkdir(parents=True, exist_ok=True)
    built = []
    for cls in cases:
        case = cls(folder)
        say(f"preparing {case.name}")
        case.prepare()
        built.append(case)
    out = []
    for knob in knobs:
        losses: dict[Any, dict[str, float]] = {}
        for value in knob.values:
            setting = knob.set(Setting(), value)
            losses[value] = {}
            for case in built:
                if knob.stage == "status" and not case.judges_statuses:
                    continue
                say(f"{knob.name} = {value}: {case.name}")
                score = case.score(case.fitted(setting), setting.thresholds)
                losses[value][case.name] = score.misjudged() if knob.stage == "status" else score.loss
        out.append(choose(knob, losses))
    return out


def markdown(choices: Sequence[KnobChoice]) -> str:
    """One table per knob: the loss of each value on each case (relative to the default's, or the statuses' loss),
    the mean, the value chosen, and for each case the value chosen without it and how it does there."""
    lines: list[str] = []
    for choice in choices:
        knob = choice.knob
        cases = list(next(iter(choice.losses.values())))
        unit = "statuses' loss" if knob.stage == "status" else "loss / default's"
        lines += [f"**{knob.name}** (default {knob.default}; {unit}; best over all: {choice.best}; chosen: "
                  f"{choice.chosen})", "",
                  "| value | " + " | ".join(cases) + " | mean |", "|---" * (len(cases) + 2) + "|"]
        for v in knob.values:
            row = [choice.losses[v][c] if knob.stage == "status" else
                   choice.losses[v][c] / choice.losses[knob.default][c] for c in cases]
            lines.append(f"| {v} | " + " | ".join(f"{x:.3f}" for x in row) + f" | {choice.scores[v]:.3f} |")
        lines.append("| left out: chosen without it | " + " | ".join(
            f"{choice.left_out[c][0]} ({choice.left_out[c][1]:.3f})" for c in cases) + " | |")
        lines.append("")
    return "\n".join(lines)


def as_json(choices: Sequence[KnobChoice]) -> list[dict[str, Any]]:
    """The study's numbers, for a file."""
    return [{"knob": c.knob.name, "stage": c.knob.stage, "default": c.knob.default, "best": c.best, "chosen": c.chosen,
             "losses": {str(v): d for v, d in c.losses.items()}, "scores": {str(v): s for v, s in c.scores.items()},
             "left_out": {k: [str(v), r] for k, (v, r) in c.left_out.items()}} for c in choices]


__all__ = ["KNOBS", "Knob", "KnobChoice", "as_json", "choose", "markdown", "run_study"]
