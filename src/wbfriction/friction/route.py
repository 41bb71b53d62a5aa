"""Which route, and how much smoothing: chosen from the log's position noise, once per log (issue 38).

Both routes leave at most ``options.noise_target`` (:data:`~wbfriction.signals.options.NOISE_TARGET`) of the
position noise in the friction (per unit inertia, in rad/s^2). The acceleration route (thesis ch. 5) does it by a
Savitzky-Golay window ``L_a`` on the positions, whose velocity is also the friction model's argument; the momentum route
(:mod:`~wbfriction.friction.momentum`) by a window on the momenta, its velocity filtered only to
:data:`~wbfriction.signals.choice.VELOCITY_NOISE_TARGET` by a window ``L_v``
(:func:`~wbfriction.signals.choice.choose_momentum_smoothing`). The route is the acceleration route where
central differences meet the target or ``L_a <= 2 L_v`` (a clean encoder, a simulator's exact log: every
sample its own estimate or nearly, the thesis's route), the momentum route where the acceleration's filter
would smooth the model's argument over more than twice the samples its noise needs (:data:`WINDOW_RATIO`;
159 samples against 59 at 1 kHz with 1e-4 rad of noise, 65 against 15 with 1e-5 rad).
The simulators' true derivatives (``diff = "true"``) are the acceleration route's.

:func:`resolve_route` replaces ``route = "auto"`` and the windows left to the data, keeps every window
the user gave, and says why in one line (:attr:`RouteDecision.reason`), as ``diff = "auto"`` does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from wbfriction.choices import flag
from wbfriction.exceptions import InputError
from wbfriction.friction.options import EstimateOptions, MomentumOptions, Route
from wbfriction.logs.clock import longest_segment
from wbfriction.logs.log import Log
from wbfriction.signals.choice import (
    DiffChoice,
    MomentumSmoothing,
    central_noise_gain,
    choose_momentum_smoothing,
    savgol_choice,
)
from wbfriction.signals.content import acceleration_content
from wbfriction.signals.options import FilterOptions

WINDOW_RATIO = 2.0
"""The momentum route is chosen where the acceleration route's window exceeds its velocity window this many times
(module docstring): with windows of a few samples the routes differ by less than the quadrature of either."""


@dataclass(frozen=True)
class RouteDecision:
    """The route and the momentum route's windows, and why.

    Attributes:
        route: the route estimated (the other one is its check).
        reason: one printable line.
        position_noise: white position noise measured [rad] (median over the moving joints; NaN: not measured).
        velocity_window, window: the momentum route's windows [samples]
            (:class:`~wbfriction.friction.options.MomentumOptions`).
        velocity_noise: RMS noise its velocity filter leaves [rad/s].
        noise_left: RMS acceleration noise it leaves per unit inertia [rad/s^2].
        noise_central: the same for central second differences, the acceleration route's unfiltered scheme.
        sample_rate: 1 / dt [Hz].
    """

    route: Route
    reason: str
    position_noise: float
    velocity_window: int
    window: int
    velocity_noise: float
    noise_left: float
    noise_central: float
    sample_rate: float

    def __str__(self) -> str:
        return self.reason

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready record (a table's metadata): every field; NaN as None."""
        return {f.name: (None if isinstance(v, float) and not math.isfinite(v) else v)
                for f in fields(self) for v in [getattr(self, f.name)]}


def _position_noise(source: Log | np.ndarray | None, dt: float, choice: DiffChoice | None) -> float:
    """The positions' white noise [rad]: the differentiation choice's measurement, else measured here (NaN for a
    log too short to measure it)."""
    if choice is not None and math.isfinite(choice.position_noise):
        return choice.position_noise
    if source is None:
        return math.nan
    q = source.q[slice(*longest_segment(source.segments, len(source.time)))] if isinstance(source, Log) else source
    try:
        content = acceleration_content(np.asarray(q, dtype=float), dt)
    except InputError:
        return math.nan
    moving = content.moving
    return float(np.median(content.position_noise[moving] if moving.any() else content.position_noise))


def choose_route(options: EstimateOptions, sigma: float, dt: float, n_samples: int) -> RouteDecision:
    """The route ``options.route`` stands for and the momentum windows (module docstring), for a white position
    noise ``sigma`` [rad] (NaN: not measured) of a log of ``n_samples`` sampled every ``dt`` [s]."""
    given = options.momentum
    if math.isfinite(sigma):
        smoothing = choose_momentum_smoothing(sigma, dt, n_samples, velocity_window=given.velocity_window,
                                              window=given.window, target=options.noise_target)
    else:  # not measured: the least smoothing, or what was given
        smoothing = MomentumSmoothing(given.velocity_window or 7, given.window or 3, math.nan, math.nan, False)
    central = sigma * central_noise_gain(dt)
    longest = max(7, (n_samples // 4) * 2 - 1)
    target = options.noise_target
    accel_window = (savgol_choice(sigma, dt, 4, "uniform", target, longest)[0].window
                    if math.isfinite(sigma) and central > target else 1)
    momentum = (f"momentum: velocity savgol L={smoothing.velocity_window} k=4 ({smoothing.velocity_noise:.2g} rad/s "
                f"of noise), window of {smoothing.window} samples ({smoothing.noise_left:.2g} rad/s^2 left)")
    route: Route
    if options.route != "auto":
        route = options.route
        why = ("acceleration" if route == "acceleration" else momentum) + ", as asked"
    elif options.diff == "true":
        route, why = "acceleration", "acceleration: the simulator's true derivatives (diff 'true')"
    elif not math.isfinite(sigma):
        route, why = "acceleration", "acceleration: the log is too short to measure its noise"
    elif central <= target:
        route = "acceleration"
        why = (f"acceleration: central second differences leave {central:.2g} rad/s^2 of noise (target "
               f"{target:g}): every sample its own estimate, no window")
    elif accel_window <= WINDOW_RATIO * smoothing.velocity_window:
        route = "acceleration"
        why = (f"acceleration: a savgol window of {accel_window} samples meets the noise target, no more than "
               f"{WINDOW_RATIO:g} times the momentum route's velocity window ({smoothing.velocity_window})")
    else:
        route = "momentum"
        why = (f"{momentum}: the positions carry {sigma:.2g} rad of noise; the acceleration route would smooth the "
               f"velocity over {accel_window} samples")
    return RouteDecision(route, why, sigma, smoothing.velocity_window, smoothing.window, smoothing.velocity_noise,
                         smoothing.noise_left, central, 1.0 / dt)


def resolve_route(options: EstimateOptions, source: Log | np.ndarray | None, dt: float | None = None,
                  choice: DiffChoice | None = None, *, rows: int | None = None, asked: FilterOptions | None = None
                  ) -> tuple[EstimateOptions, RouteDecision | None]:
    """``options`` with ``route = "auto"`` and the momentum windows left to the data replaced (module docstring),
    and the decision; options whose route and windows are all given come back as they are, with None.

    Args:
        source: the log, or positions (N, n_act) [rad] sampled every ``dt`` [s] (the first rows of a long log);
            None: nothing to measure (the acceleration route, the shortest windows).
        choice: the differentiation choice made for the same log, whose noise measurement is reused.
        rows: the samples the windows are bounded by (:func:`choose_route`'s ``n_samples``); default a log's rows,
            an array's length (0 for None).
        asked: the acceleration route's filter as the user gave it, before a differentiation choice filled it in
            (default ``options.filtering``): what the momentum route says it does not use.

    Raises:
        InputError: positions given as an array without ``dt``.
    """
    given = options.momentum
    if options.route != "auto" and given.velocity_window is not None and given.window is not None:
        return options, None
    if isinstance(source, Log):
        dt = source.dt if dt is None else dt
        n = len(source.time)
    elif source is not None:
        if dt is None:
            raise InputError("route choice: positions given as an array need the sample period dt")
        n = len(source)
    else:
        n = 0
    n = n if rows is None else rows
    decision = choose_route(options, _position_noise(source, dt or 1.0, choice), dt or 1.0, max(n, 1))
    asked = options.filtering if asked is None else asked
    unused = [f"{flag(f.name)} {getattr(asked, f.name)}" for f in fields(FilterOptions)
              if getattr(asked, f.name) != f.default]
    if decision.route == "momentum" and unused:  # the filter given is the acceleration route's: said, not dropped
        decision = replace(decision, reason=f"{decision.reason}; {', '.join(unused)} not used (the acceleration "
                           "route's filter; --route acceleration keeps it)")
    momentum = MomentumOptions(decision.velocity_window, decision.window)
    return replace(options, route=decision.route, momentum=momentum), decision
