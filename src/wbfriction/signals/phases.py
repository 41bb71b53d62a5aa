"""Support phases from contact flags, and the per-joint masks of reliable samples.

Phases (thesis 5.3): with one contact frame on the ground (single support) the friction
estimate is exact and unique (5.13); with two or more (double support) it is not; with
none (flight) the floating base is unobservable from joint data and nothing is
estimated.

Masks (thesis 6.2.1): the first ``lift_off_skip`` seconds after a lift-off and the last
``touch_down_skip`` seconds before a touch-down are dropped (velocity jumps at contact
switches). Within the remaining single-support samples:

* ``"single"``: every torque-controlled joint counts;
The dropped intervals are ``[t_lift_off, t_lift_off + lift_off_skip)`` and
``[t_touch_down - touch_down_skip, t_touch_down)``.

* ``"swing"`` (default, the thesis's reliable choice): a joint on the limb of the
  stance contact does not count (its estimate multiplies a small acceleration error by a
  large inertia, 6.1.2); a joint of the swinging leg, or of the torso, arms..., does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.signals.options import MASKS, Mask

FLIGHT, SINGLE, DOUBLE = "flight", "single", "double"


@dataclass
class Phases:
    """Support phase of every sample.

    Attributes:
        n_contacts: number of contact frames on the ground (N,).
        stance: index of the stance contact frame in single support, -1 otherwise (N,).
        keep: single-support samples left after the lift-off/touch-down margins (N,).
    """

    n_contacts: np.ndarray
    stance: np.ndarray
    keep: np.ndarray

    @property
    def single(self) -> np.ndarray:
        return self.n_contacts == 1

    @property
    def double(self) -> np.ndarray:
        return self.n_contacts >= 2

    def labels(self) -> np.ndarray:
        """Phase names per sample: ``"single"``, ``"double"`` or ``"flight"``."""
        out = np.full(self.n_contacts.shape, FLIGHT, dtype=object)
        out[self.single] = SINGLE
        out[self.double] = DOUBLE
        return out


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open index ranges [start, stop) of the True runs of the (N,) bool ``mask``."""
    edges = np.diff(np.concatenate(([0], np.asarray(mask, dtype=np.int8), [0])))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))


def segment(time: np.ndarray, contact: np.ndarray, lift_off_skip: float = 0.10,
            touch_down_skip: float = 0.05, gaps: tuple[bool, bool] = (False, False)) -> Phases:
    """Support phases and the single-support samples kept for estimation.

    Args:
        time: (N,) [s].
        contact: (N, n_contacts) boolean contact flags.
        lift_off_skip: seconds dropped after each lift-off that starts a single-support
            run (thesis: 0.10 s).
        touch_down_skip: seconds dropped before each touch-down that ends one
            (thesis: 0.05 s).
        gaps: whether a time gap comes before the first row and after the last (a segment of a
            log cut at its gaps): what happened in a gap is not known, so a run that starts
            (ends) there is trimmed as if a lift-off (touch-down) had just happened.

    A single-support run that starts (ends) at the first (last) row of the log has no
    observed lift-off (touch-down) and is not trimmed on that side, unless a gap is there.
    """
    if lift_off_skip < 0 or touch_down_skip < 0:
        raise InputError("lift-off and touch-down margins must be >= 0 s")
    n_contacts = contact.sum(axis=1)
    single = n_contacts == 1
    stance = np.where(single, np.argmax(contact, axis=1), -1)
    keep = single.copy()
    change = np.ones(len(time), dtype=bool)
    change[1:] = stance[1:] != stance[:-1]
    run_id = np.cumsum(change)
    for start, stop in true_runs(single):
        # split a single-support run where the stance foot changes without double support
        for s in np.unique(run_id[start:stop]):
            idx = np.flatnonzero(run_id[start:stop] == s) + start
            a, b = idx[0], idx[-1] + 1
            if a > 0 or gaps[0]:
                keep[a:b] &= time[a:b] - time[a] >= lift_off_skip - 1e-9
            if b < len(time) or gaps[1]:
                # at a gap: as if the touch-down were the next sample, one step after the last
                end = time[b] if b < len(time) else 2 * time[b - 1] - time[max(b - 2, 0)]
                keep[a:b] &= end - time[a:b] > touch_down_skip + 1e-9
    return Phases(n_contacts, stance, keep)


def joint_mask(phases: Phases, limb_mask: np.ndarray, mask: Mask = "swing") -> np.ndarray:
    """Per-joint validity of the single-support estimate.

    Args:
        phases: from :func:`segment`.
        limb_mask: (n_contacts, n_tc), joint j on the limb of contact c
            (:attr:`Robot.limb_mask`).
        mask: ``"swing"`` or ``"single"`` (module docstring).

    Returns:
        Boolean (N, n_tc).

    Raises:
        InputError: unknown mask.
    """
    if mask not in MASKS:
        raise InputError(f"unknown mask '{mask}': choose one of {', '.join(MASKS)}")
    valid = np.repeat(phases.keep[:, None], limb_mask.shape[1], axis=1)
    if mask == "swing":
        on_stance_limb = np.zeros_like(valid)
        single = phases.stance >= 0
        on_stance_limb[single] = limb_mask[phases.stance[single]]
        valid &= ~on_stance_limb
    return valid


def settled(time: np.ndarray, contact: np.ndarray, lift_off_skip: float = 0.10, touch_down_skip: float = 0.05
            ) -> np.ndarray:
    """(N,) the samples away from every contact change, for robots whose friction is determined in any phase (point
    feet, :mod:`wbfriction.model.determination`): the thesis's margins (6.2.1) around each foot's switches, the
    ``lift_off_skip`` seconds after a flag falls and the ``touch_down_skip`` seconds before and after one rises
    (the landing's impact, which differentiation smears on both sides).

    Args:
        time: (N,) [s]; contact: (N, n_contacts) flags.
    """
    keep = np.ones(len(time), dtype=bool)
    for c in range(contact.shape[1]):
        on = contact[:, c].astype(bool)
        for k in np.flatnonzero(on[1:] != on[:-1]) + 1:
            t = time[k]
            if on[k]:  # touch-down at row k
                keep &= ~((time >= t - touch_down_skip - 1e-9) & (time < t + touch_down_skip - 1e-9))
            else:  # lift-off at row k
                keep &= ~((time >= t - 1e-9) & (time < t + lift_off_skip - 1e-9))
    return keep
