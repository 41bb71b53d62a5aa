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

from wbfriction.inertia.consistency import FRICTION, STRIBECK, friction_lower_bounds
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.regressor import stance_regressor
from wbfriction.model.robot import Robot
from wbfriction.model.stance import stance_frame_pose
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


def friction_columns(qd_tc: np.ndarray, options: InertialOptions, stribeck: np.ndarray | None = None) -> np.ndarray:
    """(N, n_tc, k n_tc): joint ``i``'s row holds ``qd_i, tanh(a qd_i), 1`` (and the Stribeck
    column ``tanh(a qd_i) exp(-(qd_i / v_s)^2)`` where ``stribeck[i]``, else zero) in its ``k``
    columns, ``f(qd) = columns @ params``; ``qd_tc`` (N, n_tc) [rad/s]."""
    n, m = qd_tc.shape
    k = len(friction_names(options))
    out = np.zeros((n, m, k * m))
    idx = np.arange(m)
    coulomb = np.tanh(options.tanh_slope * qd_tc)
    out[:, idx, k * idx] = qd_tc
    out[:, idx, k * idx + 1] = coulomb
    out[:, idx, k * idx + 2] = 1.0
    if k == 4:
        on = np.ones(m, dtype=bool) if stribeck is None else stribeck
        out[:, idx, k * idx + 3] = coulomb * np.exp(-(qd_tc / options.stribeck_velocity) ** 2) * on
    return out


def armature_columns(qdd_tc: np.ndarray) -> np.ndarray:
    """(N, n_tc, n_tc): joint ``i``'s row holds ``qdd_i`` [rad/s^2] in column ``i`` (the armature's)."""
    n, m = qdd_tc.shape
    out = np.zeros((n, m, m))
    out[:, np.arange(m), np.arange(m)] = qdd_tc
    return out


def sample_rows(robot: Robot, kin: MeasuredKinematics, r: np.ndarray, c: int,
                options: InertialOptions) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows of samples ``r`` standing on contact frame ``c``, per torque-controlled joint.

    Returns:
        ``Y`` (N, n_tc, p_rooted): the regressor over the stance-rooted tree's parameters
        (:func:`~wbfriction.inertia.regressor.stance_regressor`: its ``to_rooted`` maps the bodies' to them);
        ``C`` (N, n_tc, k n_tc [+ n_tc]): the columns of the other parameters (:func:`friction_columns`,
        :func:`armature_columns` when identified); ``b`` (N, n_tc) [N·m]: the measured torques, less a known
        armature's share.
    """
    reg = stance_regressor(robot, c)
    tc = robot.tc_index
    pose = stance_frame_pose(robot, reg.stance, kin.q[r], None if kin.base is None else kin.base[r])
    Y = reg.joint_rows(pose, kin.q[r], kin.qd[r], kin.qdd[r])[:, tc]
    stribeck = None if options.stribeck_joints is None else np.isin(robot.torque_controlled, options.stribeck_joints)
    C = friction_columns(kin.qd[r][:, tc], options, stribeck)
    qdd_tc = kin.qdd[r][:, tc]
    b = kin.tau[r]
    if options.armature == "identify":
        C = np.concatenate([C, armature_columns(qdd_tc)], axis=2)
    elif options.armature == "known":
        b = b - given_armature(robot) * qdd_tc
    return Y, C, b


def lower_bounds(robot: Robot, options: InertialOptions) -> np.ndarray:
    """Lower bounds of the parameters (p,): none on the bodies' (their physical consistency is a constraint of
    its own), the friction's (:func:`~wbfriction.inertia.consistency.friction_lower_bounds`), armature >= 0."""
    p_in = 10 * (robot.model.njoints - 1)
    n_tc, k = len(robot.torque_controlled), len(friction_names(options))
    n_armature = len(rest_names(robot, options)) - k * n_tc
    return np.concatenate([np.full(p_in, -np.inf), friction_lower_bounds(k, n_tc), np.zeros(n_armature)])


def joint_friction(rest: np.ndarray, robot: Robot, options: InertialOptions) -> np.ndarray:
    """The friction per torque-controlled joint (n_tc, k) of the parameters after the bodies' ``rest``
    (k n_tc [+ n_tc],), a copy; the Stribeck parameter zero on the joints without the term (no column: its
    value is no fit's, nor a bound's)."""
    n_tc, k = len(robot.torque_controlled), len(friction_names(options))
    friction = rest[:k * n_tc].reshape(n_tc, k).copy()
    if k == len(FRICTION) + 1 and options.stribeck_joints is not None:
        friction[~np.isin(robot.torque_controlled, options.stribeck_joints), -1] = 0.0
    return friction
