"""The momentum route: friction from the generalized momentum, positions differentiated once (issue 38).

The acceleration route (:mod:`wbfriction.friction.estimate`, thesis 5.10-5.13) differentiates the
positions twice; on a noisy log its accelerations need windows of 150-210 ms, and the fit must undo that
smoothing. The momentum route needs velocities only. On a tree whose every external wrench is known or acts
on its root, the generalized momentum ``p = M(q) v`` obeys, row by row,

.. math::

    \\dot p = \\tau + \\tau_f + C(q, v)^T v - g(q) + \\sum_e J_e^T f_e
    \\qquad (\\dot M = C + C^T)

(:mod:`wbfriction.model.momentum`), so over each step ``[t_i, t_i+1]`` between two samples the friction's
impulse is

.. math::

    F_i = \\int_{t_i}^{t_{i+1}} \\tau_f\\, dt = p_{i+1} - p_i - \\int_{t_i}^{t_{i+1}} (\\tau + e)\\, dt
          - \\frac{b_i + b_{i+1}}{2} \\Delta t_i, \\qquad b = C^T v - g, \\quad e = \\sum_e J_e^T f_e ,

the torque's integral (and the measured wrenches' and foot forces', read as the torques are: the log-format
reference's convention) exact for a torque held over the step (``zoh``: ``tau_i Delta t_i``) and the trapezoid for
one sampled at the instants (``sample``); a log whose foot forces fit another period better is named
(:mod:`wbfriction.friction.force_sampling`, the metadata ``foot_force_sampling``); ``b``, a
smooth function of the state, by the trapezoid (an error ``dt^2 / 12`` times the momentum's third derivative:
below 1e-8 N·m on a slow arm trajectory sampled at 10 kHz, ``tests/friction/test_momentum.py``). No
acceleration anywhere: the Coulomb step is smoothed only as much as the velocity needs. The per-sample
estimate is the impulses' weighted mean over a zero-phase Hann window of ``2m`` steps
(:class:`~wbfriction.signals.window.MomentumWindow`: bandwidth its -3 dB frequency, lag zero): the momentum
observer's residual (De Luca and Mattone, ICRA 2003), taken forwards and backwards as an offline log allows.
The fit compares the model through the same window (parallel filtering, :mod:`wbfriction.fit`), at
the same once-differentiated velocities.

**Which tree** (the closures of issue 23, each where its equations hold):

* ``contact`` (rigid contacts, the thesis's premise): in single support, the tree rooted at the stance
  sole, welded flat (:meth:`~wbfriction.model.rerooted.StanceModel.momentum`); its contact wrench acts on the
  root only, so every joint row holds without it. Windows never span a contact change.
* ``wrench`` (force-torque sensors): the robot above its sensors, free-floating, every external wrench
  measured (:func:`~wbfriction.model.measured_dynamics.measured_momentum`): every joint, every phase. The
  base twist (its linear part too: a momentum is not the same in every inertial frame) comes from the
  logged base pose differentiated once, its angular part from the IMU's gyro where the base motion is
  ``imu``; without a logged pose, from the stance feet (not sliding, not turning). Windows leave out each
  touch-down's impact and every contact change, as the acceleration route does.
* ``base`` (point feet, :attr:`~wbfriction.model.robot.Robot.contact_kinds`): the free-floating robot, its base
  twist measured as for ``wrench``; a joint's row holds no unknown force while no foot is down on its limb (a swinging
  leg, :func:`~wbfriction.model.determination.free_rows`) or while its feet's three force components are measured
  (their ``J^T f`` is ``e``). The stance legs that only the base's rows determine (one foot down) are left to the
  acceleration route (:mod:`wbfriction.friction.point_contacts`). Windows never span a contact change.
* **Where the equations do not allow it.** In double support without wrenches the second foot's wrench is
  unknown and enters the joint rows: projecting it out (``P J^T = 0``) leaves combinations of the joints'
  frictions, not each joint's, as (6.1) does for the accelerations; that phase is left out. A measured base
  motion without wrenches (``base``) is taken as the rigid contact: a stance foot that rocks would need its
  twist in an inertial frame, which a state estimator that assumes the contact does not give.

Sign convention: ``tau_f`` is the torque friction exerts on the joint (:mod:`wbfriction.friction.models`).
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.estimated import FrictionEstimate, no_single_support
from wbfriction.friction.force_sampling import check_force_sampling
from wbfriction.friction.measured import impacts, log_base_motion
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import Log
from wbfriction.model.determination import Determination, determination, foot_force_torques, free_rows
from wbfriction.model.dynamics import floating_base_state
from wbfriction.model.imu import base_motion_from_imu
from wbfriction.model.measured_dynamics import measured_momentum
from wbfriction.model.momentum import momentum_and_drift
from wbfriction.model.rerooted import stance_frame_pose, stance_model
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.signals.kinematics import MeasuredKinematics, measure, straddling, time_base
from wbfriction.signals.options import FilterOptions
from wbfriction.signals.phases import joint_mask, segment, settled
from wbfriction.signals.window import MomentumWindow

VELOCITY_ORDER = 4
"""Polynomial order of the momentum route's Savitzky-Golay velocity."""


def velocity_filter(options: EstimateOptions) -> FilterOptions:
    """The Savitzky-Golay filter of the momentum route's velocities (its window resolved).

    Raises:
        InputError: a window not chosen yet (``None``: :func:`~wbfriction.friction.route.resolve_route` first).
    """
    window = options.momentum.velocity_window
    if window is None:
        raise InputError("the momentum route's velocity window is chosen once per log (resolve_route), "
                         "not per segment")
    return FilterOptions(window=window, poly_order=VELOCITY_ORDER, weights="uniform")


def momentum_window(options: EstimateOptions, log: Log) -> MomentumWindow:
    """The route's window on ``log``'s time base (:func:`~wbfriction.signals.kinematics.time_base`).

    Raises:
        InputError: a window not chosen yet.
    """
    if options.momentum.window is None:
        raise InputError("the momentum route's window is chosen once per log (resolve_route), not per segment")
    return MomentumWindow(options.momentum.window // 2, log.dt, time_base(log))


def _filter_rows(kin: MeasuredKinematics, log: Log) -> np.ndarray:
    """(N,) rows whose velocity is the filter's: its window inside the log and clear of every contact change
    (elsewhere the kinematics fill in raw differences, which the momenta must not see), and whose contact flags are
    sure (:attr:`Log.unsure <wbfriction.logs.log.Log.unsure>`: inferred without confidence)."""
    assert kin.smoother is not None
    blank = np.where(straddling(log.contact), np.nan, 0.0)[:, None]
    rows = np.isfinite(kin.smoother(blank))[:, 0]
    return rows if log.unsure is None else rows & ~log.unsure


def _base_twist(robot: Robot, kin: MeasuredKinematics, log: Log, base_motion: str, rows: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Configurations (len(rows), nq), velocities (len(rows), nv) and whether each is known (len(rows),) for the
    wrench closure (module docstring): the base pose as logged (else a stance sole flat at the origin), its twist
    from the logged pose differentiated once (angular part from the IMU with ``imu``), else from the stance feet."""
    n_rows = rows.size
    model = robot.model
    v = np.zeros((n_rows, model.nv))
    v[:, robot.act_v_index] = kin.qd[rows]
    known = np.ones(n_rows, dtype=bool)
    if kin.base_qd is not None and log.base is not None:
        q = robot.configuration(kin.q[rows], log.base[rows])
        v[:, :6] = kin.base_qd[rows]
    else:
        data = model.createData()
        q = np.empty((n_rows, model.nq))
        for i, k in enumerate(rows):
            active = np.flatnonzero(kin.contact[k]).tolist()
            if not active:
                known[i] = False
                q[i] = robot.configuration(kin.q[k], None if log.base is None else log.base[k])
                continue
            q[i], v[i], _ = floating_base_state(robot, data, kin.q[k], kin.qd[k], active,
                                                None if log.base is None else log.base[k])
    if base_motion == "imu" and kin.imu is not None and robot.imu is not None:
        zeros = np.zeros((n_rows, 3))
        angular, _ = base_motion_from_imu(model, robot.imu, q, robot.act_v_index, kin.qd[rows],
                                          np.zeros_like(kin.qd[rows]), kin.imu[rows, :3], zeros, zeros)
        v[:, 3:6] = angular[:, 3:]
    known &= np.all(np.isfinite(v), axis=1)
    return q, v, known


def momentum_estimate(robot: Robot, log: Log, options: EstimateOptions, progress: Progress | None = None,
                      require_single_support: bool = True, gaps: tuple[bool, bool] = (False, False)
                      ) -> FrictionEstimate:
    """The friction of every torque-controlled joint by the momentum route (module docstring), on one segment
    of a log (no time gap inside).

    Args:
        robot: the robot; log: the segment.
        options: the estimate's options, the momentum route's windows resolved
            (:func:`~wbfriction.friction.route.resolve_route`).
        progress: optional callable receiving numbers of samples done.
        require_single_support: refuse a log without a sample the route can estimate.
        gaps: a time gap before the first and after the last sample (:func:`~wbfriction.signals.phases.segment`).

    Returns:
        :class:`~wbfriction.friction.estimated.FrictionEstimate`: ``tau_f`` the windowed estimate [N·m],
        ``qd`` the once-differentiated velocities [rad/s], ``smoother`` the window; no accelerations.

    Raises:
        InputError: what :func:`~wbfriction.signals.kinematics.measure` raises, windows not resolved, no sample
            the route can estimate (with ``require_single_support``), a robot on point feet without its base pose.
    """
    window = momentum_window(options, log)
    has_wrench, base_motion = log_base_motion(robot, log, options.base_motion, options.wrenches)
    floating = has_wrench or robot.partial_contacts  # the free-floating tree, its base twist measured
    kin = measure(log, "savgol", compensate_delay=options.compensate_delay, torque_alignment=options.torque_alignment,
                  filtering=velocity_filter(options), velocity=options.velocity,
                  base_motion=floating and log.base is not None, imu=floating and base_motion == "imu")
    n, tc, n_c = len(log.time), robot.tc_index, len(robot.contact_frames)
    phases = segment(kin.time, kin.contact, options.lift_off_skip, options.touch_down_skip, gaps)
    rows_ok = _filter_rows(kin, log) & np.all(np.isfinite(kin.q), axis=1) & np.all(np.isfinite(kin.qd), axis=1)
    # each row's closure: -1 none, c < n_c the rigid stance on contact c, n_c the wrenches, n_c + 1 the point feet
    closure = np.full(n, -1)
    p, b = np.full((n, robot.n_act), np.nan), np.full((n, robot.n_act), np.nan)
    e = np.zeros((n, robot.n_act))  # the sensors' wrenches' joint torques, read as the torques are
    mask = np.zeros((n, len(tc)), dtype=bool)
    determined, cond = None, None  # point feet: the rank decision on the rows taken, for the shares
    if robot.partial_contacts:
        r, mask_r, det = _point_feet(robot, kin, log, options, base_motion, rows_ok, (p, b, e), progress)
        closure[r], mask[r], determined, cond = n_c + 1, mask_r, np.zeros((n, len(tc)), dtype=bool), np.full(n, np.nan)
        determined[r], cond[r] = det.determined[:, tc], det.cond
    elif has_wrench:
        assert log.wrench is not None
        rows = rows_ok & np.all(np.isfinite(log.wrench.reshape(n, -1)), axis=1) & ~straddling(log.contact)
        rows &= ~impacts(robot, kin)
        r = np.flatnonzero(rows)
        q, v, known = _base_twist(robot, kin, log, base_motion, r)
        r, q, v = r[known], q[known], v[known]
        p[r], b[r], e[r] = measured_momentum(robot, q, v, log.wrench[r], progress)
        closure[r] = n_c
        mask[r] = True
    else:
        single = rows_ok & phases.single
        per_joint = joint_mask(phases, robot.limb_mask, options.mask)
        for c in range(n_c):
            r = np.flatnonzero(single & (phases.stance == c))
            if r.size == 0:
                continue
            stance = stance_model(robot, c)
            pose = None if kin.base is None else stance_frame_pose(robot, stance, kin.q[r], kin.base[r])
            p[r], b[r] = stance.momentum(kin.q[r], kin.qd[r], pose, progress)
            closure[r] = c
            mask[r] = per_joint[r]
    if require_single_support and not np.any(closure >= 0):
        raise no_single_support(robot, log.source)
    impulses = step_impulses(p[:, tc], b[:, tc], log.tau + e[:, tc], window.step_durations(n),
                             _alignment(options, log), closure)
    tau_f = window.over_steps(impulses)
    valid = _whole_windows(mask, window.half_width) & np.isfinite(tau_f)
    route = np.select([closure == n_c, closure == n_c + 1, closure >= 0], ["wrench", "base", "contact"], "none")  # <U7
    metadata = {**kin.metadata, "robot": robot.name, "source": log.source,
                "base_motion": {"base": base_motion, "wrenches": has_wrench}, "estimate_options": asdict(options),
                "joint_labels": {j: robot.label(j) for j in robot.torque_controlled},
                **_force_sampling(robot, log, options, kin.qd, (p, b, e), valid, window, closure),
                "momentum": {"velocity_window": velocity_filter(options).window, "window": window.length,
                             "window_s": window.length * log.dt, "cutoff_hz": window.cutoff, "lag_s": 0.0}}
    return FrictionEstimate(
        joints=robot.torque_controlled, time=kin.time, qd=kin.qd[:, tc], tau_f=tau_f, valid=valid,
        phase=phases.labels(), unique=closure >= 0, contact=kin.contact, contact_frames=robot.contact_frames,
        tau_f_true=kin.tau_f_true, metadata=metadata, smoother=window, route=route, determined=determined, cond=cond)


def _point_feet(robot: Robot, kin: MeasuredKinematics, log: Log, options: EstimateOptions, base_motion: str,
                rows_ok: np.ndarray, out: tuple[np.ndarray, np.ndarray, np.ndarray], progress: Progress | None
                ) -> tuple[np.ndarray, np.ndarray, Determination]:
    """The ``base`` closure of a robot on point feet (module docstring): its momenta, rates and measured foot forces'
    torques written into ``out = (p, b, e)`` (N, n_act) at the rows it takes (outside the switches' margins, as the
    acceleration route's: a foot touching before its flag rises pushes unseen, its base twist known); returns those
    rows (M,), the joint rows they hold with no unknown force (M, n_tc) and what the equations determine there.

    Raises:
        InputError: a log without the base pose.
    """
    if log.base is None:
        raise InputError(f"{log.source}: a robot on {robot.stands_on} needs the base's measured motion: the base pose "
                         "columns base.x ... base.qw (and the IMU's imu.* with --base-motion imu)")
    r = np.flatnonzero(rows_ok & settled(kin.time, log.contact, options.lift_off_skip, options.touch_down_skip))
    q, v, known = _base_twist(robot, kin, log, base_motion, r)
    r, q, v = r[known], q[known], v[known]
    feet = None if log.foot_force is None else log.foot_force[r]
    p, b, e = out
    p[r], b[r] = (x[:, robot.act_v_index] for x in momentum_and_drift(robot.model, q, v, progress=progress)[:2])
    e[r] = foot_force_torques(robot, q, log.contact[r], feet)[:, robot.act_v_index]
    return r, free_rows(robot, log.contact[r], feet), determination(robot, q, log.contact[r], feet)


def _force_sampling(robot: Robot, log: Log, options: EstimateOptions, qd: np.ndarray,
                    pbe: tuple[np.ndarray, np.ndarray, np.ndarray], valid: np.ndarray, window: MomentumWindow,
                    closure: np.ndarray) -> dict:
    """``{"foot_force_sampling": ...}``: the readings of the measured foot forces compared on the momentum balance
    (:mod:`wbfriction.friction.force_sampling`, its warning line or ""), for a robot on point feet whose log has foot
    forces; else ``{}``. ``qd`` (N, n_act) and ``pbe`` (each (N, n_act)): the route's velocities, momenta, their
    rates and the measured forces' torques; ``valid`` (N, n_tc)."""
    if not robot.partial_contacts or log.foot_force is None:
        return {}
    tc, alignment = robot.tc_index, _alignment(options, log)
    p, b, e = (x[:, tc] for x in pbe)
    impulses = step_impulses(p, b, log.tau, window.step_durations(len(qd)), alignment, closure)
    found = check_force_sampling(impulses, e, qd[:, tc], valid, window, "held" if alignment == "zoh" else "instants")
    return {"foot_force_sampling": {**found.to_dict(), "warning": found.warning(log.source)}}


def _alignment(options: EstimateOptions, log: Log) -> str:
    """How the logged torque is held over a step: the option, else the log's metadata, else ``zoh``."""
    alignment = options.torque_alignment
    if alignment == "auto":
        alignment = log.metadata.get("torque_alignment", "zoh")
    if alignment not in ("zoh", "sample"):
        raise InputError(f"unknown torque alignment '{alignment}': choose one of zoh, sample")
    return alignment


def step_impulses(p: np.ndarray, b: np.ndarray, tau: np.ndarray, dt: np.ndarray, alignment: str = "zoh",
                  closure: np.ndarray | None = None) -> np.ndarray:
    """The friction's impulse over each step (module docstring): ``F_i = p_{i+1} - p_i - int tau - (b_i + b_{i+1})
    / 2 Delta t_i``.

    Args:
        p, b: momenta [N·m·s] and their rates without friction [N·m] (N, n) of the joints.
        tau: their torques (N, n) [N·m] (and whatever else is read as they are: the sensors' wrenches' share):
            ``zoh``, held over ``[t_i, t_i+1)``; ``sample``, read at the instants (the trapezoid).
        dt: the step durations (N - 1,) [s].
        closure: (N,) the tree each row was computed on (-1: none); a step between two trees, or off any, is NaN.

    Returns:
        (N - 1, n) [N·m·s].
    """
    dt = np.asarray(dt, dtype=float)[:, None]
    held = tau[:-1] * dt if alignment == "zoh" else 0.5 * (tau[:-1] + tau[1:]) * dt
    out = p[1:] - p[:-1] - held - 0.5 * (b[:-1] + b[1:]) * dt
    if closure is not None:
        out[(closure[1:] != closure[:-1]) | (closure[:-1] < 0)] = np.nan
    return out


def _whole_windows(mask: np.ndarray, half_width: int) -> np.ndarray:
    """(N, n): ``mask`` (N, n) held at every row of the window ``k - m .. k + m`` around row ``k``."""
    from scipy.ndimage import minimum_filter1d
    if len(mask) == 0:
        return mask.copy()
    return minimum_filter1d(mask.astype(np.int8), 2 * half_width + 1, axis=0, mode="constant", cval=0).astype(bool)
