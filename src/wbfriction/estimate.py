"""Joint friction estimation from measured kinematics (thesis 5.11-5.13, 6.1).

The acceleration difference of the torque-controlled joints is caused by friction:

.. math:: \\Delta\\ddot q_{tc} = \\ddot q_{msr,tc} - \\ddot q_{est,tc} = M_{mod}^{-1} \\tau_f. \\qquad (5.12)

* **Single support** (one contact): ``M_mod^{-1}`` is invertible and
  ``tau_f = M_mod Delta qdd_tc`` (5.13) is exact. The default route computes it with one
  recursive Newton-Euler pass on the robot re-rooted at the stance foot
  (:mod:`wbfriction.stance`), batched in C++ (``pin.rneaInParallel``); ``method="kkt"``
  forms (5.10)-(5.13) explicitly (:mod:`wbfriction.dynamics`). Both agree to 1e-9.
* **Double support**: ``M_mod^{-1}`` is singular; the regularised weighted least squares
  (6.1) ``min 1/2 |Delta - M_mod^{-1} tau_f|_W^2 + 1/2 tau_f^T Lambda tau_f`` gives
  ``tau_f = (A^T W A + Lambda)^{-1} A^T W Delta`` with ``A = M_mod^{-1}``. Such samples
  are flagged ``unique = False`` and never valid.

Sign convention: ``tau_f`` is the torque friction exerts on the joint,
``M qdd + h = S^T (tau + tau_f) + J^T lambda``; dissipative friction has ``qd tau_f <= 0``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
import pinocchio as pin
import pyarrow as pa

from .dynamics import constrained_dynamics
from .exceptions import InputError
from .kinematics import FilterOptions, MeasuredKinematics, Smoother, measure
from .log import Log, with_metadata
from .phases import Phases, joint_mask, segment
from .robot import Robot
from .stance import StanceModel, stance_model

CHUNK = 4096
METHODS = ("rnea", "kkt")


@dataclass(frozen=True)
class EstimateOptions:
    """Options of the estimator (defaults from the thesis).

    Attributes:
        diff: differentiation scheme: ``central``, ``backward``, ``savgol``, ``butterworth``
            (:mod:`~wbfriction.kinematics`, :mod:`~wbfriction.filters`) or ``true``.
        compensate_delay: shift the derivatives by their delay (6.1.2).
        torque_alignment: ``zoh`` (mean of tau[k-1], tau[k]), ``sample``, or ``auto``
            (what the log's metadata declares, else ``zoh``).
        lift_off_skip: seconds dropped after a lift-off [s] (6.2.1: 0.10).
        touch_down_skip: seconds dropped before a touch-down [s] (6.2.1: 0.05).
        mask: ``swing`` (a leg joint counts only while its leg swings) or ``single``.
        ds_weight: diagonal of W in (6.1), scalar or (n_tc,): relative weights of the
            joints' acceleration residuals (dimensionless).
        ds_regularization: diagonal of Lambda in (6.1), scalar or (n_tc,)
            [(rad/s^2)^2 / (N·m)^2 with W = 1]; it competes with ``A^T W A``, whose
            entries are of the order of (1 / joint inertia)^2.
        condition_number: report cond(M_mod^{-1}) per sample (one KKT inverse per sample).
        method: single-support route, ``rnea`` (default) or ``kkt``.
        filtering: parameters of the ``savgol`` and ``butterworth`` schemes.
    """

    diff: str = "central"
    compensate_delay: bool = True
    torque_alignment: str = "auto"
    lift_off_skip: float = 0.10
    touch_down_skip: float = 0.05
    mask: str = "swing"
    ds_weight: float | tuple[float, ...] = 1.0
    ds_regularization: float | tuple[float, ...] = 1e-3
    condition_number: bool = False
    method: str = "rnea"
    filtering: FilterOptions = FilterOptions()


@dataclass
class FrictionEstimate:
    """Per-sample friction estimate of the torque-controlled joints.

    Attributes:
        joints: torque-controlled joint names (n_tc,).
        time: (N,) [s].
        qd: joint velocities (N, n_tc) [rad/s] (same differentiation as ``qdd_msr``).
        tau_f: estimated friction torque (N, n_tc) [N·m]; NaN where not estimated.
        valid: (N, n_tc) samples to trust (single support, margins, mask).
        phase: (N,) ``single`` / ``double`` / ``flight``.
        unique: (N,) the estimate is the exact unique solution (single support).
        cond: (N,) condition number of ``M_mod^{-1}`` (NaN where not computed), or None.
        contact: (N, n_contacts) flags; ``contact_frames`` their names.
        tau_f_true: (N, n_tc) true friction if the log had it, else None.
        metadata: carried from the log, plus the options used.
        smoother: the zero-phase smoother the estimate went through (filtering schemes),
            or None; the fit passes the model through it too
            (:func:`~wbfriction.identify.fit_friction`). A table records it as the
            ``estimate_options`` of its metadata.
    """

    joints: tuple[str, ...]
    time: np.ndarray
    qd: np.ndarray
    tau_f: np.ndarray
    valid: np.ndarray
    phase: np.ndarray
    unique: np.ndarray
    contact: np.ndarray
    contact_frames: tuple[str, ...]
    cond: np.ndarray | None = None
    tau_f_true: np.ndarray | None = None
    metadata: dict = field(default_factory=dict)
    smoother: Smoother | None = None

    def to_table(self) -> pa.Table:
        """The estimate as an Arrow table: ``time``, ``phase``, ``unique``, [``cond``],
        ``contact.<frame>``, and per joint ``qd.<j>``, ``tau_f.<j>``, ``valid.<j>``,
        [``tau_f_true.<j>``]."""
        cols: dict[str, object] = {"time": self.time, "phase": pa.array(self.phase.astype(str)).dictionary_encode(),
                                   "unique": self.unique}
        if self.cond is not None:
            cols["cond"] = self.cond
        for i, f in enumerate(self.contact_frames):
            cols[f"contact.{f}"] = self.contact[:, i].astype(np.int8)
        for i, j in enumerate(self.joints):
            cols[f"qd.{j}"] = self.qd[:, i]
            cols[f"tau_f.{j}"] = self.tau_f[:, i]
            cols[f"valid.{j}"] = self.valid[:, i]
            if self.tau_f_true is not None and not np.all(np.isnan(self.tau_f_true[:, i])):
                cols[f"tau_f_true.{j}"] = self.tau_f_true[:, i]
        return with_metadata(pa.table(cols), self.metadata)


def _stance_frame_pose(robot: Robot, stance: StanceModel, angles: np.ndarray, base: np.ndarray | None) -> np.ndarray:
    """World pose of the stance frame: identity (flat, at the origin) or from the logged base."""
    n = angles.shape[0]
    pose = np.zeros((n, 7))
    pose[:, 6] = 1.0
    if base is None:
        return pose
    model, data = robot.model, robot.model.createData()
    fid = model.getFrameId(stance.frame)
    q = robot.configuration(angles, base)
    for k in range(n):
        pin.forwardKinematics(model, data, q[k])
        pose[k] = pin.SE3ToXYZQUAT(pin.updateFramePlacement(model, data, fid))
    return pose


def single_support_friction_rnea(robot: Robot, contact_index: int, angles: np.ndarray, qd: np.ndarray,
                                 qdd: np.ndarray, tau_tc: np.ndarray, base: np.ndarray | None = None,
                                 progress=None) -> np.ndarray:
    """Single-support friction (5.13) by inverse dynamics on the stance-rooted tree.

    Args:
        robot: the robot.
        contact_index: stance contact frame (index into ``robot.contact_frames``).
        angles, qd, qdd: joint positions, velocities, measured accelerations (N, n_act).
        tau_tc: torques of the torque-controlled joints (N, n_tc) [N·m].
        base: logged base poses (N, 7) or None (stance foot flat).
        progress: optional callable receiving numbers of samples done.

    Returns:
        tau_f (N, n_tc) [N·m], sign convention of :mod:`wbfriction.friction`.
    """
    stance = stance_model(robot, contact_index)
    out = np.empty_like(tau_tc, dtype=float)
    for start in range(0, angles.shape[0], CHUNK):
        sl = slice(start, start + CHUNK)
        pose = _stance_frame_pose(robot, stance, angles[sl], None if base is None else base[sl])
        tau_joint, _ = stance.inverse_dynamics(pose, angles[sl], qd[sl], qdd[sl])
        out[sl] = tau_joint[:, robot.tc_index] - tau_tc[sl]
        if progress is not None:
            progress(len(out[sl]))
    return out


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
                      progress=None) -> FrictionEstimate:
    """Estimate the friction torque of every torque-controlled joint at every sample.

    Args:
        robot: the robot.
        kin: measured kinematics (:func:`wbfriction.kinematics.measure`).
        options: :class:`EstimateOptions`.
        progress: optional callable receiving numbers of samples processed.

    Returns:
        :class:`FrictionEstimate`.

    Raises:
        InputError: no single-support sample, unknown method or mask.
    """
    if options.method not in METHODS:
        raise InputError(f"unknown method '{options.method}': choose one of {', '.join(METHODS)}")
    n, n_tc = len(kin.time), len(robot.torque_controlled)
    phases: Phases = segment(kin.time, kin.contact, options.lift_off_skip, options.touch_down_skip)
    usable = kin.valid & (phases.n_contacts > 0)
    if not np.any(usable & phases.single):
        raise InputError("the log has no single-support sample (exactly one contact flag set) with defined derivatives")
    tau_f = np.full((n, n_tc), np.nan)
    cond = np.full(n, np.nan) if options.condition_number else None
    tc = robot.tc_index
    ss = usable & phases.single
    # the KKT route (one Pinocchio call per sample) serves double support, and single
    # support when asked for it or for the condition number
    kkt_in_single = options.method == "kkt" or options.condition_number
    need_kkt = usable & (phases.double | (phases.single & kkt_in_single))
    if options.method == "rnea":
        rnea_progress = None if kkt_in_single else progress  # counted by the KKT pass then
        for c in range(len(robot.contact_frames)):
            rows = np.flatnonzero(ss & (phases.stance == c))
            if rows.size:
                tau_f[rows] = single_support_friction_rnea(
                    robot, c, kin.q[rows], kin.qd[rows], kin.qdd[rows], kin.tau[rows],
                    None if kin.base is None else kin.base[rows], rnea_progress)
    rows = np.flatnonzero(need_kkt)
    for start in range(0, rows.size, CHUNK):
        r = rows[start:start + CHUNK]
        dyn = constrained_dynamics(robot, kin.q[r], kin.qd[r], kin.qdd[r], kin.tau[r], kin.contact[r],
                                   None if kin.base is None else kin.base[r], with_Mmod_inv=True, progress=progress)
        delta = kin.qdd[r][:, tc] - dyn.qdd_est[:, tc]
        is_ss = phases.single[r]
        if options.method == "kkt" and np.any(is_ss):
            tau_f[r[is_ss]] = np.linalg.solve(dyn.Mmod_inv[is_ss], delta[is_ss][..., None])[..., 0]
        if np.any(~is_ss):
            tau_f[r[~is_ss]] = regularised_least_squares(dyn.Mmod_inv[~is_ss], delta[~is_ss],
                                                         options.ds_weight, options.ds_regularization)
        if cond is not None:
            cond[r] = np.linalg.cond(dyn.Mmod_inv)
    valid = joint_mask(phases, robot.limb_mask, options.mask) & usable[:, None] & np.isfinite(tau_f)
    metadata = dict(kin.metadata)
    metadata["estimate_options"] = asdict(options)
    return FrictionEstimate(
        joints=robot.torque_controlled, time=kin.time, qd=kin.qd[:, tc], tau_f=tau_f, valid=valid,
        phase=phases.labels(), unique=ss.copy(), contact=kin.contact, contact_frames=robot.contact_frames,
        cond=cond, tau_f_true=kin.tau_f_true, metadata=metadata, smoother=kin.smoother)


def estimate_log(robot: Robot, log: Log, options: EstimateOptions = EstimateOptions(), progress=None) -> FrictionEstimate:
    """Differentiate a log (:func:`~wbfriction.kinematics.measure`) and estimate its friction."""
    kin = measure(log, options.diff, compensate_delay=options.compensate_delay,
                  torque_alignment=options.torque_alignment, filtering=options.filtering)
    kin.metadata.update(robot=robot.name, source=log.source)
    return estimate_friction(robot, kin, options, progress)
