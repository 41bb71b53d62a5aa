"""Footstep plans and their contact timeline (thesis 6.2.2: 0.8 s single, 0.2 s double support).

A plan is a list of steps. Each step lifts one foot at ``lift_off``, swings it for the
single-support time and puts it down flat at ``target`` (a planar pose on the ground:
x, y [m] in the world frame, yaw [rad] about the vertical). Between steps, both feet
stand (double support). Gaits:

* ``forward``: consecutive footprints ``step_length`` apart along the walking direction
  (the swing foot travels twice that in mid-walk); the last step closes the feet.
* ``sideways``: the leading foot steps ``step_width`` outward, then the trailing foot
  follows by as much (every foot travels ``step_width``); about half of the steps (an
  even number) go to the left (``step_width > 0``), the rest back, so that every joint
  moves both ways.
* ``turning``: footprints ``turn_length`` apart along an arc, the walking direction
  turning by ``turn_angle`` per step, to the left for the first half of the steps and
  back to the right for the second (a swinging hip yaw moves one way per turn direction);
  each half ends by closing the feet.
* ``both``: ``steps`` forward, then ``steps`` sideways (the thesis's walk of Table 6.2).
* ``combined``: ``steps`` forward, sideways and turning: every leg joint, the hip yaw
  included, moves both ways in swing (the demo's walk).

Contact indices follow :attr:`Robot.contact_frames`: the plan needs two (left, right).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.walking.options import GaitOptions


@dataclass(frozen=True)
class Step:
    """One step: ``foot`` (contact index) leaves ``start`` at ``lift_off`` and lands on ``target``."""

    foot: int
    start: np.ndarray  # (3,) x, y, yaw
    target: np.ndarray  # (3,) x, y, yaw
    lift_off: float
    touch_down: float


@dataclass(frozen=True)
class FootstepPlan:
    """Initial foot poses and the steps, with the timeline they imply.

    Attributes:
        initial_feet: (2, 3) planar poses (x, y, yaw) of the two feet at t = 0.
        steps: the steps in time order.
        duration: total duration [s].
        options: the :class:`GaitOptions` it was planned with.
    """

    initial_feet: np.ndarray
    steps: tuple[Step, ...]
    duration: float
    options: GaitOptions = field(default_factory=GaitOptions)

    def contact(self, time: np.ndarray) -> np.ndarray:
        """Planned contact flags (N, 2): a foot is in contact unless it swings."""
        time = np.asarray(time, dtype=float)
        flags = np.ones((len(time), 2), dtype=bool)
        for s in self.steps:
            flags[(time >= s.lift_off) & (time < s.touch_down), s.foot] = False
        return flags


def _mid_frame(feet: np.ndarray) -> np.ndarray:
    """Walking frame between two planar foot poses: their mean position, the left foot's heading."""
    f = 0.5 * (feet[0] + feet[1])
    f[2] = feet[0, 2]
    return f


def _compose(frame: np.ndarray, local: np.ndarray) -> np.ndarray:
    """Planar pose ``frame ⊕ local`` (x, y, yaw)."""
    c, s = np.cos(frame[2]), np.sin(frame[2])
    return np.array([frame[0] + c * local[0] - s * local[1], frame[1] + s * local[0] + c * local[1],
                     frame[2] + local[2]])


def _walk_targets(frame: np.ndarray, half_width: float, n: int, advance: np.ndarray,
                  first: int) -> list[tuple[int, np.ndarray]]:
    """Alternating steps: step i lands at frame_i ⊕ (0, ±w, 0), frame_i = frame ⊕ i·advance; the last closes."""
    out, f = [], frame.copy()
    for i in range(n):
        foot = (first + i) % 2
        if i < n - 1:
            f = _compose(f, advance)
        side = 1.0 if foot == 0 else -1.0
        out.append((foot, _compose(f, np.array([0.0, side * half_width, 0.0]))))
    return out


def _sideways_targets(feet: np.ndarray, n: int, width: float) -> list[tuple[int, np.ndarray]]:
    """Leading foot out by ``width`` along its own lateral axis, then the trailing foot by as much."""
    lead = 0 if width > 0 else 1
    out, pos = [], feet.copy()
    for i in range(n):
        foot = lead if i % 2 == 0 else 1 - lead
        pos[foot] = _compose(pos[foot], np.array([0.0, width, 0.0]))
        out.append((foot, pos[foot].copy()))
    return out


def plan_footsteps(initial_feet: np.ndarray, options: GaitOptions = GaitOptions()) -> FootstepPlan:
    """Plan the steps of a gait from the initial foot poses (module docstring).

    Args:
        initial_feet: (2, 3) planar poses (x, y, yaw) of the left (0) and right (1) feet.
        options: :class:`GaitOptions`.

    Returns:
        A :class:`FootstepPlan`; forward and turning walks start with the right foot,
        sideways walks with the leading foot.
    """
    feet = np.asarray(initial_feet, dtype=float).copy()
    if feet.shape != (2, 3):
        raise InputError(f"initial_feet must be (2, 3) (x, y, yaw of two feet), got {feet.shape}")
    o = options
    half_width = 0.5 * float(np.hypot(*(feet[0, :2] - feet[1, :2])))
    targets: list[tuple[int, np.ndarray]] = []

    def now() -> np.ndarray:
        pos = feet.copy()
        for foot, target in targets:
            pos[foot] = target
        return pos

    if o.gait in ("forward", "both", "combined"):
        targets += _walk_targets(_mid_frame(feet), half_width, o.steps, np.array([o.step_length, 0.0, 0.0]), first=1)
    if o.gait in ("sideways", "both", "combined"):
        half = min(o.steps, 2 * ((o.steps + 3) // 4))  # even: the feet are back together
        targets += _sideways_targets(now(), half, o.step_width)
        targets += _sideways_targets(now(), o.steps - half, -o.step_width)
    if o.gait in ("turning", "combined"):
        half = (o.steps + 1) // 2
        for n, angle in ((half, o.turn_angle), (o.steps - half, -o.turn_angle)):
            if n:
                targets += _walk_targets(_mid_frame(now()), half_width, n,
                                         np.array([o.turn_length, 0.0, angle]), first=1 if angle >= 0 else 0)

    steps, t, placed = [], o.initial, feet.copy()  # the feet as placed so far
    for foot, target in targets:
        steps.append(Step(foot, placed[foot].copy(), target, t, t + o.single_support))
        placed[foot] = target
        t += o.single_support + o.double_support
    duration = t - o.double_support + o.final
    return FootstepPlan(feet, tuple(steps), duration, o)
