"""Identified inertias kept only where they predict held-out torques better: the identification's gate (issue 24).

An identification fits the training samples; on a log the given model already explains, what it changes
is noise, and it may predict new data worse than the given model (on a walk simulated with the exact
model, 9 of 12 leg joints were predicted worse on held-out data, and principal moments moved by -100 %
and +164 %). So the identified parameters are kept only where they predict the held-out samples (the
end of the log, never used to identify: :attr:`~wbfriction.inertia.options.InertialOptions.holdout`)
better than the given model with its best friction; the rest stays as given.

**Per limb, not per body.** The unit of the decision is a *limb*: a maximal unbranched chain of bodies
of the kinematic tree (:func:`limbs`; TALOS: the pelvis, each leg, the torso, each arm with its gripper,
the head; an arm on a fixed base: its whole chain). A body's ten inertial parameters are not identifiable
on their own: the torques see only combinations of them (the base parameters, thesis 2.4; Khalil's
regrouping moves a body's mass and first moments into its parent's parameters along the chain), so the
identification may move a quantity from one body to its neighbour, and one body's identified values
without its neighbour's are a model nobody identified. Within an unbranched chain such moves stay in the
chain (but at its ends, which the gate's held-out test then judges). Fewer decisions also select less
of the held-out data's noise than one per body would.

**The decision** (:func:`validate_groups`). The model with the limbs in a set ``S`` identified and the
others given, with the friction (and identified armature) that best explains the training data with those
inertias, predicts the held-out torques ``tau_hat_S`` (N, n_tc); per joint, ``SS_j(S) = sum_n (tau_j -
tau_hat_{S,j})^2`` [N^2·m^2]. ``S = {}`` is the given model with its best friction, the reference. A set
is *admissible* when it predicts the held-out torques better, by a margin that noise does not give:

* over all joints, its RMS is at least :data:`GAIN` (1 %) below the reference's (on a log simulated with
  the exact model, an identification fits noise and moves the held-out RMS by less than that: measured
  0.98-1.015 per joint on the simulated Panda);
* no joint's RMS exceeds the reference's by more than :data:`TOLERANCE` (5 %) of it plus a floor
  (:data:`FLOOR`: a thousandth of the reference's RMS over all joints; a change below it is no change).
  The RMS of one joint over one held-out window carries its own sampling error; on the real KUKA LWR4+
  (runs 1-2, the last 20 % held out) the identified arm lowers the RMS over all joints from 0.748 to
  0.253 N·m and one wrist joint's from 0.2427 to 0.2483 (+2.3 %): a rule that refused any increase
  refused the arm, which predicts a third run 1.8 times better.

Two greedy paths, free of that constraint, score the sets worth scoring: from ``{}`` adding the limb that
lowers ``sum_j SS_j`` most, and from every limb removing the one whose removal lowers it most (an
identification compensates across limbs: on a walk seen through a model with a wrong leg, every limb alone
predicted some joint worse, all together 240 times better). The admissible set of lowest total among
those scored (the empty set, always admissible, if none is) is then polished by single additions and
removals that keep it admissible and lower the total (a removal: or leave it unchanged, where a limb does
not help the given one stays). Hence, by construction, the written model predicts the held-out torques
better than the given model with its best friction, no joint more than 5 % worse, and no single limb
added or removed would improve on it. (The held-out samples decide and score: the numbers after the gate
are optimistic by the little that a choice among a few limbs can select of their noise.)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

TOLERANCE = 0.05
"""Relative increase of one joint's held-out RMS still accepted in a model that predicts the held-out torques
better over all joints (module docstring: a window's RMS has its own sampling error)."""
GAIN = 0.01
"""Relative decrease of the held-out RMS over all joints a model must reach to be kept: less is what fitting
noise gives (module docstring)."""
_ROUNDING = 1e-9
"""Relative change of a sum of squares counted as none (a limb that does not act on a joint leaves its
prediction equal to the last digits)."""
FLOOR = 1e-3
"""Increase of a joint's held-out RMS counted as no change, as a share of the reference's RMS over all
joints [N·m/N·m]: a joint the given model predicts to a thousandth of the others' error (an upper-body
joint of a simulated walk, 1e-5 N·m) may move by that much. On a log the given model explains, the
reference is small and so is the floor; where it is badly off, a change of a thousandth of its error is
not worth keeping its error for."""


@dataclass(frozen=True)
class BodyGroup:
    """Bodies decided together.

    Attributes:
        name: the limb's label: its first and last body (``leg_left_1_joint…leg_left_6_joint``).
        bodies: indices of its bodies in the identification's body order (Pinocchio joint ``j`` is body
            ``j - 1``).
    """

    name: str
    bodies: tuple[int, ...]


def limbs(model: pin.Model) -> tuple[BodyGroup, ...]:
    """The maximal unbranched chains of ``model``'s kinematic tree (module docstring), in model order:
    a body starts a new limb when it hangs on the universe or on a body with several children; otherwise
    it continues its parent's."""
    children = [0] * model.njoints
    for j in range(1, model.njoints):
        children[model.parents[j]] += 1
    group_of: dict[int, int] = {}
    members: list[list[int]] = []
    for j in range(1, model.njoints):
        parent = model.parents[j]
        if parent == 0 or children[parent] != 1:
            group_of[j] = len(members)
            members.append([])
        else:
            group_of[j] = group_of[parent]
        members[group_of[j]].append(j)
    out = []
    for js in members:
        first, last = model.names[js[0]], model.names[js[-1]]
        out.append(BodyGroup(first if len(js) == 1 else f"{first}…{last}", tuple(j - 1 for j in js)))
    return tuple(out)


@dataclass(frozen=True)
class GroupDecision:
    """The gate's decision on one group.

    Attributes:
        name: :attr:`BodyGroup.name`.
        bodies: the names of its bodies.
        kept: whether its identified parameters are kept (else it stays as given).
        reason: why, one phrase.
        joints: the torque-controlled joints whose held-out predictions it moves.
        rms_before, rms_after: held-out torque RMS over ``joints`` [N·m], of the gate's final model with
            this group as given and as identified (nan when it moves none).
    """

    name: str
    bodies: tuple[str, ...]
    kept: bool
    reason: str
    joints: tuple[str, ...]
    rms_before: float
    rms_after: float

    def to_dict(self) -> dict:
        nan = lambda x: float(x) if np.isfinite(x) else None  # noqa: E731
        return {"name": self.name, "bodies": list(self.bodies), "kept": self.kept, "reason": self.reason,
                "joints": list(self.joints), "rms_before": nan(self.rms_before), "rms_after": nan(self.rms_after)}


@dataclass(frozen=True)
class Validation:
    """What :func:`validate_groups` decided.

    Attributes:
        groups: one decision per group, in the groups' order.
        joints: the torque-controlled joints (n_tc,).
        samples: held-out samples.
        rms_reference: per joint, held-out torque RMS of the given model with its best friction [N·m] (n_tc,).
        rms_identified: the same with every group identified (n_tc,).
        rms_validated: the same with the groups kept identified, the others given (n_tc,).
        tolerance: :data:`TOLERANCE` as used.
        gain: :data:`GAIN` as used.
        floor: the increase of a joint's held-out RMS counted as no change [N·m] (:data:`FLOOR` times the
            reference's RMS over all joints).
    """

    groups: tuple[GroupDecision, ...]
    joints: tuple[str, ...]
    samples: int
    rms_reference: np.ndarray
    rms_identified: np.ndarray
    rms_validated: np.ndarray
    tolerance: float = TOLERANCE
    floor: float = 0.0
    gain: float = GAIN

    @property
    def kept(self) -> np.ndarray:
        """(n_groups,) bool."""
        return np.array([g.kept for g in self.groups], dtype=bool)

    @staticmethod
    def total(rms: np.ndarray) -> float:
        """RMS over every joint and sample [N·m] of per-joint RMS values ``rms`` over the same samples."""
        return float(np.sqrt(np.mean(np.square(rms)))) if len(rms) else float("nan")

    def verdict(self, label: str = "") -> str:
        """One line: how many groups (bodies) were kept, the held-out torque RMS over all joints before and
        after, and why the others stay as given; ``label`` (``"pass 1"``) first."""
        head = f"{label}: " if label else ""
        n, kept = len(self.groups), [g for g in self.groups if g.kept]
        bodies = sum(len(g.bodies) for g in self.groups)
        kept_bodies = sum(len(g.bodies) for g in kept)
        ref, val, ident = (self.total(x) for x in (self.rms_reference, self.rms_validated, self.rms_identified))
        if not kept:
            return (f"{head}no limb kept: the given inertias stay (held-out torque RMS {ref:.3g} N·m with them and "
                    f"their best friction, {ident:.3g} N·m identified: {self._why_not()})")
        line = (f"{head}{len(kept)} of {n} limbs kept ({kept_bodies} of {bodies} bodies; held-out torque RMS "
                f"{ref:.3g} → {val:.3g} N·m, {ident:.3g} with every limb identified)")
        if len(kept) < n:
            line += f"; {n - len(kept)} stay as given ({self._why_not()})"
        return line

    def _why_not(self) -> str:
        counts: dict[str, int] = {}
        for g in self.groups:
            if not g.kept:
                key = "would make a joint worse" if g.reason.startswith("would make") else g.reason
                counts[key] = counts.get(key, 0) + 1
        if len(counts) == 1:
            return next(iter(counts))
        return ", ".join(f"{c}: {reason}" for reason, c in counts.items())

    def to_dict(self) -> dict:
        """JSON-ready (``passes[k].validation`` of ``wbfriction identify --json``)."""
        per_joint = lambda x: dict(zip(self.joints, map(float, x)))  # noqa: E731
        return {"samples": self.samples, "tolerance": self.tolerance, "floor": self.floor, "gain": self.gain,
                "rms_given_with_friction": self.total(self.rms_reference),
                "rms_identified": self.total(self.rms_identified),
                "rms_validated": self.total(self.rms_validated),
                "joints_rms_given_with_friction": per_joint(self.rms_reference),
                "joints_rms_identified": per_joint(self.rms_identified),
                "joints_rms_validated": per_joint(self.rms_validated),
                "groups": [g.to_dict() for g in self.groups]}


def validate_groups(groups: Sequence[BodyGroup], body_names: Sequence[str], joints: Sequence[str],
                    measured: np.ndarray, predict: Callable[[np.ndarray], np.ndarray],
                    tolerance: float = TOLERANCE, floor: float = FLOOR, gain: float = GAIN) -> Validation:
    """Choose the groups whose identified parameters predict held-out torques better (module docstring).

    Args:
        groups: the groups decided on (:func:`limbs`).
        body_names: names of all bodies (indexed by :attr:`BodyGroup.bodies`).
        joints: the torque-controlled joints (n_tc,).
        measured: the held-out torques the models predict (N, n_tc) [N·m] (less a known armature's share), NaN where
            a joint's row does not hold (a robot on point feet): each joint is scored on its own rows.
        predict: ``predict(mask)`` -> (N, n_tc) [N·m]: the held-out torques predicted by the model with the
            groups ``mask`` (n_groups,) bool identified and the others given, with its best friction; called
            at most a few times per group (results cached).
        tolerance: relative increase of a joint's held-out RMS over the reference's still counted as no worse.
        floor: increase of a joint's held-out RMS still counted as no worse, as a share of the reference's
            RMS over all joints (:data:`FLOOR`).
        gain: relative decrease of the held-out RMS over all joints a set of groups must reach (:data:`GAIN`).

    Returns:
        :class:`Validation`.
    """
    measured = np.asarray(measured, dtype=float)
    G, N = len(groups), measured.shape[0]
    scores = HeldOutScores(measured, predict)
    ref = scores(np.zeros(G, dtype=bool))
    bar = Admission.of(ref, scores.counts, tolerance, floor, gain)
    kept = choose_groups(G, scores, bar)
    size = np.sqrt(np.nanmean(measured ** 2, axis=0)) + 1e-12  # each joint's torque: what "moves no torque" is below
    decisions = tuple(group_decision(g, group, kept, scores, bar, body_names, joints, size)
                      for g, group in enumerate(groups))
    rms = lambda s: np.sqrt(s / np.maximum(scores.counts, 1))  # noqa: E731
    return Validation(decisions, tuple(joints), N, rms(ref), rms(scores(np.ones(G, dtype=bool))), rms(scores(kept)),
                      tolerance, bar.floor, gain)


def mask_key(mask: np.ndarray) -> tuple[bool, ...]:
    """A set of groups (n_groups,) bool as a dictionary key."""
    return tuple(bool(x) for x in mask)


def toggled(mask: np.ndarray, g: int | np.integer, on: bool) -> np.ndarray:
    """``mask`` with group ``g`` identified (``on``) or given, a copy."""
    out = mask.copy()
    out[g] = on
    return out


class HeldOutScores:
    """Each set of groups' held-out prediction and per-joint sum of squared errors [N^2·m^2], computed once.

    Args:
        measured: the held-out torques (N, n_tc) [N·m], NaN where a joint's row does not hold.
        predict: ``predict(mask)`` -> (N, n_tc) [N·m] (:func:`validate_groups`).

    Attributes:
        counts: each joint's held-out rows (n_tc,): its finite ``measured``.
    """

    def __init__(self, measured: np.ndarray, predict: Callable[[np.ndarray], np.ndarray]):
        self.measured, self.predict = measured, predict
        self.counts = np.isfinite(measured).sum(axis=0)
        self.squares: dict[tuple[bool, ...], np.ndarray] = {}
        self.predictions: dict[tuple[bool, ...], np.ndarray] = {}

    def __call__(self, mask: np.ndarray) -> np.ndarray:
        """Per joint, the sum over the held-out samples of the squared error of the set ``mask`` (n_tc,)."""
        key = mask_key(mask)
        if key not in self.squares:
            self.predictions[key] = np.asarray(self.predict(np.array(key, dtype=bool)), dtype=float)
            self.squares[key] = np.nansum((self.predictions[key] - self.measured) ** 2, axis=0)
        return self.squares[key]

    def total(self, mask: np.ndarray) -> float:
        """The sum of squared errors of the set ``mask`` over every joint."""
        return float(self(mask).sum())

    def scored(self) -> list[np.ndarray]:
        """The sets scored so far, in the order scored."""
        return [np.array(key, dtype=bool) for key in list(self.squares)]


@dataclass(frozen=True)
class Admission:
    """What a set of groups must reach to be kept (module docstring), from the reference's sums of squares.

    Attributes:
        limit: per joint, the largest sum of squared errors still no worse than the reference's (n_tc,)
            [N^2·m^2] (:data:`TOLERANCE` of its RMS, plus the floor).
        better: the largest sum over all joints of a set that predicts better (:data:`GAIN` below the
            reference's) [N^2·m^2].
        rounding: a change of a sum over all joints counted as none [N^2·m^2] (:data:`_ROUNDING` of the
            reference's).
        floor: the increase of a joint's held-out RMS counted as no change [N·m].
        gain: the relative decrease of the held-out RMS over all joints ``better`` asks (:data:`GAIN`).
    """

    limit: np.ndarray
    better: float
    rounding: float
    floor: float
    gain: float

    @classmethod
    def of(cls, ref: np.ndarray, counts: np.ndarray, tolerance: float = TOLERANCE, floor: float = FLOOR,
           gain: float = GAIN) -> Admission:
        """The thresholds of the reference's per-joint sums of squares ``ref`` (n_tc,) over each joint's ``counts``
        (n_tc,) held-out rows (:func:`validate_groups`' ``tolerance``, ``floor`` and ``gain``)."""
        floor_nm = floor * float(np.sqrt(ref.sum() / max(int(np.sum(counts)), 1)))
        rows = np.maximum(counts, 1)
        limit = (np.sqrt(ref / rows) * (1.0 + tolerance) + floor_nm) ** 2 * rows + 1e-30
        return cls(limit, (1.0 - gain) ** 2 * float(ref.sum()), float(ref.sum()) * _ROUNDING, floor_nm, gain)

    def admits(self, mask: np.ndarray, squares: np.ndarray) -> bool:
        """Whether the set ``mask`` with per-joint sums of squares ``squares`` (n_tc,) makes no joint worse and,
        unless it is the empty set, predicts better over all joints."""
        return bool(np.all(squares <= self.limit)) and (not mask.any() or float(squares.sum()) <= self.better)


def descend(start: np.ndarray, adding: bool, scores: HeldOutScores, rounding: float) -> None:
    """Greedy toggles from ``start`` (adding groups, or removing them) that lower the total, constraint-free,
    while one does: the path visits (scores) the sets worth scoring."""
    S = start.copy()
    while True:
        moves = [toggled(S, g, adding) for g in np.flatnonzero(~S if adding else S)]
        if not moves:
            return
        best = min(moves, key=scores.total)
        if scores.total(best) >= scores.total(S) - rounding:
            return
        S = best


def choose_groups(G: int, scores: HeldOutScores, bar: Admission) -> np.ndarray:
    """The groups kept (G,) bool (module docstring): the admissible set of lowest total among those the two
    greedy paths scored (the empty set always is), then single toggles that keep it admissible and lower the
    total (a removal: or keep it unchanged)."""
    descend(np.zeros(G, dtype=bool), True, scores, bar.rounding)  # limbs that help on their own
    # limbs that help only together (an identification compensates across limbs)
    descend(np.ones(G, dtype=bool), False, scores, bar.rounding)
    S = min([m for m in scores.scored() if bar.admits(m, scores(m))], key=scores.total)  # the empty set is there
    while True:  # single toggles that keep every joint no worse and lower the total (a removal: or keep it)
        moves = [toggled(S, g, not S[g]) for g in range(G)]
        moves = [m for m, g in zip(moves, range(G)) if bar.admits(m, scores(m))
                 and scores.total(m) < scores.total(S) + (bar.rounding if S[g] else -bar.rounding)]
        if not moves:
            return S
        S = min(moves, key=lambda m: (scores.total(m), int(m.sum())))


def group_decision(g: int, group: BodyGroup, kept: np.ndarray, scores: HeldOutScores, bar: Admission,
                   body_names: Sequence[str], joints: Sequence[str], size: np.ndarray) -> GroupDecision:
    """The decision on group ``g`` of the kept set ``kept``: the joints it moves (a change of their prediction
    above 1e-9 of their RMS torque ``size`` (n_tc,)), their held-out RMS with it given and identified, and
    why (:func:`decision_reason`)."""
    off, on = toggled(kept, g, False), toggled(kept, g, True)
    s_off, s_on = scores(off), scores(on)
    p_off, p_on = scores.predictions[mask_key(off)], scores.predictions[mask_key(on)]
    moved = np.max(np.abs(p_on - p_off), axis=0, initial=0.0) > 1e-9 * size
    names = tuple(j for j, m in zip(joints, moved) if m)
    rows = max(int(scores.counts[moved].sum()), 1)
    before = float(np.sqrt(s_off[moved].sum() / rows)) if moved.any() else float("nan")
    after = float(np.sqrt(s_on[moved].sum() / rows)) if moved.any() else float("nan")
    reason = decision_reason(bool(kept[g]), moved, s_off, s_on, bar, joints)
    return GroupDecision(group.name, tuple(body_names[b] for b in group.bodies), bool(kept[g]), reason, names,
                         before, after)


def decision_reason(kept: bool, moved: np.ndarray, s_off: np.ndarray, s_on: np.ndarray, bar: Admission,
                    joints: Sequence[str]) -> str:
    """Why a group is kept or stays as given, one phrase, from the per-joint sums of squares of the kept set
    with the group given (``s_off``) and identified (``s_on``) (n_tc,), and the joints it ``moved`` (n_tc,) bool."""
    if kept and s_on[moved].sum() < s_off[moved].sum():
        return "predicts the held-out torques of its joints better"
    if kept:
        worse = [j for j, bad in zip(joints, s_off > bar.limit) if bad]
        return (f"kept with the others: without it {', '.join(worse[:3])}{' …' if len(worse) > 3 else ''} "
                "would be predicted worse than by the given model" if worse else
                "kept with the others: without it they do not predict the held-out torques better")
    if not moved.any():
        return "moves no held-out torque"
    if not np.all(s_on <= bar.limit):
        worse = [j for j, bad in zip(joints, s_on > bar.limit) if bad]
        return f"would make {', '.join(worse[:3])}{' …' if len(worse) > 3 else ''} worse on held-out data"
    return f"does not lower the held-out torques' RMS by {100 * bar.gain:g} %"
