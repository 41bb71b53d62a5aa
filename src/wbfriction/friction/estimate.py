"""Joint friction estimation from measured kinematics (thesis 5.11-5.13, 6.1).

The acceleration difference of the torque-controlled joints is caused by friction:

.. math:: \\Delta\\ddot q_{tc} = \\ddot q_{msr,tc} - \\ddot q_{est,tc} = M_{mod}^{-1} \\tau_f. \\qquad (5.12)

* **Single support** (one contact): ``M_mod^{-1}`` is invertible and
  ``tau_f = M_mod Delta qdd_tc`` (5.13) is exact. The default route computes it with one
  recursive Newton-Euler pass on the robot re-rooted at the stance foot
  (:mod:`wbfriction.model.rerooted`), batched in C++ (``pin.rneaInParallel``); ``method="kkt"``
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

from wbfriction.exceptions import InputError
from wbfriction.friction.decision import decide_log, longest_stretch
from wbfriction.friction.decision import resolve_differentiation as resolve_differentiation  # importable from here
from wbfriction.friction.estimated import FrictionEstimate, no_single_support
from wbfriction.friction.measured import (
    base_route,
    impacts,
    log_base_motion,
    measured_base,
    wrench_route,
)
from wbfriction.friction.momentum import momentum_estimate
from wbfriction.friction.options import METHODS, EstimateOptions, Route
from wbfriction.friction.point_contacts import point_contact_estimate
from wbfriction.logs.log import Log
from wbfriction.logs.torque import torque_record
from wbfriction.model.dynamics import check_contact_patterns, constrained_dynamics
from wbfriction.model.rerooted import stance_frame_pose, stance_model
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.signals.kinematics import MeasuredKinematics, joined_smoother, measure, straddling
from wbfriction.signals.options import FILTERING_SCHEMES, Diff, Scheme
from wbfriction.signals.phase_window import log_swings
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
        (:meth:`~wbfriction.model.rerooted.StanceModel.acceleration_difference`).
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
    if robot.partial_contacts:  # where the contacts leave the friction determined, sample by sample
        return point_contact_estimate(robot, kin, options, progress, require_single_support)
    phases: Phases = segment(kin.time, kin.contact, options.lift_off_skip, options.touch_down_skip, gaps)
    assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
    usable = kin.valid & (phases.n_contacts > 0)
    with_wrenches = options.wrenches and kin.wrench is not None
    if require_single_support and not with_wrenches and not np.any(usable & phases.single):
        raise no_single_support(robot, kin.metadata.get('source', 'the log'))
    tau_f, delta, cond = contact_route(robot, kin, phases, usable, options, progress)
    valid = joint_mask(phases, robot.limb_mask, options.mask) & usable[:, None] & np.isfinite(tau_f)
    unique = usable & phases.single
    route = np.where(np.any(np.isfinite(tau_f), axis=1), "contact", "none").astype("<U7")
    disagreement = measured_routes(robot, kin, phases, usable, options, tau_f, delta, valid, unique, route)
    metadata = dict(kin.metadata)
    metadata["estimate_options"] = asdict(options)
    metadata["joint_labels"] = {j: robot.label(j) for j in robot.torque_controlled}
    tc = robot.tc_index
    return FrictionEstimate(
        joints=robot.torque_controlled, time=kin.time, qd=kin.qd[:, tc], tau_f=tau_f, valid=valid,
        phase=phases.labels(), unique=unique, contact=kin.contact, contact_frames=robot.contact_frames,
        qdd=kin.qdd[:, tc], delta_qdd=delta, cond=cond, tau_f_true=kin.tau_f_true, metadata=metadata,
        smoother=kin.smoother, route=route, disagreement=disagreement)


def contact_route(robot: Robot, kin: MeasuredKinematics, phases: Phases, usable: np.ndarray,
                  options: EstimateOptions, progress: Progress | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """The rigid-contact route (thesis ch. 5) on the ``usable`` rows (N,) of ``kin``: single support by
    ``options.method`` (one RNEA pass on the stance-rooted tree, :func:`single_support`, or the KKT system), double
    support by the regularised least squares (6.1) (:func:`kkt_rows`).

    Returns:
        ``(tau_f, delta_qdd, cond)``: the friction (N, n_tc) [N·m] and the acceleration difference (5.12)
        (N, n_tc) [rad/s^2], NaN where not estimated; ``cond(M_mod^-1)`` (N,) where the KKT system was formed
        (``options.condition_number``), else None.
    """
    n, n_tc = len(kin.time), len(robot.torque_controlled)
    cond = np.full(n, np.nan) if options.condition_number else None
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
    kkt_rows(robot, kin, phases, np.flatnonzero(need_kkt), options, tau_f, delta, cond, progress)
    return tau_f, delta, cond


def kkt_rows(robot: Robot, kin: MeasuredKinematics, phases: Phases, rows: np.ndarray, options: EstimateOptions,
             tau_f: np.ndarray, delta: np.ndarray, cond: np.ndarray | None, progress: Progress | None = None) -> None:
    """The KKT system (5.10)-(5.13) on the rows ``rows`` of ``kin``, :data:`CHUNK` at a time, written into
    ``tau_f`` and ``delta`` (N, n_tc) and, if given, ``cond`` (N,): single support solved exactly (``method="kkt"``),
    double support by the regularised least squares (6.1)."""
    tc = robot.tc_index
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


def measured_routes(robot: Robot, kin: MeasuredKinematics, phases: Phases, usable: np.ndarray,
                    options: EstimateOptions, tau_f: np.ndarray, delta: np.ndarray, valid: np.ndarray,
                    unique: np.ndarray, route: np.ndarray) -> np.ndarray | None:
    """The measured routes in place of the rigid-contact route's estimate, where they apply (arrays updated in
    place): the force-torque sensors' wrenches (``options.wrenches``: every joint in every phase, but across a
    touch-down), else a measured base motion (every joint in single support; the mask stays).

    Returns:
        The disagreement of the measured route with the rigid-contact route (N, n_tc) [N·m]
        (:attr:`FrictionEstimate.disagreement`), or None without a measured route.
    """
    if options.wrenches and kin.wrench is not None:  # every joint, every phase
        assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
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
        return _measured(tau_f, delta, unique, route, tau_m, done, "wrench")
    if measured_base(kin) != "contact":  # every joint in single support; the mask stays
        tau_m, done = base_route(robot, kin, usable & phases.single)
        valid[done] = (joint_mask(phases, robot.limb_mask, options.mask) & np.isfinite(tau_m))[done]
        return _measured(tau_f, delta, unique, route, tau_m, done, "base")
    return None


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

    The route (``options.route``) and the differentiation are chosen once for the log
    (:func:`~wbfriction.friction.decision.decide_log`, its noise measured on its longest stretch between time gaps,
    the route's windows bounded by its rows), and recorded in the metadata (``route``, ``differentiation``) with
    the noise the fit reads (``noise``, :func:`~wbfriction.friction.noise.noise_record`).

    Raises:
        InputError: contacts on the ground together that the robot's contact models make redundant
            (:func:`~wbfriction.model.dynamics.check_contact_patterns`: a sole on a point foot); what
            :func:`~wbfriction.signals.kinematics.measure` and :func:`estimate_friction` raise (no segment can be
            estimated; with ``require_single_support``, no single-support sample in the whole log).
    """
    check_contact_patterns(robot, log.contact, log.source)  # before any work: the KKT route's matrix singular
    positions, changes = longest_stretch(log)
    swings = log_swings(log.contact, robot.contact_frames, log.dt, log.segments,
                        (options.lift_off_skip, options.touch_down_skip)) if robot.floating_base else None
    decision = decide_log(robot, options, positions, log.dt, segments=log.segments, rows=len(log.time),
                          source=log.source, route_rows=len(log.time),  # the whole log's rows: module docstring
                          changes=changes, swings=swings,
                          swings_only=not robot.ft_sensors and log.foot_force is None)
    est = estimate_resolved(robot, log, decision.options, progress, companion, require_single_support)
    for e in (est, est.route_check):
        if e is not None:
            e.metadata.update(decision.metadata())
    return est


def estimate_resolved(robot: Robot, log: Log, options: EstimateOptions, progress: Progress | None = None,
                      companion: bool = False, require_single_support: bool = True) -> FrictionEstimate:
    """:func:`estimate_log` with ``options`` already resolved (:func:`~wbfriction.friction.decision.decide_log`):
    each of the log's segments by its route and the other, nothing chosen or measured (a chunk of a long log, whose
    choices are the whole log's).

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
    # the terms' signals; a continuous joint's angle unwrapped from its window's first row, written in (-pi, pi]
    est.q, est.tau, est.temperature = robot.layout.principal(log.q)[:, robot.tc_index], log.tau, log.temperature
    est.metadata["torque_source"] = torque_record(robot, log.torque_source, log.setpoints)  # every output says it
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
