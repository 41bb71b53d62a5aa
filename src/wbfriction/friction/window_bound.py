"""The windows a log's swings allow: a window chosen from the noise bounded by half the shortest swing, a window
given that no swing can hold refused naming it (issue 82).

:func:`~wbfriction.friction.decision.decide_log` chooses the differentiation's window and the momentum route's from
the positions' noise alone. On a robot whose feet leave the ground that is not enough: a sample is estimated only
where its whole window lies inside one phase, and a window longer than a swing leaves none of it
(:mod:`wbfriction.signals.phase_window`). So, once per log, before any work:

* a window chosen from the noise longer than :func:`~wbfriction.signals.phase_window.window_bound` of the shortest
  swing (of those longer than the lift-off and touch-down margins: nothing of a shorter one is estimated) is bounded
  to it (the momentum route's momentum window first, then its velocity window; each at least its
  scheme's least), the noise it then leaves recomputed, and the log's warnings say so in one line
  (:meth:`WindowBound.warning`); the estimate's metadata records it (``window_bound``);
* a window given (``--window``, ``--momentum-window``, ``--velocity-window``) is kept, but one that leaves no sample
  of even the longest swing is refused in one line naming it and the longest window that keeps half the shortest
  swing (:func:`refuse_given`), where the swings are the only phases estimated (no force sensed at the feet);
  otherwise the refusal would come after the work, and blame the feet's forces;
* margins that leave no row of any swing are refused the same way, naming ``--lift-off`` and ``--touch-down``
  (:func:`refuse_margins`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from wbfriction.exceptions import OptionError
from wbfriction.friction.options import EstimateOptions
from wbfriction.friction.route import RouteDecision
from wbfriction.signals.choice import (
    MOMENTUM_ORDER,
    DiffChoice,
    momentum_noise_gain,
    savgol_cutoff,
    savgol_noise_gain,
    velocity_noise_gain,
)
from wbfriction.signals.phase_window import Swing, Swings, samples_left, window_bound

LEAST_MOMENTUM = (7, 3)
"""The momentum route's least velocity and momentum windows [samples] (order :data:`MOMENTUM_ORDER`'s least
Savitzky-Golay window, and a window of one step each side)."""


def least_savgol(order: int) -> int:
    """The least odd Savitzky-Golay window of order ``order`` (:func:`~wbfriction.signals.choice.savgol_choice`'s)."""
    return order + 2 + (order + 1) % 2


def _odd_at_most(x: int) -> int:
    return x if x % 2 else x - 1


@dataclass(frozen=True)
class WindowBound:
    """A window chosen from the noise, bounded by the shortest swing.

    Attributes:
        what: which window (``the differentiation's savgol window``, ``the momentum route's windows``).
        before, after: its span [samples] before and after (a Savitzky-Golay window; the momentum route's
            ``L_v + L_m - 1``).
        swing: the shortest swing, which bounds it.
        dt: the sampling period [s].
    """

    what: str
    before: int
    after: int
    swing: Swing
    dt: float
    stretch: bool = False

    def phrase(self) -> str:
        """What was bounded, before and after (and by what, when it is a stretch, not a swing)."""
        by = (f" by the shortest stretch estimated while {self.swing.frame} swings ({self.swing.samples} samples, "
              f"{self.swing.seconds:.3g} s, from row {self.swing.start}: a swing less the switches' margins)"
              if self.stretch else "")
        return (f"{self.what} {self.before} samples ({self.before * self.dt:.3g} s) -> {self.after} "
                f"({self.after * self.dt:.3g} s){by}")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready record: the window, its spans and the swing."""
        return {"what": self.what, "before": self.before, "after": self.after, "swing_frame": self.swing.frame,
                "swing_samples": self.swing.samples, "swing_seconds": self.swing.seconds}


def warning(bounds: tuple[WindowBound, ...], source: str) -> str:
    """The one line saying ``bounds`` (not empty) were made."""
    s = bounds[0].swing
    if bounds[0].stretch:
        return (f"{source}: window chosen from the noise longer than half the rows it must lie in: "
                f"{'; '.join(b.phrase() for b in bounds)}; a longer window would leave less of each stretch than it "
                "costs")
    return (f"{source}: window chosen from the noise longer than half the shortest swing ({s.frame}, {s.samples} "
            f"samples, {s.seconds:.3g} s, from row {s.start}): {'; '.join(b.phrase() for b in bounds)}; a longer "
            "window would leave less of each swing than it costs")


def refuse_given(given: EstimateOptions, options: EstimateOptions, swings: Swings) -> None:
    """Refuse a window given that leaves no sample of even the longest swing (module docstring).

    Raises:
        OptionError: naming the option, its value, the swings and the longest window that keeps half the shortest
            swing.
    """
    longest, shortest = swings.longest(), swings.shortest(1, options.lift_off_skip + options.touch_down_skip)
    if longest is None:
        return
    keep = window_bound((shortest or longest).samples)
    why = (f"at most {keep} (half the shortest swing; the window {{span}} samples, {{seconds:.3g}} s, is longer than "
           f"every swing, the longest {longest.samples} samples, {longest.seconds:.3g} s ({longest.frame}): no sample "
           "away from a contact change)")
    dt = longest.seconds / longest.samples
    m = options.momentum
    if options.route == "momentum" and m.window is not None and m.velocity_window is not None:
        span = m.velocity_window + m.window - 1
        for flag, value, was in (("--momentum-window", m.window, given.momentum.window),
                                 ("--velocity-window", m.velocity_window, given.momentum.velocity_window)):
            if was is not None and samples_left(span, longest.samples) == 0:
                raise OptionError(flag, value, why.format(span=span, seconds=span * dt))
    elif options.diff == "savgol" and given.diff != "auto":
        span = options.filtering.window
        if samples_left(span, longest.samples) == 0:
            raise OptionError("--window", span, why.format(span=span, seconds=span * dt))


def refuse_margins(options: EstimateOptions, swings: Swings) -> None:
    """Refuse lift-off and touch-down margins that leave no row of any swing, where the swings are the only phases
    estimated (no force sensed at the feet): every swing is then shorter than the margins and the other feet's
    switches leave of it (a small robot's swings, 0.2 s on a Solo-12, against the thesis's 0.10 + 0.05 s), and
    the refusal would otherwise come after the work, as "no valid sample".

    Raises:
        OptionError: naming ``--lift-off``, both margins and the longest swing.
    """
    longest = swings.longest()
    if longest is None or swings.stretches:
        return
    raise OptionError("--lift-off", options.lift_off_skip,
                      f"shorter, with --touch-down ({options.touch_down_skip:g} s), than a swing: together they "
                      f"leave no row of any swing (the longest {longest.samples} samples, {longest.seconds:.3g} s, "
                      f"{longest.frame}, less both margins and the other feet's switches); without foot forces only "
                      "the swings are estimated")


def bound_windows(given: EstimateOptions, options: EstimateOptions, choice: DiffChoice | None,
                  route: RouteDecision | None, swings: Swings, dt: float
                  ) -> tuple[EstimateOptions, DiffChoice | None, RouteDecision | None, tuple[WindowBound, ...]]:
    """The windows chosen from the noise bounded by the shortest swing (module docstring); windows given kept.

    Args:
        given: the options as asked; options: resolved (:func:`~wbfriction.friction.decision.decide_log`).
        choice, route: the decisions that chose them, their noise recomputed where bounded.
        swings: the log's swings (:func:`~wbfriction.signals.phase_window.log_swings`); dt: its period [s].

    Returns:
        The options, the choice and the route decision, bounded, and what was bounded (empty: nothing; the
        arguments then come back as they are).
    """
    bounds: list[WindowBound] = []
    margins = options.lift_off_skip + options.touch_down_skip  # a swing no longer than them is lost anyway
    if choice is not None and options.diff == "savgol" and given.diff == "auto":
        order, weights = options.filtering.poly_order, options.filtering.weights
        swing = swings.shortest(least_savgol(order), margins)
        if swing is not None and options.filtering.window > window_bound(swing.samples):
            window = max(least_savgol(order), window_bound(swing.samples))
            bounds.append(WindowBound("the differentiation's savgol window", options.filtering.window, window, swing,
                                      dt))
            options = replace(options, filtering=replace(options.filtering, window=window))
            choice = _bounded_choice(choice, window, order, weights, dt, swing)
    m = options.momentum
    if m.window is not None and m.velocity_window is not None and (given.momentum.window is None
                                                                    or given.momentum.velocity_window is None):
        swing = swings.shortest(sum(LEAST_MOMENTUM) - 1, margins)
        span = m.velocity_window + m.window - 1
        if swing is not None and span > window_bound(swing.samples):
            vw, w = _momentum_windows(m.velocity_window, m.window, window_bound(swing.samples), given)
            bounds.append(WindowBound("the momentum route's windows", span, vw + w - 1, swing, dt))
            options = replace(options, momentum=replace(m, velocity_window=vw, window=w))
            route = _bounded_route(route, vw, w, dt, swing) if route is not None else None
        options, route = _bound_by_stretches(given, options, route, swings, dt, bounds)
    return options, choice, route, tuple(bounds)


def _bound_by_stretches(given: EstimateOptions, options: EstimateOptions, route: RouteDecision | None,
                        swings: Swings, dt: float, bounds: list[WindowBound]
                        ) -> tuple[EstimateOptions, RouteDecision | None]:
    """The momentum route's momentum window bounded by the shortest stretch it estimates while a foot swings
    (:attr:`~wbfriction.signals.phase_window.Swings.stretches`: a swing less the lift-off and touch-down margins and
    the other feet's switches): its impulses are summed over windows that lie whole inside those rows, so the same
    bound as a swing's (:func:`~wbfriction.signals.phase_window.window_bound`) applies to it; ``bounds`` appended."""
    m = options.momentum
    stretch = swings.shortest_stretch(LEAST_MOMENTUM[1])
    if given.momentum.window is not None or m.window is None or m.velocity_window is None or stretch is None:
        return options, route
    w = max(LEAST_MOMENTUM[1], window_bound(stretch.samples))
    if w >= m.window:
        return options, route
    bounds.append(WindowBound("the momentum route's momentum window", m.window, w, stretch, dt, stretch=True))
    options = replace(options, momentum=replace(m, window=w))
    bounded = None if route is None else _bounded_route(route, m.velocity_window, w, dt, stretch,
                                                        "stretch estimated while a foot swings")
    return options, bounded


def _momentum_windows(vw: int, w: int, bound: int, given: EstimateOptions) -> tuple[int, int]:
    """The momentum route's windows bounded to a span of ``bound``: the momentum window first, then the velocity
    window, each at least its least (:data:`LEAST_MOMENTUM`), a window given kept."""
    if given.momentum.window is None:
        w = max(LEAST_MOMENTUM[1], _odd_at_most(bound - vw + 1))
    if vw + w - 1 > bound and given.momentum.velocity_window is None:
        vw = max(LEAST_MOMENTUM[0], _odd_at_most(bound - w + 1))
    return vw, w


def _bounded_choice(choice: DiffChoice, window: int, order: int, weights: Any, dt: float, swing: Swing) -> DiffChoice:
    """``choice`` with its Savitzky-Golay window bounded to ``window`` by ``swing``, its noise and cutoff recomputed."""
    left = choice.position_noise * savgol_noise_gain(window, order, dt, weights)
    return replace(choice, filtering=replace(choice.filtering, window=window), noise_left=left,
                   filter_cutoff=savgol_cutoff(window, order, dt, weights), reached=left <= choice.target,
                   reason=f"{choice.reason}; bounded to L={window} by the shortest swing ({swing.frame}, "
                          f"{swing.samples} samples): it leaves {left:.2g} rad/s^2")


def _bounded_route(route: RouteDecision, vw: int, w: int, dt: float, swing: Swing, what: str = "swing"
                   ) -> RouteDecision:
    """``route`` with the momentum route's windows bounded to ``vw`` and ``w`` by ``swing`` (the shortest ``what``:
    a swing, or a stretch the route estimates while a foot swings), their noise recomputed."""
    sigma = route.position_noise
    velocity = sigma * velocity_noise_gain(vw, dt, MOMENTUM_ORDER) if math.isfinite(sigma) else math.nan
    left = sigma * momentum_noise_gain(vw, (w - 1) // 2, dt) if math.isfinite(sigma) else math.nan
    return replace(route, velocity_window=vw, window=w, velocity_noise=velocity, noise_left=left,
                   reason=f"{route.reason}; windows bounded to {vw} and {w} by the shortest {what} ({swing.frame}, "
                          f"{swing.samples} samples)")
