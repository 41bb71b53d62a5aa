"""Joint friction estimation from measured kinematics (thesis 5.11-5.13, 6.1).

The acceleration difference of the torque-controlled joints is caused by friction:

.. math:: \\Delta\\ddot q_{tc} = \\ddot q_{msr,tc} - \\ddot q_{est,tc} = M_{mod}^{-1} \\tau_f. \\qquad (5.12)

* **Single support** (one contact): ``M_mod^{-1}`` is invertible and
  ``tau_f = M_mod Delta qdd_tc`` (5.13) is exact. The default route computes it with one
  recursive Newton-Euler pass on the robot re-rooted at the stance foot
  (:mod:`wbfriction.model.stance`), batched in C++ (``pin.rneaInParallel``); ``method="kkt"``
  forms (5.10)-(5.13) explicitly (:mod:`wbfriction.model.dynamics`). Both agree to 1e-9.
* **Double support**: ``M_mod^{-1}`` is singular; the regularised weighted least squares
  (6.1) ``min 1/2 |Delta - M_mod^{-1} tau_f|_W^2 + 1/2 tau_f^T Lambda tau_f`` gives
  ``tau_f = (A^T W A + Lambda)^{-1} A^T W Delta`` with ``A = M_mod^{-1}``. Such samples
  are flagged ``unique = False`` and never valid.

Sign convention: ``tau_f`` is the torque friction exerts on the joint,
``M qdd + h = S^T (tau + tau_f) + J^T lambda``; dissipative friction has ``qd tau_f <= 0``.
"""

from __future__ import annotations

from dataclasses import asdict, fields, replace
from typing import Any, cast

import numpy as np

from wbfriction.exceptions import InputError, OptionError
from wbfriction.friction.estimated import FrictionEstimate, no_single_support
from wbfriction.friction.measured import (
    base_route,
    impacts,
    log_base_motion,
    measured_base,
    wrench_route,
)
from wbfriction.friction.momentum import momentum_estimate
from wbfriction.friction.noise import noise_record
from wbfriction.friction.options import METHODS, EstimateOptions, Route
from wbfriction.friction.route import resolve_route
from wbfriction.logs.clock import longest_segment
from wbfriction.logs.log import Log
from wbfriction.model.dynamics import constrained_dynamics
from wbfriction.model.robot import Robot
from wbfriction.model.stance import stance_frame_pose, stance_model
from wbfriction.progress import Progress
from wbfriction.signals.choice import DiffChoice, choose_differentiation
from wbfriction.signals.kinematics import MeasuredKinematics, joined_smoother, measure, straddling
from wbfriction.signals.options import FILTERING_SCHEMES, Diff, Scheme
from wbfriction.signals.phases import Phases, joint_mask, segment

CHUNK = 4096
def single_support_friction_rnea(robot: Robot, contact_index: int, angles: np.ndarray, qd: np.ndarray,
                                 qdd: np.ndarray, tau_tc: np.ndarray, base: np.ndarray | None = None,
                                 progress: Progress | None = None,
                                 with_delta: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Single-support friction (5.13) by inverse dynamics on the stance-rooted tree.

    Args:
        robot: the robot.
        contact_index: stance contact frame (index into ``robot.contact_frames``).
        angles, qd, qdd: joint positions, velocities, measured accelerations (N, n_act).
        tau_tc: torques of the torque-controlled joints (N, n_tc) [N·m].
        base: logged base poses (N, 7) or None (stance foot flat).
        progress: optional callable receiving numbers of samples done.
        with_delta: compute ``delta_qdd`` (else NaN).

    Returns:
        ``(tau_f, delta_qdd)``: friction (N, n_tc) [N·m], sign convention of
        :mod:`wbfriction.friction.models`, and the acceleration difference (5.12)
        ``Delta qdd_tc = qdd_msr - qdd_est = M_mod^{-1} tau_f`` (N, n_tc) [rad/s^2],
        with ``M_mod`` the stance-rooted mass matrix of the torque-controlled joints
        (:meth:`~wbfriction.model.stance.StanceModel.acceleration_difference`).
    """
    stance = stance_model(robot, contact_index)
    tau_f = np.empty_like(tau_tc, dtype=float)
    delta = np.full_like(tau_tc, np.nan, dtype=float)
    for start in range(0, angles.shape[0], CHUNK):
        sl = slice(start, start + CHUNK)
        pose = stance_frame_pose(robot, stance, angles[sl], None if base is None else base[sl])
        tau_joint, _ = stance.inverse_dynamics(pose, angles[sl], qd[sl], qdd[sl])
        tau_f[sl] = tau_joint[:, robot.tc_index] - tau_tc[sl]
        if with_delta:
            delta[sl] = stance.acceleration_difference(angles[sl], tau_f[sl], robot.tc_index)
        if progress is not None:
            progress(len(tau_f[sl]))
    return tau_f, delta


def single_support(robot: Robot, kin: MeasuredKinematics, rows: np.ndarray, stance: np.ndarray,
                   progress: Progress | None = None, with_delta: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """:func:`single_support_friction_rnea` on the rows ``rows`` (N,) of ``kin``, each on its
    stance contact ``stance`` (N,); returns ``(tau_f, delta_qdd)`` (N, n_tc), NaN elsewhere."""
    n, n_tc = len(kin.time), len(robot.torque_controlled)
    tau_f, delta = np.full((n, n_tc), np.nan), np.full((n, n_tc), np.nan)
    for c in range(len(robot.contact_frames)):
        r = np.flatnonzero(rows & (stance == c))
        if r.size:
            tau_f[r], delta[r] = single_support_friction_rnea(
                robot, c, kin.q[r], kin.qd[r], kin.qdd[r], kin.tau[r], None if kin.base is None else kin.base[r],
                progress, with_delta)
    return tau_f, delta


def _diag(value, n: int) -> np.ndarray:
    d = np.broadcast_to(np.asarray(value, dtype=float), (n,))
    return np.diag(d)


def regularised_least_squares(Mmod_inv: np.ndarray, delta_qdd: np.ndarray, weight, regularization) -> np.ndarray:
    """Solve (6.1) for a stack of samples.

    Args:
        Mmod_inv: (N, n, n) operators ``A``.
        delta_qdd: (N, n) acceleration differences.
        weight: diagonal of W (scalar or (n,)).
        regularization: diagonal of Lambda (scalar or (n,)).

    Returns:
        tau_f (N, n) minimising ``1/2 |Delta - A tau_f|_W^2 + 1/2 tau_f^T Lambda tau_f``.
    """
    n = delta_qdd.shape[1]
    W, L = _diag(weight, n), _diag(regularization, n)
    At = np.swapaxes(Mmod_inv, 1, 2)
    lhs = At @ W @ Mmod_inv + L
    rhs = (At @ W @ delta_qdd[..., None])
    return np.linalg.solve(lhs, rhs)[..., 0]


def estimate_friction(robot: Robot, kin: MeasuredKinematics, options: EstimateOptions = EstimateOptions(),
                      progress: Progress | None = None, require_single_support: bool = True,
                      gaps: tuple[bool, bool] = (False, False)) -> FrictionEstimate:
    """Estimate the friction torque of every torque-controlled joint at every sample.

    Args:
        robot: the robot.
        kin: measured kinematics (:func:`wbfriction.signals.kinematics.measure`).
        options: :class:`EstimateOptions`.
        progress: optional callable receiving numbers of samples processed.
        require_single_support: refuse kinematics without a single-support sample (off for
            a stretch of a longer log, which is checked as a whole).
        gaps: a time gap before the first and after the last sample (a segment of a log cut at
            its gaps): the lift-off and touch-down margins apply there (:func:`~wbfriction.signals.phases.segment`).

    Returns:
        :class:`FrictionEstimate`.

    Raises:
        InputError: no single-support sample, unknown method or mask.
    """
    if options.method not in METHODS:
        raise InputError(f"unknown method '{options.method}': choose one of {', '.join(METHODS)}")
    n, n_tc = len(kin.time), len(robot.torque_controlled)
    phases: Phases = segment(kin.time, kin.contact, options.lift_off_skip, options.touch_down_skip, gaps)
    assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
    usable = kin.valid & (phases.n_contacts > 0)
    with_wrenches = options.wrenches and kin.wrench is not None
    if require_single_support and not with_wrenches and not np.any(usable & phases.single):
        raise no_single_support(robot, kin.metadata.get('source', 'the log'))
    cond = np.full(n, np.nan) if options.condition_number else None
    tc = robot.tc_index
    ss = usable & phases.single
    # the KKT route (one Pinocchio call per sample) serves double support, and single
    # support when asked for it or for the condition number
    kkt_in_single = options.method == "kkt" or options.condition_number
    need_kkt = usable & (phases.double | (phases.single & kkt_in_single))
    if options.method == "rnea":
        rnea_progress = None if kkt_in_single else progress  # counted by the KKT pass then
        tau_f, delta = single_support(robot, kin, ss, phases.stance, rnea_progress, options.acceleration_difference)
    else:
        tau_f, delta = np.full((n, n_tc), np.nan), np.full((n, n_tc), np.nan)
    rows = np.flatnonzero(need_kkt)
    for start in range(0, rows.size, CHUNK):
        r = rows[start:start + CHUNK]
        dyn = constrained_dynamics(robot, kin.q[r], kin.qd[r], kin.qdd[r], kin.tau[r], kin.contact[r],
                                   None if kin.base is None else kin.base[r], with_Mmod_inv=True, progress=progress)
        assert dyn.Mmod_inv is not None  # with_Mmod_inv
        d = kin.qdd[r][:, tc] - dyn.qdd_est[:, tc]
        is_ss = phases.single[r]
        if options.method == "kkt" and np.any(is_ss):
            tau_f[r[is_ss]] = np.linalg.solve(dyn.Mmod_inv[is_ss], d[is_ss][..., None])[..., 0]
            delta[r[is_ss]] = d[is_ss]
        if np.any(~is_ss):
            tau_f[r[~is_ss]] = regularised_least_squares(dyn.Mmod_inv[~is_ss], d[~is_ss],
                                                         options.ds_weight, options.ds_regularization)
            delta[r[~is_ss]] = d[~is_ss]
        if cond is not None:
            cond[r] = np.linalg.cond(dyn.Mmod_inv)
    valid = joint_mask(phases, robot.limb_mask, options.mask) & usable[:, None] & np.isfinite(tau_f)
    unique = ss.copy()
    route = np.where(np.any(np.isfinite(tau_f), axis=1), "contact", "none").astype("<U7")
    disagreement = None
    if with_wrenches:  # every joint, every phase
        rows = kin.valid
        if options.diff != "true":  # not across a touch-down: its impact is smeared by the differentiation
            left_out = straddling(kin.contact) | impacts(robot, kin)
            rows = rows & ~left_out
            # nor the rigid-contact route's estimate there: the same smearing, and a sole touching the ground
            # before its flag rises (a light first touch, up to 0.1 s early on MuJoCo) is a force that route
            # does not know of (the swing leg's friction off by the touch's joint torques: N·m)
            valid[left_out] = False
        tau_m, done = wrench_route(robot, kin, rows)
        valid[done] = np.isfinite(tau_m[done])
        disagreement = _measured(tau_f, delta, unique, route, tau_m, done, "wrench")
    elif measured_base(kin) != "contact":  # every joint in single support; the mask stays
        tau_m, done = base_route(robot, kin, usable & phases.single)
        valid[done] = (joint_mask(phases, robot.limb_mask, options.mask) & np.isfinite(tau_m))[done]
        disagreement = _measured(tau_f, delta, unique, route, tau_m, done, "base")
    metadata = dict(kin.metadata)
    metadata["estimate_options"] = asdict(options)
    metadata["joint_labels"] = {j: robot.label(j) for j in robot.torque_controlled}
    return FrictionEstimate(
        joints=robot.torque_controlled, time=kin.time, qd=kin.qd[:, tc], tau_f=tau_f, valid=valid,
        phase=phases.labels(), unique=unique, contact=kin.contact, contact_frames=robot.contact_frames,
        qdd=kin.qdd[:, tc], delta_qdd=delta, cond=cond, tau_f_true=kin.tau_f_true, metadata=metadata,
        smoother=kin.smoother, route=route, disagreement=disagreement)


def _measured(tau_f: np.ndarray, delta: np.ndarray, unique: np.ndarray, route: np.ndarray, tau_m: np.ndarray,
              done: np.ndarray, name: str) -> np.ndarray:
    """Put a measured route's friction ``tau_m`` in place of the rigid-contact route's on the rows ``done``
    (its acceleration difference is not computed: NaN); return their disagreement where both estimated a
    single-support sample (:attr:`FrictionEstimate.disagreement`)."""
    both = done & unique  # unique so far: the rigid route's single support
    disagreement = np.full_like(tau_f, np.nan)
    disagreement[both] = tau_m[both] - tau_f[both]
    tau_f[done], delta[done], unique[done], route[done] = tau_m[done], np.nan, True, name
    return disagreement


def companion_scheme(diff: Diff) -> Scheme:
    """The scheme of the other kind (Fig. 7.4): ``central`` for a filtering scheme,
    ``savgol`` for the others."""
    return "central" if diff in FILTERING_SCHEMES else "savgol"


def estimate_log(robot: Robot, log: Log, options: EstimateOptions = EstimateOptions(), progress: Progress | None = None,
                 companion: bool = False, require_single_support: bool = True) -> FrictionEstimate:
    """Differentiate a log (:func:`~wbfriction.signals.kinematics.measure`) and estimate its friction.

    A log with time gaps (:attr:`~wbfriction.logs.log.Log.segments`) is estimated segment by
    segment, never differentiated or filtered across a gap; a segment too short for the
    scheme gives NaN, invalid rows.

    With ``companion``, the single-support acceleration difference is also computed through
    :func:`companion_scheme` (:attr:`FrictionEstimate.companion_delta_qdd`; one more
    inverse-dynamics pass over the single-support samples).

    The route (``options.route``, :func:`~wbfriction.friction.route.resolve_route`) and the differentiation
    (:func:`resolve_differentiation`) are chosen once for the log, and recorded in the metadata (``route``,
    ``differentiation``) with the noise the fit reads (``noise``, :func:`~wbfriction.friction.noise.noise_record`).

    Raises:
        InputError: what :func:`~wbfriction.signals.kinematics.measure` and :func:`estimate_friction`
            raise (no segment can be estimated; with ``require_single_support``, no
            single-support sample in the whole log).
    """
    given = options
    options, choice = resolve_differentiation(options, log)
    options, decision = resolve_route(options, log, choice=choice)
    check_windows(given, options, log.segments, len(log.time), log.dt, log.source)
    est = estimate_resolved(robot, log, options, progress, companion, require_single_support)
    a, b = longest_segment(log.segments, len(log.time))
    record = noise_record(robot, log.q[a:b], log.dt, options)
    unmeasured = unmeasured_noise(record, b - a, options)
    for e in (est, est.route_check):
        if e is None:
            continue
        if unmeasured:
            e.metadata["noise_unmeasured"] = unmeasured
        if choice is not None:
            e.metadata["differentiation"] = choice.to_dict()
        if decision is not None:
            e.metadata["route"] = decision.to_dict()
        if record is not None:
            e.metadata["noise"] = record
    return est


def resolve_differentiation(options: EstimateOptions, source: Log | np.ndarray | None,
                            dt: float | None = None) -> tuple[EstimateOptions, DiffChoice | None]:
    """``options`` with ``diff="auto"`` replaced by the scheme and filter chosen from the positions
    (:func:`~wbfriction.signals.choice.choose_differentiation`), and that choice; other options as
    they are, and None.

    Args:
        source: the log, or positions (N, n_act) [rad] sampled every ``dt`` [s] (the first rows
            of a long log); None: nothing to choose from (central differences, no choice).

    A log too short to measure its noise gets central differences, and a choice that says why.
    """
    if options.diff != "auto":
        return options, None
    if source is None:
        return replace(options, diff="central"), None
    try:
        choice = choose_differentiation(source, dt, target=options.noise_target)
    except InputError as exc:  # too short a log to measure its noise: say so, differentiate it plainly
        choice = DiffChoice.fallback(f"central differences: {exc}")
    return replace(options, diff=choice.scheme, filtering=choice.filtering), choice


def unmeasured_noise(record: dict | None, longest: int, options: EstimateOptions) -> str:
    """Why a fit of this estimate cannot be called ``ok`` (the metadata's ``noise_unmeasured``,
    :attr:`~wbfriction.fit.result.FitResult.unmeasured`): the positions' noise not measured (``record`` None) on
    the ``longest`` samples between time gaps, so no Cramér-Rao bound says what the data allow; "" when measured,
    or for the simulators' true derivatives (no noise)."""
    if record is not None or options.diff == "true":
        return ""
    return (f"the positions' noise could not be measured: the longest stretch without a time gap has {longest} "
            "samples (no Cramér-Rao bound)")


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


def estimate_resolved(robot: Robot, log: Log, options: EstimateOptions, progress: Progress | None = None,
                      companion: bool = False, require_single_support: bool = True) -> FrictionEstimate:
    """:func:`estimate_log` with ``options`` already resolved (:func:`resolve_differentiation`,
    :func:`~wbfriction.friction.route.resolve_route`): each of the log's segments by its route and the other, nothing
    chosen or measured (a chunk of a long log, whose choices are the whole log's).

    Raises:
        InputError: options not resolved; what the routes raise.
    """
    parts = log.parts()
    if len(parts) == 1:
        return _estimate_segment(robot, log, options, progress, companion, require_single_support)
    done: list[FrictionEstimate | None] = []
    first_error: InputError | None = None
    for k, part in enumerate(parts):
        try:
            done.append(_estimate_segment(robot, part, options, progress, companion, False,
                                          (k > 0, k < len(parts) - 1)))
        except InputError as exc:
            first_error = first_error or exc
            done.append(None)
    if all(d is None for d in done):
        assert first_error is not None  # every part raised one
        raise first_error
    template = next(d for d in done if d is not None)
    est = concat_estimates([d if d is not None else _blank(template, part) for d, part in zip(done, parts)])
    if require_single_support and not est.unique.any():
        raise no_single_support(robot, log.source)
    return est


def _estimate_segment(robot: Robot, log: Log, options: EstimateOptions, progress, companion: bool,
                      require_single_support: bool, gaps: tuple[bool, bool] = (False, False)) -> FrictionEstimate:
    """One segment by ``options.route``, and by the other route as its check (``options.check_route``).

    The contact margins at a gap (``gaps``) apply only where there are contacts: a fixed base is always
    welded, nothing lifts off or touches down in a gap."""
    if not robot.floating_base:
        gaps = (False, False)
    if options.route == "auto":
        raise InputError("route 'auto' is resolved once per log (resolve_route), not per segment")
    if options.route == "momentum":
        est = momentum_estimate(robot, log, options, progress, require_single_support, gaps)
    else:
        est = _acceleration_segment(robot, log, options, progress, companion, require_single_support, gaps)
    est.q, est.tau, est.temperature = log.q[:, robot.tc_index], log.tau, log.temperature  # the terms' signals
    if options.check_route:
        other: Route = "acceleration" if options.route == "momentum" else "momentum"
        est.route_check = _estimate_segment(robot, log, replace(options, route=other, check_route=False), None,
                                            False, False, gaps)
    return est


def _acceleration_segment(robot: Robot, log: Log, options: EstimateOptions, progress, companion: bool,
                          require_single_support: bool, gaps: tuple[bool, bool] = (False, False)) -> FrictionEstimate:
    if options.diff == "auto":
        raise InputError("diff 'auto' is resolved once per log (resolve_differentiation), not per segment")
    has_wrench, base_motion = log_base_motion(robot, log, options.base_motion, options.wrenches)
    kin = measure(log, options.diff, compensate_delay=options.compensate_delay,
                  torque_alignment=options.torque_alignment, filtering=options.filtering, velocity=options.velocity,
                  base_motion=base_motion == "logged", imu=base_motion == "imu")
    kin.metadata.update(robot=robot.name, source=log.source)
    kin.metadata["base_motion"] = {"base": base_motion, "wrenches": has_wrench}
    est = estimate_friction(robot, kin, options, progress, require_single_support, gaps)
    if companion:
        other = companion_scheme(options.diff)
        kin2 = measure(log, other, compensate_delay=options.compensate_delay,
                       torque_alignment=options.torque_alignment, filtering=options.filtering)
        phases = segment(kin2.time, kin2.contact, options.lift_off_skip, options.touch_down_skip, gaps)
        _, est.companion_delta_qdd = single_support(robot, kin2, kin2.valid & phases.single, phases.stance)
        est.companion_diff = other
    return est


def _blank(template: FrictionEstimate, log: Log | FrictionEstimate) -> FrictionEstimate:
    """An estimate of the rows of ``log`` (a log, or an estimate of it) with nothing estimated (NaN, invalid), shaped
    like ``template``."""
    n = len(log.time)
    nan = lambda x: None if x is None else np.full((n, *np.shape(x)[1:]), np.nan)  # noqa: E731
    return FrictionEstimate(
        joints=template.joints, time=log.time, qd=cast(np.ndarray, nan(template.qd)),
        tau_f=cast(np.ndarray, nan(template.tau_f)),
        valid=np.zeros((n, len(template.joints)), dtype=bool), phase=segment(log.time, log.contact).labels(),
        unique=np.zeros(n, dtype=bool), contact=log.contact, contact_frames=template.contact_frames,
        qdd=nan(template.qdd), delta_qdd=nan(template.delta_qdd), cond=nan(template.cond),
        tau_f_true=log.tau_f_true, metadata=template.metadata, smoother=template.smoother,
        companion_delta_qdd=nan(template.companion_delta_qdd), companion_diff=template.companion_diff,
        disagreement=nan(template.disagreement),
        route=None if template.route is None else np.full(n, "none", dtype=template.route.dtype),
        route_check=None if template.route_check is None else _blank(template.route_check, log))


def concat_estimates(parts: list[FrictionEstimate]) -> FrictionEstimate:
    """Estimates of consecutive stretches of one log as one (arrays stacked along time; names and
    metadata of the first; the smoothers joined, :func:`~wbfriction.signals.kinematics.joined_smoother`)."""
    first = parts[0]
    out: dict[str, Any] = {}  # field values by name
    for f in fields(FrictionEstimate):
        values = [getattr(p, f.name) for p in parts]
        arrays = [v for v in values if isinstance(v, np.ndarray)]
        if arrays:  # a part without the array (e.g. no companion) gets NaN rows
            out[f.name] = np.concatenate([v if v is not None else np.full((len(p.time), *arrays[0].shape[1:]), np.nan)
                                          for v, p in zip(values, parts)])
        else:
            out[f.name] = getattr(first, f.name)
    out["smoother"] = joined_smoother([p.smoother for p in parts], [len(p.time) for p in parts])
    checks = [p.route_check for p in parts]
    template = next((c for c in checks if c is not None), None)
    out["route_check"] = None if template is None else concat_estimates(
        [c if c is not None else _blank(template, p) for c, p in zip(checks, parts)])
    return FrictionEstimate(**out)
