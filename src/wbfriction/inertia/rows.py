"""The identification's parameters and its regression rows (:mod:`wbfriction.inertia.identification`).

The parameters are the bodies' inertial parameters (10 per body, :func:`~wbfriction.inertia.regressor.
body_parameters` order), then per torque-controlled joint its ``k`` friction parameters (:func:`friction_names`)
and, with ``armature = "identify"``, one armature per joint: ``pi.ravel(), friction.ravel()[, armature]``
(:func:`rest_names`). A joint's row of the inverse dynamics (single support, stance-rooted: module docstring of
:mod:`~wbfriction.inertia.identification`) is the bodies' regressor ``Y``, its own friction columns
(:func:`friction_columns`) and armature column (:func:`armature_columns`), and its measured torque
(:func:`sample_rows`).
"""

from __future__ import annotations

import numpy as np

from wbfriction.fit.smoothing import row_smoothing
from wbfriction.friction.measured import base_state
from wbfriction.inertia.consistency import FRICTION, STRIBECK, friction_lower_bounds
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.regressor import floating_regressor, stance_regressor
from wbfriction.model.determination import foot_force_torques
from wbfriction.model.rerooted import stance_frame_pose
from wbfriction.model.robot import Robot
from wbfriction.signals.kinematics import MeasuredKinematics


def friction_names(options: InertialOptions) -> tuple[str, ...]:
    """The friction parameters identified per joint with ``options``: Coulomb, viscous and offset
    (:data:`~wbfriction.inertia.consistency.FRICTION`), then the Stribeck term's with a Stribeck velocity."""
    return FRICTION + ((STRIBECK,) if options.stribeck_velocity is not None else ())


def rest_names(robot: Robot, options: InertialOptions) -> tuple[str, ...]:
    """``<joint>.<friction parameter>`` per torque-controlled joint, then ``<joint>.armature`` if identified:
    the parameters after the bodies', in order."""
    names = tuple(f"{j}.{p}" for j in robot.torque_controlled for p in friction_names(options))
    if options.armature == "identify":
        names += tuple(f"{j}.armature" for j in robot.torque_controlled)
    return names


def own_columns(robot: Robot, options: InertialOptions) -> np.ndarray:
    """Each torque-controlled joint's own columns among the parameters after the bodies' (n_tc, k[+1]):
    its ``k`` friction parameters, then its armature when identified (:func:`rest_names`' order)."""
    n_tc, k = len(robot.torque_controlled), len(friction_names(options))
    armature = [[k * n_tc + i] for i in range(n_tc)] if options.armature == "identify" else [[]] * n_tc
    return np.array([[k * i + c for c in range(k)] + armature[i] for i in range(n_tc)], dtype=int)


def given_armature(robot: Robot) -> np.ndarray:
    """The model's armature of the torque-controlled joints (n_tc,) [kg·m^2]."""
    return np.array(robot.model.armature[robot.act_v_index][robot.tc_index], dtype=float)


def friction_features(qd_tc: np.ndarray, options: InertialOptions, stribeck: np.ndarray | None = None,
                      one_way: np.ndarray | None = None) -> np.ndarray:
    """(N, n_tc, k): joint ``i``'s ``qd_i, tanh(a qd_i), 1`` (the offset's zero where ``one_way[i]``:
    :attr:`~wbfriction.inertia.options.InertialOptions.one_way_joints`; and the Stribeck
    column ``tanh(a qd_i) exp(-(qd_i / v_s)^2)`` where ``stribeck[i]``, else zero), ``f_i(qd) = features_i @ params_i``;
    ``qd_tc`` (N, n_tc) [rad/s]."""
    k = len(friction_names(options))
    out = np.empty((*qd_tc.shape, k))
    coulomb = np.tanh(options.tanh_slope * qd_tc)
    out[:, :, 0] = qd_tc
    out[:, :, 1] = coulomb
    out[:, :, 2] = 1.0 if one_way is None else np.where(one_way, 0.0, 1.0)
    if k == 4:
        on = np.ones(qd_tc.shape[1], dtype=bool) if stribeck is None else stribeck
        out[:, :, 3] = coulomb * np.exp(-(qd_tc / options.stribeck_velocity) ** 2) * on
    return out


def friction_columns(features: np.ndarray) -> np.ndarray:
    """(N, n_tc, k n_tc): joint ``i``'s row holds its :func:`friction_features` (N, n_tc, k) in its ``k`` columns
    (``f(qd) = columns @ params``), zero elsewhere."""
    n, m, k = features.shape
    out = np.zeros((n, m, k * m))
    idx = np.arange(m)
    for c in range(k):
        out[:, idx, k * idx + c] = features[:, :, c]
    return out


def friction_rows(robot: Robot, kin: MeasuredKinematics, r: np.ndarray, options: InertialOptions) -> np.ndarray:
    """The :func:`friction_features` of the rows ``r`` (len(r), n_tc, k) (the Stribeck term on ``options``'
    joints, no offset on its joints that moved one way), at the kinematics' velocities; with a smoother
    (``kin.smoother``: the differentiation's filter, which the torques went through too), passed through it as the
    fit's model is (parallel filtering, :func:`~wbfriction.fit.solve.filtered_problem`): the friction seen through
    the filter, not the friction of the filtered velocity. NaN where the smoother's window holds a sample without a
    velocity (such a row is left out: :func:`row_mask`). A global smoother (Butterworth) filters the whole series:
    call it once for all the rows of a part, not per block."""
    joints = robot.torque_controlled
    stribeck = None if options.stribeck_joints is None else np.isin(joints, options.stribeck_joints)
    one_way = np.isin(joints, options.one_way_joints) if options.one_way_joints else None
    qd = kin.qd[:, robot.tc_index]
    if kin.smoother is None or not len(r):
        return friction_features(qd[r], options, stribeck, one_way)
    smoothing = row_smoothing(kin.smoother, len(qd), r)
    return smoothing(friction_features(qd[smoothing.support], options, stribeck, one_way))


def row_mask(holds: np.ndarray | None, C: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """Where each joint's row of a block enters the regression (n, n_tc) bool: it holds (``holds``, None: everywhere:
    :meth:`~wbfriction.inertia.samples.Part.holds`) and its columns ``C`` (n, n_tc, p) and torque ``b`` (n, n_tc)
    are finite; None: every row."""
    finite = np.isfinite(C).all(axis=2) & np.isfinite(b)
    if holds is None:
        return None if finite.all() else finite
    return holds & finite


def armature_columns(qdd_tc: np.ndarray) -> np.ndarray:
    """(N, n_tc, n_tc): joint ``i``'s row holds ``qdd_i`` [rad/s^2] in column ``i`` (the armature's)."""
    n, m = qdd_tc.shape
    out = np.zeros((n, m, m))
    out[:, np.arange(m), np.arange(m)] = qdd_tc
    return out


def sample_rows(robot: Robot, kin: MeasuredKinematics, r: np.ndarray, c: int, options: InertialOptions,
                features: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows of samples ``r`` of row group ``c`` (:func:`~wbfriction.inertia.regressor.row_groups`: standing on
    contact frame ``c``, or on point feet), per torque-controlled joint; ``features``: their
    :func:`friction_rows` (len(r), n_tc, k) if computed already (None: here).

    Returns:
        ``Y`` (N, n_tc, p_rooted): the regressor over the group's parameters
        (:func:`~wbfriction.inertia.regressor.regressor_of`: its ``to_rooted`` maps the bodies' to them);
        ``C`` (N, n_tc, k n_tc [+ n_tc]): the columns of the other parameters (:func:`friction_columns`,
        :func:`armature_columns` when identified); ``b`` (N, n_tc) [N·m]: the measured torques, less a known
        armature's share, plus on point feet the measured foot forces' ``J^T f``
        (:func:`~wbfriction.model.determination.foot_force_torques`). On point feet a joint's row holds only where
        no foot with an unknown force is down on its limb (:attr:`~wbfriction.inertia.samples.Part.rows`).
    """
    tc = robot.tc_index
    if robot.partial_contacts:
        Y, b = floating_rows(robot, kin, r)
    else:
        reg = stance_regressor(robot, c)
        pose = stance_frame_pose(robot, reg.stance, kin.q[r], None if kin.base is None else kin.base[r])
        Y, b = reg.joint_rows(pose, kin.q[r], kin.qd[r], kin.qdd[r])[:, tc], kin.tau[r]
    C = friction_columns(friction_rows(robot, kin, r, options) if features is None else features)
    qdd_tc = kin.qdd[r][:, tc]
    if options.armature == "identify":
        C = np.concatenate([C, armature_columns(qdd_tc)], axis=2)
    elif options.armature == "known":
        b = b - given_armature(robot) * qdd_tc
    return Y, C, b


def floating_rows(robot: Robot, kin: MeasuredKinematics, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A robot on point feet, its base's motion measured (:func:`~wbfriction.friction.measured.base_state`): the
    torque-controlled joints' rows of the floating regressor (N, n_tc, 10 n_bodies) and their measured torques plus
    the measured foot forces' ``J^T f`` (N, n_tc) [N·m] (``S (M a + h) = tau + tau_f + S J^T f``)."""
    q, v, a_b = base_state(robot, kin, r)
    assert a_b is not None  # point feet: the base measured (split_log)
    a = np.zeros_like(v)
    a[:, :6], a[:, robot.act_v_index] = a_b, kin.qdd[r]
    rows = robot.act_v_index[robot.tc_index]
    feet = None if kin.foot_force is None else kin.foot_force[r]
    forces = foot_force_torques(robot, q, kin.contact[r], feet)[:, rows]
    return floating_regressor(robot).joint_rows(q, v, a)[:, robot.tc_index], kin.tau[r] + forces


def lower_bounds(robot: Robot, options: InertialOptions) -> np.ndarray:
    """Lower bounds of the parameters (p,): none on the bodies' (their physical consistency is a constraint of
    its own), the friction's (:func:`~wbfriction.inertia.consistency.friction_lower_bounds`), armature >= 0."""
    p_in = 10 * (robot.model.njoints - 1)
    n_tc, k = len(robot.torque_controlled), len(friction_names(options))
    n_armature = len(rest_names(robot, options)) - k * n_tc
    return np.concatenate([np.full(p_in, -np.inf), friction_lower_bounds(k, n_tc), np.zeros(n_armature)])


def joint_friction(rest: np.ndarray, robot: Robot, options: InertialOptions) -> np.ndarray:
    """The friction per torque-controlled joint (n_tc, k) of the parameters after the bodies' ``rest``
    (k n_tc [+ n_tc],), a copy; the Stribeck parameter zero on the joints without the term, the offset on the joints
    that moved one way (no column: its value is no fit's, nor a bound's)."""
    n_tc, k = len(robot.torque_controlled), len(friction_names(options))
    friction = rest[:k * n_tc].reshape(n_tc, k).copy()
    if k == len(FRICTION) + 1 and options.stribeck_joints is not None:
        friction[~np.isin(robot.torque_controlled, options.stribeck_joints), -1] = 0.0
    friction[np.isin(robot.torque_controlled, options.one_way_joints), FRICTION.index("tau_os")] = 0.0
    return friction
