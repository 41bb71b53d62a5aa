"""What is decided once per log, before any row is estimated: the differentiation, the route, the noise.

Both ways a log is estimated, whole in memory (:func:`~wbfriction.friction.estimate.estimate_log`) and chunk by
chunk from its file (:func:`~wbfriction.pipeline.estimate_step.estimate_file`), decide through one function,
:func:`decide_log`, in one order:

1. the differentiation ``diff="auto"`` stands for (:func:`resolve_differentiation`: the scheme and its filter
   from the positions' noise);
2. the route ``route="auto"`` stands for and the momentum route's windows
   (:func:`~wbfriction.friction.route.resolve_route`, reusing the noise the first step measured);
3. on a robot whose feet leave the ground, the windows chosen bounded by half the shortest swing, a window given that
   no swing can hold refused (:mod:`~wbfriction.friction.window_bound`); then the windows checked against the log's
   longest stretch between time gaps (:func:`check_windows`);
4. the noise record the fit reads (:func:`~wbfriction.friction.noise.noise_record`), or why there is none
   (:func:`unmeasured_noise`).

The two ways differ in what they hand it, and keep doing so, so that no estimate already made moves: the positions
the noise is measured on (the whole log's longest stretch in memory; of a file, the longest stretch of its first
:data:`~wbfriction.logs.clock.ROUGHNESS_ROWS` rows, which are all it reads before its chunks), and the samples the
route's windows are bounded by (``route_rows``: the whole log's rows in memory; of a file, those positions' rows).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from wbfriction.exceptions import InputError, OptionError
from wbfriction.friction.noise import noise_record
from wbfriction.friction.options import EstimateOptions
from wbfriction.friction.route import RouteDecision, resolve_route
from wbfriction.friction.window_bound import WindowBound, bound_windows, refuse_given, refuse_margins
from wbfriction.friction.window_bound import warning as window_warning
from wbfriction.logs.clock import longest_segment
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot
from wbfriction.signals.choice import DiffChoice, choose_differentiation
from wbfriction.signals.content import contact_changes
from wbfriction.signals.phase_window import Swings


@dataclass(frozen=True)
class LogDecision:
    """What :func:`decide_log` decided for one log.

    Attributes:
        options: the options with every choice left to the data made (``diff``, ``route``, the windows).
        differentiation: the choice ``diff="auto"`` made (:class:`~wbfriction.signals.choice.DiffChoice`), or None
            (a scheme given, or no positions to choose from).
        route: the route decision (:class:`~wbfriction.friction.route.RouteDecision`), or None (route and windows
            all given).
        noise: the noise record the fit reads (:func:`~wbfriction.friction.noise.noise_record`), or None.
        noise_unmeasured: why a fit of the estimate cannot be called ``ok`` (:func:`unmeasured_noise`), or "".
        bounds: the windows chosen from the noise that the shortest swing bounded
            (:func:`~wbfriction.friction.window_bound.bound_windows`; empty: none).
        source: the log's name, for :attr:`warnings`.
    """

    options: EstimateOptions
    differentiation: DiffChoice | None
    route: RouteDecision | None
    noise: dict[str, Any] | None
    noise_unmeasured: str = ""
    bounds: tuple[WindowBound, ...] = ()
    source: str = "the log"

    @property
    def warnings(self) -> tuple[str, ...]:
        """What the decision says before the work, one line each: the windows the shortest swing bounded."""
        return (window_warning(self.bounds, self.source),) if self.bounds else ()

    def metadata(self) -> dict[str, Any]:
        """The estimate's metadata entries (fresh dictionaries, the noise record shared): ``noise_unmeasured``,
        ``differentiation``, ``route``, ``noise``, those there are."""
        out: dict[str, Any] = {}
        if self.noise_unmeasured:
            out["noise_unmeasured"] = self.noise_unmeasured
        if self.differentiation is not None:
            out["differentiation"] = self.differentiation.to_dict()
        if self.route is not None:
            out["route"] = self.route.to_dict()
        if self.noise is not None:
            out["noise"] = self.noise
        if self.bounds:
            out["window_bound"] = {"warning": self.warnings[0], "bounds": [b.to_dict() for b in self.bounds]}
        return out


def decide_log(robot: Robot, options: EstimateOptions, positions: np.ndarray | None, dt: float, *,
               segments: list[tuple[int, int]] | None, rows: int, source: str,
               route_rows: int | None = None, changes: np.ndarray | None = None, swings: Swings | None = None,
               swings_only: bool = False) -> LogDecision:
    """Decide once for a log what ``options`` leave to the data, and measure its noise (module docstring).

    Args:
        robot: the robot (the noise record's inertias).
        options: the options as asked.
        positions: the positions (M, n_act) [rad] the noise is measured on: one stretch without a time gap; None:
            none could be read (a file's first rows not finite: central differences, the acceleration route, no
            noise record, nothing said of it).
        dt: the sampling period [s].
        segments, rows: the whole log's row ranges between time gaps (None: one) and its rows, which the windows
            must fit in (:func:`check_windows`).
        source: the log's name, for the messages.
        route_rows: the samples the route's windows are bounded by
            (:func:`~wbfriction.friction.route.choose_route`); default the rows of ``positions``.
        changes: the rows of ``positions`` where a contact flag changes
            (:func:`~wbfriction.signals.content.contact_changes`): their impacts are not counted as noise.
        swings: the whole log's swings (:func:`~wbfriction.signals.phase_window.log_swings`), which bound the windows
            chosen (:func:`~wbfriction.friction.window_bound.bound_windows`); None: none (a fixed base).
        swings_only: the swings are the only phases estimated (no force sensed at the feet): a window given that none
            of them holds is refused (:func:`~wbfriction.friction.window_bound.refuse_given`), and margins that leave
            none of them (:func:`~wbfriction.friction.window_bound.refuse_margins`).

    Raises:
        OptionError: a window given longer than the log's longest stretch, or than every swing (``swings_only``);
            InputError: one the data chose, or stretches too short for any scheme (:func:`check_windows`).
    """
    given = options
    options, choice = resolve_differentiation(options, positions, dt, changes)
    options, route = resolve_route(options, positions, dt, choice, rows=route_rows, asked=given.filtering)
    bounds: tuple[WindowBound, ...] = ()
    if swings is not None and swings.swings:
        if swings_only:
            refuse_margins(options, swings)
            refuse_given(given, options, swings)
        options, choice, route, bounds = bound_windows(given, options, choice, route, swings, dt)
    check_windows(given, options, segments, rows, dt, source)
    if positions is None:
        return LogDecision(options, choice, route, None, bounds=bounds, source=source)
    record = noise_record(robot, positions, dt, options, changes)
    return LogDecision(options, choice, route, record, unmeasured_noise(record, len(positions), options), bounds,
                       source)


def longest_stretch(log: Log) -> tuple[np.ndarray, np.ndarray | None]:
    """The positions (M, n_act) [rad] of the log's longest stretch between time gaps, and the rows (M,) where a
    contact flag changes there (:func:`~wbfriction.signals.content.contact_changes`, None: none)."""
    a, b = longest_segment(log.segments, len(log.time))
    return log.q[a:b], contact_changes(log.contact[a:b])


def resolve_differentiation(options: EstimateOptions, source: Log | np.ndarray | None,
                            dt: float | None = None, changes: np.ndarray | None = None
                            ) -> tuple[EstimateOptions, DiffChoice | None]:
    """``options`` with ``diff="auto"`` replaced by the scheme and filter chosen from the positions
    (:func:`~wbfriction.signals.choice.choose_differentiation`), and that choice; other options as
    they are, and None.

    Args:
        source: the log, or positions (N, n_act) [rad] sampled every ``dt`` [s] (the first rows
            of a long log); None: nothing to choose from (central differences, no choice).
        changes: the rows of positions where a contact flag changes, not counted as noise (a log: its own).

    A log too short to measure its noise gets central differences, and a choice that says why.
    """
    if options.diff != "auto":
        return options, None
    if source is None:
        return replace(options, diff="central"), None
    try:
        choice = choose_differentiation(source, dt, target=options.noise_target, changes=changes)
    except InputError as exc:  # too short a log to measure its noise: say so, differentiate it plainly
        choice = DiffChoice.fallback(f"central differences: {exc}")
    return replace(options, diff=choice.scheme, filtering=choice.filtering), choice


UNMEASURED = "the positions' noise could not be measured"
"""How :func:`unmeasured_noise` starts, and so the reason of a fit on such an estimate: a parameters file of an earlier
version wrote it only there (:func:`~wbfriction.fit.params_file.written_unmeasured`)."""


def unmeasured_noise(record: dict | None, longest: int, options: EstimateOptions) -> str:
    """Why a fit of this estimate cannot be called ``ok`` (the metadata's ``noise_unmeasured``,
    :attr:`~wbfriction.fit.result.FitResult.unmeasured`): the positions' noise not measured (``record`` None) on
    the ``longest`` samples between time gaps, so no Cramér-Rao bound says what the data allow; "" when measured,
    or for the simulators' true derivatives (no noise)."""
    if record is not None or options.diff == "true":
        return ""
    return (f"{UNMEASURED}: the longest stretch without a time gap has {longest} samples (no Cramér-Rao bound)")


FILTER_SPAN = 5_000_000
"""Rows beyond which a Butterworth filter's response is not computed (its cutoff refused): 40 MB per array."""


def check_windows(given: EstimateOptions, options: EstimateOptions, segments: list[tuple[int, int]] | None,
                  rows: int, dt: float, source: str) -> None:
    """Refuse, before any work, windows no stretch of the log between two time gaps can hold: nothing would be
    estimated (or a filter's response too long to compute). The option is named when it was given (``given``, the
    options before :func:`resolve_differentiation` and :func:`~wbfriction.friction.route.resolve_route`); a window
    the data chose is refused with the stretches' length.

    Args:
        given: the options as asked; options: resolved.
        segments: the log's row ranges between time gaps (None: one); rows: its length; dt: its step [s].

    Raises:
        OptionError: a given window (``--window``, ``--cutoff``, ``--momentum-window``, ``--velocity-window``) longer
            than the longest stretch; InputError: a chosen one, or stretches too short for any scheme.
    """
    a, b = longest_segment(segments, rows)
    longest = b - a
    where = f"at most the {longest} samples of the log's longest stretch without a time gap"
    asked = given.diff != "auto"
    if options.route == "momentum":
        vw, w = options.momentum.velocity_window, options.momentum.window
        if vw is None or w is None:
            return
        for flag, value, was in (("--momentum-window", w, given.momentum.window),
                                 ("--velocity-window", vw, given.momentum.velocity_window)):
            if value > longest and was is not None:
                raise OptionError(flag, value, where)
        need, what = w + vw - 1, f"the momentum route's windows (--velocity-window {vw}, --momentum-window {w})"
        if need > longest and given.momentum.window is not None and given.momentum.velocity_window is not None:
            raise OptionError("--momentum-window", w, f"{where}, less --velocity-window {vw} - 1")
    elif options.diff == "savgol":
        need, what = options.filtering.window, f"a Savitzky-Golay window of {options.filtering.window} (--window)"
        if need > longest and asked:
            raise OptionError("--window", need, where)
    elif options.diff == "butterworth":
        from wbfriction.signals.filters import ZeroPhaseLowpass
        f = options.filtering
        span = int(20 * f.butter_order / (f.cutoff * dt)) + 1 if f.cutoff > 0 else FILTER_SPAN + 1
        # the response's half width is at least a hundredth of ``span`` (FILTER_SPAN: not computed beyond it)
        if span > FILTER_SPAN or span // 100 > longest:
            need = 2 * (span // 100) + 1
        else:
            need = 2 * ZeroPhaseLowpass(f.cutoff, f.butter_order, dt).half_width + 1
        what = f"a Butterworth filter of {f.cutoff:g} Hz, order {f.butter_order} ({need} samples or more; --cutoff)"
        if need > longest and asked:
            raise OptionError("--cutoff", f.cutoff, f"high enough for the filter's response ({need} samples or "
                              f"more) to fit in {where.removeprefix('at most ')}")
    else:
        need, what = 3, f"{options.diff} differences"
    if need > longest:
        raise InputError(f"{source}: the longest stretch without a time gap has {longest} samples, fewer than "
                         f"{what} needs ({need}): nothing could be estimated")
