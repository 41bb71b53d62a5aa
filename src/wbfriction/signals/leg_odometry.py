"""The floating base's motion from the robot's own sensors: its orientation from the IMU, its velocity and
acceleration from the stance legs' kinematics fused with the IMU by a Kalman filter and smoother (issue 82, item 2).

A walking robot's log often holds no base pose: the IMU's orientation (roll, pitch, yaw or a quaternion), its
angular rate, perhaps its specific force, and the joints. :func:`base_from_legs` makes the base's motion of them,
sample by sample, in Pinocchio's free-flyer convention (:mod:`wbfriction.signals.base_motion`):

* **Orientation.** The IMU frame's rotation (:func:`imu_rotation`, IMU frame to world) composed with its placement on
  the base link through the joints: ``R_b = R_imu R_bi(q)^T`` (``R_bi``: the IMU frame's rotation in the base frame,
  constant when the IMU sits on the base link, :mod:`wbfriction.model.imu`).
* **Angular velocity and acceleration.** The gyro's rate turned into the base frame, the IMU link's motion relative
  to the base through the joints taken out, and its derivative: :func:`~wbfriction.model.imu.base_motion_from_imu`
  on the gyro and the gyro differentiated by a Savitzky-Golay fit (:func:`~wbfriction.signals.filters.savgol_kernels`,
  order :attr:`OdometryOptions.gyro_order`) whose window is the shortest that leaves at most
  :attr:`OdometryOptions.noise_target` of the gyro's white noise in the angular acceleration (the joints'
  differentiation target, :mod:`wbfriction.signals.choice`), the noise read from the gyro itself
  (:func:`~wbfriction.signals.content.white_position_noise`, the contact changes' impacts left out).
* **Linear velocity from each stance leg.** A confident stance foot's contact point does not move
  (its contact model's constraint ``J_c v = 0``, :mod:`wbfriction.model.contacts`; for a point foot of
  :attr:`~wbfriction.model.robot.Robot.foot_radius` ``r`` the sphere's lowest point, so that a rolling foot is
  right), so that the base's linear velocity follows from the leg's joint velocities and the base's angular
  velocity: ``J_c[:, :3] v_lin = -J_c[:, 3:] v[3:]`` (least squares for a sole's six rows).
* **Fusion.** Per world axis a constant-acceleration model (state: velocity and acceleration, driven by a white
  jerk of spectral density ``s`` [m^2/s^5]) in ``filterpy``'s Kalman filter and Rauch-Tung-Striebel smoother (the
  log is offline: every sample's estimate uses the whole log). Measurements: the mean of the confident stance feet's
  velocities weighted by their noise (variance ``1 / sum(1 / sd^2)``), and with an accelerometer its specific force
  made the base origin's acceleration in the world (:func:`~wbfriction.model.imu.base_motion_from_imu`, gravity
  added back, the IMU's lever arm taken out). The accelerometer enters as a measurement of the state's acceleration
  rather than as the process's input (Bloesch et al. 2013, "State estimation for legged robots: consistent fusion of leg
  kinematics and IMU"): the two agree as the jerk's density grows, and the smoother then gives the acceleration its
  own standard deviation. Flight (no foot down, every foot's state confident) without an accelerometer: the
  centre of mass falls at ``g`` (a pseudo-measurement ``a = g - a_com|a_b=0``, Pinocchio's centre-of-mass
  acceleration with the base's linear acceleration zero, its standard deviation
  :attr:`OdometryOptions.noise_target` through the centre of mass's joint Jacobian); rows with no confident foot
  carry no measurement: the smoother bridges them by the model and their standard deviations grow.

**Noise levels, from the data** (each may be given instead, :class:`OdometryOptions`):

* each stance foot's velocity noise per axis (:mod:`~wbfriction.signals.leg_noise`): the stance level
  ``sigma_leg``, the robust spread of the stance feet's velocities about their mean over the samples with two or
  more confident stance feet (:func:`~wbfriction.signals.leg_noise.pooled_spread`), raised near the foot's own
  touch-down and lift-off by as much as the feet disagree there (:func:`~wbfriction.signals.leg_noise.stance_noise`:
  a landing foot is still stopping, a lifting one unloading); the velocity measurement is the feet's mean weighted
  by ``1 / sd^2``. A foot the smoothed state rejects (a chi-square test, :data:`GATE`: slipping, landing or lifting
  off beyond its noise) is left out and the whole done again (:func:`fused_velocity`); the test's variance is the
  smoothed residual's, ``sd^2 - P`` for a foot the state used (the state holds part of its error) and
  ``sd^2 + P`` for one it did not (``P`` the state's velocity variance);
* the accelerometer's and the gyro's white noise: :func:`~wbfriction.signals.content.white_position_noise` of their
  second differences (robust to the impacts);
* ``s`` per axis: the maximum of the measurements' likelihood (the innovations'), on a grid of decades of the
  dimensionless ``s T^3 / sigma_leg^2`` from 1e-14 to 1e4 (filters of bandwidth from minutes to the Nyquist
  frequency) two by two, then half decades about the best.

The twist's and acceleration's linear standard deviations are the smoothed covariance's, turned into the base
frame; the angular velocity's is the gyro's noise, its derivative's that noise through the fit's kernel (the fit's
bias not counted). They count the noise the data show, not a bias common to every foot (feet creeping together on a
soft ground). The position is the smoothed world velocity integrated (trapezoids) from 0: the base's pose in a
world whose origin is where the log starts, the orientation the IMU's (its yaw drifts as the IMU's does).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from wbfriction.choices import check_range, flag
from wbfriction.exceptions import InputError, OptionError
from wbfriction.model.imu import base_motion_from_imu
from wbfriction.model.robot import Robot
from wbfriction.signals.base_motion import continuous_quaternions
from wbfriction.signals.content import contact_changes, white_position_noise
from wbfriction.signals.filters import fir, savgol_kernels
from wbfriction.signals.leg_noise import pooled_spread, stance_noise
from wbfriction.signals.options import NOISE_TARGET

JERK_GRID = (-14.0, 4.0)
"""The decades of the dimensionless jerk density ``s T^3 / sigma_leg^2`` the likelihood is searched over (module
docstring): a filter's bandwidth is about ``(s / sigma^2)^(1/4)``, here from about 0.04 rad/s to the Nyquist
frequency at 500 Hz."""

GATE = 16.27
"""A foot's velocity is left out where its squared Mahalanobis distance to the smoothed state (three axes; the
smoothed residual's variance, module docstring) exceeds this: the chi-square distribution's 99.9 % quantile with 3
degrees of freedom (a foot slipping, landing or lifting off while its flag says stance)."""
GATE_ROUNDS = 3
"""Most rounds of :func:`fused_velocity` (the feet kept settle in two or three)."""


@dataclass(frozen=True)
class OdometryOptions:
    """How :func:`base_from_legs` estimates the base's motion (module docstring); None: measured from the data.

    Attributes:
        gyro_window: the Savitzky-Golay window [samples] (odd, > ``gyro_order``) differentiating the gyro; None: the
            shortest that leaves at most ``noise_target`` of the gyro's noise in the angular acceleration.
        gyro_order: that fit's polynomial order (>= 1).
        noise_target: most RMS noise the angular acceleration's fit may leave [rad/s^2] (the joints'
            :data:`~wbfriction.signals.options.NOISE_TARGET`); also the joints' acceleration noise a flight's
            gravity pseudo-measurement is given.
        jerk: the process's white jerk density [m^2/s^5] on every axis (> 0); None: per axis, the likelihood's best.
        leg_sd: a stance foot's velocity noise [m/s] (> 0), every foot and sample alike; None: the stance feet's
            spread, raised near each foot's touch-down and lift-off (:mod:`~wbfriction.signals.leg_noise`).
        acc_sd: the accelerometer's white noise [m/s^2] (> 0); None: read from it.
        gyro_sd: the gyro's white noise [rad/s] (>= 0); None: read from it.

    Raises:
        OptionError: a value out of its range, naming the option (``--gyro-window`` ...).
    """

    gyro_window: int | None = None
    gyro_order: int = 2
    noise_target: float = NOISE_TARGET
    jerk: float | None = None
    leg_sd: float | None = None
    acc_sd: float | None = None
    gyro_sd: float | None = None

    def __post_init__(self) -> None:
        check_range("gyro_order", self.gyro_order, low=1)
        if self.gyro_window is not None and (self.gyro_window % 2 == 0 or self.gyro_window <= self.gyro_order):
            raise OptionError(flag("gyro_window"), self.gyro_window, f"odd and > --gyro-order {self.gyro_order}")
        check_range("noise_target", self.noise_target, low=0.0, strict=True)
        for name in ("jerk", "leg_sd", "acc_sd"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise OptionError(flag(name), value, "> 0 (or None: from the data)")
        if self.gyro_sd is not None and not (math.isfinite(self.gyro_sd) and self.gyro_sd >= 0):
            raise OptionError(flag("gyro_sd"), self.gyro_sd, ">= 0 (or None: from the data)")


@dataclass(frozen=True)
class BaseEstimate:
    """The base's motion estimated from the robot's own sensors (:func:`base_from_legs`, module docstring).

    Attributes:
        pose: (N, 7) x, y, z [m], qx, qy, qz, qw: the base in the world, the position integrated from the velocity
            (0 at the first sample), the orientation the IMU's (sign-continuous quaternions).
        twist: (N, 6) Pinocchio's free-flyer velocity ``v[:6]``: linear [m/s] then angular [rad/s], base frame.
        acceleration: (N, 6) its derivative ``a[:6]`` in Pinocchio's convention, ``(R^T p_ddot - w x v_lin,
            w_dot)`` [m/s^2, rad/s^2], base frame; the angular part NaN where the gyro's fit has no whole window.
        twist_sd, acceleration_sd: (N, 6) their standard deviations (the flights' and the unconfident rows' grow).
        stance: (N,) the confident stance feet per sample (0: none measured the velocity there).
        leg_sd: (3,) the stance feet's velocity noise used [m/s], world axes: the stance level (a foot near its
            touch-down or lift-off counts more, :func:`~wbfriction.signals.leg_noise.stance_noise`).
        jerk: (3,) the process's jerk density used [m^2/s^5], world axes.
        gyro_sd, acc_sd: the gyro's [rad/s] and the accelerometer's [m/s^2] noise used (acc_sd NaN without one).
        gyro_window: the gyro fit's window [samples].
    """

    pose: np.ndarray
    twist: np.ndarray
    acceleration: np.ndarray
    twist_sd: np.ndarray
    acceleration_sd: np.ndarray
    stance: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    leg_sd: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    jerk: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    gyro_sd: float = math.nan
    acc_sd: float = math.nan
    gyro_window: int = 0


def _require_imu(robot: Robot, purpose: str) -> None:
    if robot.imu is None:
        raise InputError(f"robot '{robot.name}': no [imu] in its TOML (link, xyz, rpy): {purpose} needs the IMU's "
                         "placement on the robot")


def imu_rotation(robot: Robot, roll_pitch_yaw: np.ndarray | None = None, quaternion: np.ndarray | None = None
                 ) -> np.ndarray:
    """The IMU frame's rotation in the world (N, 3, 3) (IMU frame to world), from its logged orientation.

    Args:
        robot: a robot with an ``[imu]`` (:mod:`wbfriction.model.imu`).
        roll_pitch_yaw: (N, 3) [rad], ``pin.rpy`` convention: ``R = Rz(yaw) Ry(pitch) Rx(roll)``.
        quaternion: (N, 4) x, y, z, w (normalised here); exactly one of the two.

    Raises:
        InputError: a robot without ``[imu]``; neither or both orientations, a wrong shape, a non-finite value or a
            zero quaternion (naming the row).
    """
    from scipy.spatial.transform import Rotation
    _require_imu(robot, "the base's orientation from the IMU")
    if (roll_pitch_yaw is None) == (quaternion is None):
        raise InputError("the IMU's orientation: give roll, pitch, yaw or a quaternion (one of them)")
    name, x, width = (("roll, pitch, yaw", roll_pitch_yaw, 3) if quaternion is None else ("quaternion", quaternion, 4))
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[1] != width:
        raise InputError(f"the IMU's {name} must be (N, {width}), got shape {x.shape}")
    bad = ~np.all(np.isfinite(x), axis=1)
    if width == 4:
        bad |= np.linalg.norm(np.where(np.isfinite(x), x, 0.0), axis=1) < 1e-9
    if bad.any():
        raise InputError(f"the IMU's {name} at row {int(np.flatnonzero(bad)[0])} is not a rotation: {x[bad][0]}")
    rotation = Rotation.from_euler("xyz", x) if width == 3 else Rotation.from_quat(x)
    return np.asarray(rotation.as_matrix()).reshape(-1, 3, 3)


def base_rotation(robot: Robot, q: np.ndarray, imu_rot: np.ndarray) -> np.ndarray:
    """The base's rotation in the world (N, 3, 3), ``R_imu R_bi(q)^T`` (module docstring), from the joints' angles
    ``q`` (N, n_act) and the IMU frame's rotation (N, 3, 3)."""
    assert robot.imu is not None
    model = robot.model
    frame = model.frames[robot.imu.frame]
    if frame.parentJoint == 1:  # on the base link: a constant placement in the root joint's frame
        return np.einsum("nij,kj->nik", imu_rot, frame.placement.rotation)
    data, out = model.createData(), np.empty_like(imu_rot)
    for k, full in enumerate(robot.configuration(q)):
        pin.framesForwardKinematics(model, data, full)
        out[k] = imu_rot[k] @ data.oMf[robot.imu.frame].rotation.T
    return out


def white_noise(x: np.ndarray, dt: float, contact: np.ndarray) -> np.ndarray:
    """The white noise (m,) on a signal ``x`` (N, m) sampled every ``dt``, read from its second differences
    (:func:`~wbfriction.signals.content.white_position_noise`, the contact changes' impacts left out); 0 where
    nothing could be read."""
    second = (x[2:] - 2.0 * x[1:-1] + x[:-2]) / dt**2
    sigma = white_position_noise(second, dt, changes=contact_changes(contact))
    return np.where(np.isfinite(sigma), sigma, 0.0)


def gyro_window(sigma: float, dt: float, order: int, target: float, n: int) -> int:
    """The shortest odd Savitzky-Golay window (order ``order``) whose first derivative leaves at most ``target``
    [rad/s^2] of a white gyro noise ``sigma`` [rad/s] (bisection: the kernel's norm falls as the window grows),
    else the longest the log allows (``n`` samples)."""
    def left(w: int) -> float:
        return sigma * float(np.linalg.norm(savgol_kernels(w, order, dt, max_deriv=1)[1]))

    lo, hi = (order + 1) // 2, max((n - 1) // 2, (order + 1) // 2)  # half-widths: windows 2 h + 1 > order
    if left(2 * lo + 1) <= target:
        return 2 * lo + 1
    if left(2 * hi + 1) > target:
        return 2 * hi + 1
    while hi - lo > 1:  # left(2 lo + 1) > target >= left(2 hi + 1)
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if left(2 * mid + 1) <= target else (mid, hi)
    return 2 * hi + 1


def stance_velocities(robot: Robot, full_q: np.ndarray, rest: np.ndarray, base_rot: np.ndarray,
                      feet: np.ndarray) -> np.ndarray:
    """Each measuring foot's estimate of the base's linear velocity in the world (N, n_c, 3) [m/s], NaN where a foot
    does not measure (module docstring).

    Args:
        full_q: configurations (N, nq) with the base's orientation; rest: velocities (N, nv), the base's linear
            part ignored (its angular, the joints'); base_rot: (N, 3, 3); feet: (N, n_c) bool, the measuring feet.
    """
    model, kinds = robot.model, robot.contact_models
    data, ids = model.createData(), robot.contact_frame_ids
    out = np.full(feet.shape + (3,), np.nan)
    for k in np.flatnonzero(feet.any(axis=1)):
        pin.computeJointJacobians(model, data, full_q[k])
        pin.updateFramePlacements(model, data)
        for c in np.flatnonzero(feet[k]):
            J = kinds[c].jacobian(robot, data, ids[c])
            v_lin = np.linalg.lstsq(J[:, :3], -(J[:, 3:] @ rest[k, 3:]), rcond=None)[0]
            out[k, c] = base_rot[k] @ v_lin
    return out


def flight_gravity(robot: Robot, full_q: np.ndarray, v: np.ndarray, a: np.ndarray, rows: np.ndarray,
                   target: float) -> tuple[np.ndarray, np.ndarray]:
    """The base's acceleration in flight (len(rows), 3) [m/s^2], world: the centre of mass falls at ``g``, less its
    acceleration relative to the base (Pinocchio's with the base's linear velocity and acceleration zero), and its
    standard deviation (len(rows), 3): ``target`` [rad/s^2] of joint acceleration noise through the centre of mass's
    joint Jacobian."""
    model, data = robot.model, robot.model.createData()
    g = model.gravity.linear
    z, sd = np.empty((rows.size, 3)), np.empty((rows.size, 3))
    for i, k in enumerate(rows):
        pin.centerOfMass(model, data, full_q[k], v[k], a[k])
        z[i] = g - data.acom[0]
        J = pin.jacobianCenterOfMass(model, data, full_q[k])[:, robot.act_v_index]
        sd[i] = target * np.linalg.norm(J, axis=1)
    return z, sd


def kalman_pass(dt: float, z_v: np.ndarray, r_v: np.ndarray, z_a: np.ndarray, r_a: np.ndarray, jerk: np.ndarray,
                prior_sd: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, object]:
    """One forward pass of the constant-acceleration Kalman filter (``filterpy``; state: the world velocity (3)
    then acceleration (3); module docstring).

    Args:
        dt: the sample period [s]; z_v, r_v: (N, 3) the velocity measurements [m/s] and their variances, NaN rows
            where none; z_a, r_a: (N, 3) the acceleration's [m/s^2]; jerk: (3,) the jerk densities [m^2/s^5];
            prior_sd: the first state's standard deviation (velocity [m/s] and acceleration [m/s^2]: diffuse).

    Returns:
        ``(x, P, loglik, filter)``: the filtered means (N, 6, 1) and covariances (N, 6, 6), the measurements'
        log-likelihood per axis (3,) (the update's covariance is diagonal: the axes are independent), the filter
        (for its smoother).
    """
    from filterpy.kalman import KalmanFilter
    eye, zero = np.eye(3), np.zeros((3, 3))
    kf = KalmanFilter(dim_x=6, dim_z=3)
    kf.F = np.block([[eye, dt * eye], [zero, eye]])
    s = np.diag(jerk)
    kf.Q = np.block([[s * dt**3 / 3.0, s * dt**2 / 2.0], [s * dt**2 / 2.0, s * dt]])
    kf.x = np.zeros((6, 1))
    kf.P = np.eye(6) * prior_sd**2
    H_v, H_a = np.hstack([eye, zero]), np.hstack([zero, eye])
    n = len(z_v)
    xs, Ps, loglik = np.empty((n, 6, 1)), np.empty((n, 6, 6)), np.zeros(3)
    has_v, has_a = np.all(np.isfinite(z_v), axis=1), np.all(np.isfinite(z_a), axis=1)
    for k in range(n):
        if k:
            kf.predict()
        for z, r, H, has in ((z_v, r_v, H_v, has_v), (z_a, r_a, H_a, has_a)):
            if has[k]:
                kf.update(z[k].reshape(3, 1), R=np.diag(r[k]), H=H)
                S, y = np.diag(kf.S), kf.y.ravel()
                loglik -= 0.5 * (np.log(2.0 * np.pi * S) + y**2 / S)
        xs[k], Ps[k] = kf.x, kf.P
    return xs, Ps, loglik, kf


def likeliest_jerk(dt: float, z_v: np.ndarray, r_v: np.ndarray, z_a: np.ndarray, r_a: np.ndarray,
                   leg_sd: np.ndarray, prior_sd: float) -> np.ndarray:
    """The jerk density per axis (3,) [m^2/s^5] of the measurements' greatest likelihood (module docstring): decades
    of :data:`JERK_GRID` two by two, then half decades about the best (the axes searched together: they are
    independent)."""
    scale = leg_sd**2 / dt**3

    def loglik(decades: np.ndarray) -> np.ndarray:
        return kalman_pass(dt, z_v, r_v, z_a, r_a, scale * 10.0**decades, prior_sd)[2]

    grid = np.arange(JERK_GRID[0], JERK_GRID[1] + 1.0, 2.0)
    best = grid[np.argmax([loglik(np.full(3, d)) for d in grid], axis=0)]
    fine = best[None, :] + np.arange(-1.5, 1.75, 0.5)[:, None]  # (7, 3), best among them
    scores = np.array([loglik(d) for d in fine])
    return scale * 10.0 ** fine[np.argmax(scores, axis=0), np.arange(3)]


def _check(robot: Robot, arrays: dict[str, np.ndarray | None], dt: float, source: str) -> int:
    """The arrays' shapes and values (one line naming the array); returns N."""
    _require_imu(robot, "the base's motion from the legs")
    n = len(np.asarray(arrays["q"]))
    shapes = {"q": (n, robot.n_act), "qd": (n, robot.n_act), "qdd": (n, robot.n_act), "imu_rotation": (n, 3, 3),
              "gyro": (n, 3), "acc": (n, 3), "contact": (n, len(robot.contact_frames)),
              "confident": (n, len(robot.contact_frames))}
    for name, shape in shapes.items():
        x = arrays[name]
        if x is not None and np.shape(x) != shape:
            raise InputError(f"{source}: the base's motion from the legs: {name} must be {shape}, got {np.shape(x)}")
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"{source}: the base's motion from the legs: the sample period must be > 0 s, got {dt!r}")
    if n < 3:
        raise InputError(f"{source}: the base's motion from the legs needs 3 samples or more, got {n}")
    for name in ("q", "qd", "gyro"):
        bad = ~np.all(np.isfinite(np.asarray(arrays[name], dtype=float)), axis=1)
        if bad.any():
            raise InputError(f"{source}: the base's motion from the legs: {name} is not finite at row "
                             f"{int(np.flatnonzero(bad)[0])}")
    stance = np.asarray(arrays["contact"], dtype=bool) & np.asarray(arrays["confident"], dtype=bool)
    if not stance.any():
        raise InputError(f"{source}: no sample has a confident stance foot: the base's velocity cannot be taken "
                         "from the legs")
    return n


@dataclass(frozen=True)
class _Angular:
    omega: np.ndarray  # (N, 3) base frame [rad/s]
    omega_d: np.ndarray  # (N, 3) [rad/s^2], NaN without a whole window
    acc_base: np.ndarray | None  # (N, 3) the base origin's classical acceleration, base frame [m/s^2]
    gyro_sd: float
    omega_d_sd: float
    window: int


def angular_motion(robot: Robot, full_q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, gyro: np.ndarray,
                   acc: np.ndarray | None, dt: float, contact: np.ndarray, options: OdometryOptions) -> _Angular:
    """The base's angular velocity and acceleration, and with an accelerometer its origin's acceleration, from the
    IMU (:func:`~wbfriction.model.imu.base_motion_from_imu`, the gyro differentiated: module docstring)."""
    assert robot.imu is not None
    n = len(gyro)
    gyro_sd = (options.gyro_sd if options.gyro_sd is not None
               else float(np.sqrt(np.mean(white_noise(gyro, dt, contact)**2))))
    window = options.gyro_window or gyro_window(gyro_sd, dt, options.gyro_order, options.noise_target, n)
    if window > n:
        raise OptionError(flag("gyro_window"), window, f"at most the log's {n} samples")
    h = savgol_kernels(window, options.gyro_order, dt, max_deriv=1)[1]
    gyro_d = fir(gyro, h)
    v_b, a_b = base_motion_from_imu(robot.model, robot.imu, full_q, robot.act_v_index, qd, qdd, gyro, gyro_d,
                                    np.zeros((n, 3)) if acc is None else acc)
    return _Angular(v_b[:, 3:], a_b[:, 3:], None if acc is None else a_b[:, :3], gyro_sd,
                    gyro_sd * float(np.linalg.norm(h)), window)


def _acceleration_measurements(robot: Robot, full_q: np.ndarray, rest: np.ndarray, qdd: np.ndarray,
                               base_rot: np.ndarray, ang: _Angular, contact: np.ndarray, confident: np.ndarray,
                               acc: np.ndarray | None, dt: float, options: OdometryOptions
                               ) -> tuple[np.ndarray, np.ndarray, float]:
    """The filter's acceleration measurements ``z_a, r_a`` (N, 3) (NaN rows where none) and the accelerometer's
    noise (NaN without one): the accelerometer's, or without one the flights' gravity (module docstring)."""
    n = len(rest)
    z_a, r_a, acc_sd = np.full((n, 3), np.nan), np.full((n, 3), np.nan), math.nan
    if acc is not None:
        assert ang.acc_base is not None
        acc_sd = (options.acc_sd if options.acc_sd is not None
                  else float(np.sqrt(np.mean(white_noise(acc, dt, contact)**2))))
        z_a = np.einsum("nij,nj->ni", base_rot, ang.acc_base)
        r_a[:] = acc_sd**2
        return z_a, r_a, acc_sd
    known = np.all(np.isfinite(ang.omega_d), axis=1) & np.all(np.isfinite(qdd), axis=1)
    flight = np.flatnonzero(~contact.any(axis=1) & confident.all(axis=1) & known)
    if flight.size:
        a = np.zeros_like(rest)
        a[:, 3:6] = ang.omega_d
        a[:, robot.act_v_index] = qdd
        z, sd = flight_gravity(robot, full_q, rest, a, flight, options.noise_target)
        z_a[flight], r_a[flight] = z, sd**2
    return z_a, r_a, acc_sd


def fused_velocity(dt: float, feet_v: np.ndarray, feet_sd: np.ndarray, leg_sd: np.ndarray, z_a: np.ndarray,
                   r_a: np.ndarray, jerk: float | None, prior_sd: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The smoothed world velocity and acceleration (N, 6) and covariance (N, 6, 6), the jerk density used (3,) and
    the feet kept (N, n_c) bool (module docstring): the filter and smoother on the kept feet's velocities ``feet_v``
    (N, n_c, 3), weighted by their noise ``feet_sd`` (N, n_c, 3) (:func:`~wbfriction.signals.leg_noise.stance_noise`:
    their mean weighted by ``1 / sd^2``, its variance ``1 / sum(1 / sd^2)`` per axis); the feet whose velocity the
    smoothed state rejects (:data:`GATE`) left out and the whole done again until the feet kept stay the same (at
    most :data:`GATE_ROUNDS` rounds), the jerk's density chosen again each round (on the scale of the stance level
    ``leg_sd`` (3,))."""
    measuring = np.isfinite(feet_v[..., 0])
    use = measuring
    weight = np.where(measuring[..., None], 1.0 / np.where(measuring[..., None], feet_sd, 1.0) ** 2, 0.0)
    v0 = np.where(measuring[..., None], feet_v, 0.0)

    def measured(use: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        w = weight * use[..., None]
        total = w.sum(axis=1)
        has = np.asarray(use.any(axis=1), dtype=bool)
        z_v = np.full((len(feet_v), 3), np.nan)
        z_v[has] = np.sum(w * v0, axis=1)[has] / total[has]
        return z_v, 1.0 / np.where(has[:, None], total, 1.0)

    def likeliest(use: np.ndarray) -> np.ndarray:
        return np.full(3, jerk) if jerk is not None else likeliest_jerk(dt, *measured(use), z_a, r_a, leg_sd,
                                                                        prior_sd)

    for last in [False] * (GATE_ROUNDS - 1) + [True]:
        s = likeliest(use)
        xs, Ps, _, kf = kalman_pass(dt, *measured(use), z_a, r_a, s, prior_sd)
        x, P, _, _ = kf.rts_smoother(xs, Ps)  # type: ignore[attr-defined]
        state = np.diagonal(P[:, :3, :3], axis1=1, axis2=2)[:, None, :]
        var = np.where(use[..., None], feet_sd**2 - state, feet_sd**2 + state)
        var = np.where(var > 0, var, np.inf)  # a foot the state holds to rounding: nothing to test it against
        d2 = np.sum((feet_v - x[:, None, :3, 0])**2 / var, axis=2)
        kept = measuring & (d2 <= GATE)
        if last or np.array_equal(kept, use):
            break
        use = kept
    return x[..., 0], P, s, use


def base_from_legs(robot: Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, imu_rotation: np.ndarray,
                   gyro: np.ndarray, contact: np.ndarray, confident: np.ndarray, dt: float,
                   acc: np.ndarray | None = None, options: OdometryOptions = OdometryOptions(),
                   source: str = "<log>") -> BaseEstimate:
    """The base's pose, twist and acceleration with their standard deviations, from the IMU and the stance legs
    (module docstring).

    Args:
        robot: a floating-base robot with an ``[imu]`` and contact frames.
        q, qd, qdd: the actuated joints' angles [rad], velocities [rad/s] and accelerations [rad/s^2] (N, n_act),
            :attr:`~wbfriction.model.robot.Robot.actuated` order.
        imu_rotation: (N, 3, 3) the IMU frame's rotation, IMU frame to world (:func:`imu_rotation`).
        gyro: (N, 3) its angular velocity [rad/s], IMU frame.
        contact, confident: (N, n_c) bool per :attr:`~wbfriction.model.robot.Robot.contact_frames`: the foot on the
            ground, and whether that state is known (an unconfident foot measures nothing).
        dt: the sample period [s].
        acc: (N, 3) the IMU's specific force [m/s^2], IMU frame, or None (no accelerometer).
        options: :class:`OdometryOptions`; source: the log's name, for messages.

    Returns:
        :class:`BaseEstimate`.

    Raises:
        InputError: a robot without ``[imu]``; an array of the wrong shape or not finite; no confident stance foot
            in the log; no sample with two confident stance feet to measure the legs' noise (give ``leg_sd``).
        OptionError: a gyro window longer than the log.
    """
    from scipy.spatial.transform import Rotation
    n = _check(robot, dict(q=q, qd=qd, qdd=qdd, imu_rotation=imu_rotation, gyro=gyro, acc=acc, contact=contact,
                           confident=confident), dt, source)
    q, qd, qdd, gyro = (np.asarray(x, dtype=float) for x in (q, qd, qdd, gyro))
    contact, confident = np.asarray(contact, dtype=bool), np.asarray(confident, dtype=bool)
    acc = None if acc is None else np.asarray(acc, dtype=float)
    base_rot = base_rotation(robot, q, np.asarray(imu_rotation, dtype=float))
    pose = continuous_quaternions(np.hstack([np.zeros((n, 3)), Rotation.from_matrix(base_rot).as_quat()]))
    full_q = robot.configuration(q, pose)
    ang = angular_motion(robot, full_q, qd, qdd, gyro, acc, dt, contact, options)
    rest = np.zeros((n, robot.model.nv))
    rest[:, 3:6] = ang.omega
    rest[:, robot.act_v_index] = qd
    feet_v = stance_velocities(robot, full_q, rest, base_rot, contact & confident)
    leg_sd = np.full(3, options.leg_sd) if options.leg_sd is not None else pooled_spread(feet_v)
    if not np.all(np.isfinite(leg_sd) & (leg_sd > 0)):
        raise OptionError(flag("leg_sd"), None, f"given: {source} has no sample with two confident stance feet to "
                          "measure the legs' velocity noise from")
    z_a, r_a, acc_sd = _acceleration_measurements(robot, full_q, rest, qdd, base_rot, ang, contact, confident, acc,
                                                  dt, options)
    prior_sd = float(np.linalg.norm(robot.model.gravity.linear)) * 1.0  # a second of free fall: diffuse
    feet_sd = (np.where(np.isfinite(feet_v), options.leg_sd, np.nan) if options.leg_sd is not None
               else stance_noise(feet_v, leg_sd))
    x, P, jerk, kept = fused_velocity(dt, feet_v, feet_sd, leg_sd, z_a, r_a, options.jerk, prior_sd)
    v_w, a_w = x[:, :3], x[:, 3:]
    v_lin = np.einsum("nji,nj->ni", base_rot, v_w)
    a_lin = np.einsum("nji,nj->ni", base_rot, a_w) - np.cross(ang.omega, v_lin)

    def turned_sd(block: np.ndarray) -> np.ndarray:  # sqrt(diag(R^T P R))
        return np.sqrt(np.einsum("nji,njk,nki->ni", base_rot, block, base_rot))

    pose[1:, :3] = np.cumsum(0.5 * (v_w[1:] + v_w[:-1]) * dt, axis=0)
    omega_d_sd = np.where(np.isfinite(ang.omega_d), ang.omega_d_sd, np.nan)
    return BaseEstimate(
        pose=pose, twist=np.hstack([v_lin, ang.omega]), acceleration=np.hstack([a_lin, ang.omega_d]),
        twist_sd=np.hstack([turned_sd(P[:, :3, :3]), np.full((n, 3), ang.gyro_sd)]),
        acceleration_sd=np.hstack([turned_sd(P[:, 3:, 3:]), omega_d_sd]), stance=kept.sum(axis=1), leg_sd=leg_sd,
        jerk=jerk, gyro_sd=ang.gyro_sd, acc_sd=float(acc_sd), gyro_window=ang.window)
