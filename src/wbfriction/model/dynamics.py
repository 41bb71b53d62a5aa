"""Constrained floating-base dynamics without friction (thesis 4.4-4.5, 5.4-5.12).

Per sample, with the feet in contact and the position-controlled joints as constraints

.. math::

    M \\ddot q + h = S_{tc}^T \\tau_{tc} + J_c^T \\lambda, \\qquad
    J_c \\ddot q = b, \\qquad
    J_c = \\begin{bmatrix} J \\\\ S_{pc} \\end{bmatrix}, \\quad
    b = \\begin{bmatrix} -\\dot J \\dot q \\\\ \\ddot q_{pc,msr} \\end{bmatrix}
    \\qquad (5.5, 5.6)

the acceleration estimate ``qdd_est`` (5.10) is Pinocchio's ``forwardDynamics`` with the
stacked constraint Jacobian and drift, and the operator (5.12)

.. math:: M_{mod}^{-1} = S_{tc} M^{-1} N S_{tc}^T

is the torque-controlled block of the upper-left block of the inverse KKT matrix
``[[M, J_c^T], [J_c, 0]]^{-1}`` (``computeKKTContactDynamicMatrixInverse``), which
equals ``M^{-1} - M^{-1} J_c^T (J_c M^{-1} J_c^T)^{-1} J_c M^{-1} = M^{-1} N``.
(The thesis's ``qdd_pc = 0`` is the special case of a head that does not move.)

The floating-base state comes from the joint data: the base pose is the logged one or,
if none, the one that puts the (first) stance contact frame flat at the world origin
(gravity only sees the foot's tilt, so position and yaw do not matter); the base twist
solves ``J v = 0`` for the contacts on the ground (least squares in double support).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import SupportsIndex

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress


@dataclass
class ConstrainedDynamics:
    """Output of :func:`constrained_dynamics` for N samples.

    Attributes:
        qdd_est: acceleration estimate without friction (N, n_act) [rad/s^2], actuated joints.
        Mmod_inv: ``M_mod^{-1}`` (N, n_tc, n_tc) [1/(kg m^2)], or None if not requested.
        q, v: full floating-base configuration (N, nq) and velocity (N, nv) used.
    """

    qdd_est: np.ndarray
    Mmod_inv: np.ndarray | None
    q: np.ndarray
    v: np.ndarray


def contact_jacobians(robot: Robot, data: pin.Data, q: np.ndarray, active: Sequence[SupportsIndex],
                      reconstruct_base: bool) -> np.ndarray:
    """The LOCAL Jacobians of the active contacts of one sample, stacked (6 per contact, nv).

    Args:
        robot: the robot; data: a Pinocchio data of ``robot.model`` (overwritten).
        q: the sample's configuration (nq,); with ``reconstruct_base`` its base part is
            overwritten in place by the pose that puts contact ``active[0]`` flat at the origin.
        active: indices (into ``robot.contact_frames``) of the contacts on the ground, at least one.

    The Jacobians are in each contact frame (LOCAL), which makes them independent of the base pose.
    """
    model = robot.model
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    fids = [robot.contact_frame_ids[c] for c in active]
    if reconstruct_base:
        q[:7] = pin.SE3ToXYZQUAT(data.oMf[fids[0]].inverse())
    return np.vstack([pin.getFrameJacobian(model, data, f, pin.LOCAL) for f in fids])


def base_twist(robot: Robot, J: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Velocities ``v`` (N, nv) whose base twist solves ``J v = 0`` for the given joint velocities, in
    least squares (exactly in single support), batched.

    Args:
        robot: the robot.
        J: stacked contact Jacobians (N, 6 n_active, nv) (:func:`contact_jacobians`).
        qd: joint velocities of the actuated joints (N, n_act) [rad/s].
    """
    v = np.zeros((J.shape[0], robot.model.nv))
    v[:, robot.act_v_index] = qd
    v[:, :6] = -(np.linalg.pinv(J[..., :6]) @ (J[..., 6:] @ v[:, 6:, None]))[..., 0]
    return v


def floating_base_state(robot: Robot, data: pin.Data, angles: np.ndarray, qd: np.ndarray,
                        active: Sequence[SupportsIndex],
                        base: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Full ``q``, ``v`` of one sample, and the stacked LOCAL Jacobians of the active contacts
    (:func:`contact_jacobians`, :func:`base_twist`).

    Args:
        robot: the robot.
        data: a Pinocchio data of ``robot.model`` (overwritten).
        angles, qd: joint positions and velocities (n_act,).
        active: indices (into ``robot.contact_frames``) of the contacts on the ground, at
            least one.
        base: logged base pose (7,) or None to reconstruct it from ``active[0]`` flat.
    """
    q = robot.configuration(angles, base)
    J = contact_jacobians(robot, data, q, active, base is None)
    return q, base_twist(robot, J[None], qd[None])[0], J


def constrained_dynamics(robot: Robot, angles: np.ndarray, qd: np.ndarray, qdd_msr: np.ndarray,
                         tau_tc: np.ndarray, contact: np.ndarray, base: np.ndarray | None = None,
                         with_Mmod_inv: bool = True, progress: Progress | None = None) -> ConstrainedDynamics:
    r"""Acceleration estimate (5.10) and ``M_mod^{-1}`` (5.12).

    Per sample, Pinocchio gives the kinematics (contact Jacobians, drifts ``Jdot v``), ``M^{-1}``
    (``computeMinverse``) and ``h`` (``nonLinearEffects``); the constrained solve is then
    batched over the samples of each contact pattern:

    .. math::

        \ddot q_{free} = M^{-1}(S^T\tau - h), \quad K = M^{-1} J_c^T, \quad
        (J_c K)\,\lambda = -\gamma - J_c \ddot q_{free}, \quad
        \ddot q_{est} = \ddot q_{free} + K\lambda, \quad
        M_{mod}^{-1} = S_{tc}\,(M^{-1} - K (J_c K)^{-1} K^T)\,S_{tc}^T,

    with ``J_c \ddot q + \gamma = 0`` the constraints (5.5, 5.6): ``gamma`` the contacts'
    drifts and ``-qdd_pc,msr``. This is the KKT system of ``pin.forwardDynamics`` solved by
    its Schur complement (tests/model/test_dynamics.py compares both per sample).

    Args:
        robot: the robot.
        angles, qd, qdd_msr: joint positions, velocities, measured accelerations (N, n_act).
            Only the position-controlled columns of ``qdd_msr`` are used (constraint 5.4c).
        tau_tc: torques of the torque-controlled joints (N, n_tc) [N·m].
        contact: contact flags (N, n_contacts); every row needs at least one contact.
        base: logged base poses (N, 7) or None.
        with_Mmod_inv: also compute ``M_mod^{-1}``.
        progress: optional callable receiving the number of samples done since last call.

    Returns:
        :class:`ConstrainedDynamics`.
    """
    model = robot.model
    data = model.createData()
    n, n_tc = angles.shape[0], len(robot.torque_controlled)
    iv_tc = robot.act_v_index[robot.tc_index]
    iv_pc = robot.act_v_index[robot.pc_index]
    S_pc = np.zeros((len(iv_pc), model.nv))
    S_pc[np.arange(len(iv_pc)), iv_pc] = 1.0
    zero_a = np.zeros(model.nv)
    q_all, v_all = robot.configuration(angles, base), np.zeros((n, model.nv))
    qdd_est = np.empty((n, robot.n_act))
    Mmod_inv = np.empty((n, n_tc, n_tc)) if with_Mmod_inv else None
    patterns, pattern_of = np.unique(contact, axis=0, return_inverse=True)
    for p, flags in enumerate(patterns):
        rows = np.flatnonzero(pattern_of.ravel() == p)
        active = list(np.flatnonzero(flags))
        m = 6 * len(active) + len(iv_pc)
        Jc = np.empty((len(rows), m, model.nv))
        gamma = np.empty((len(rows), m))
        Minv = np.empty((len(rows), model.nv, model.nv))
        h = np.empty((len(rows), model.nv))
        for i, k in enumerate(rows):
            Jc[i, :6 * len(active)] = contact_jacobians(robot, data, q_all[k], active, base is None)
        v_all[rows] = base_twist(robot, Jc[:, :6 * len(active)], qd[rows])
        for i, k in enumerate(rows):
            q, v = q_all[k], v_all[k]
            pin.forwardKinematics(model, data, q, v, zero_a)
            for c, fid in enumerate(robot.contact_frame_ids[a] for a in active):
                gamma[i, 6 * c:6 * c + 6] = pin.getFrameAcceleration(model, data, fid, pin.LOCAL).vector
            Minv[i] = pin.computeMinverse(model, data, q)
            h[i] = pin.nonLinearEffects(model, data, q, v)
        Jc[:, 6 * len(active):] = S_pc
        gamma[:, 6 * len(active):] = -qdd_msr[rows][:, robot.pc_index]
        tau = -h
        tau[:, iv_tc] += tau_tc[rows]
        a_free = (Minv @ tau[..., None])[..., 0]
        K = Minv @ np.swapaxes(Jc, 1, 2)  # (N, nv, m)
        G = Jc @ K
        lam = np.linalg.solve(G, (-gamma - (Jc @ a_free[..., None])[..., 0])[..., None])[..., 0]
        qdd_est[rows] = (a_free + (K @ lam[..., None])[..., 0])[:, robot.act_v_index]
        if Mmod_inv is not None:
            K_tc = K[:, iv_tc]
            Mmod_inv[rows] = Minv[:, iv_tc[:, None], iv_tc] - K_tc @ np.linalg.solve(G, np.swapaxes(K_tc, 1, 2))
        if progress is not None:
            progress(len(rows))
    return ConstrainedDynamics(qdd_est, Mmod_inv, q_all, v_all)


@dataclass(frozen=True)
class RedundantContacts:
    """Contacts whose constraints are redundant at every posture (:func:`redundant_contacts`).

    Attributes:
        frames: the contact frames on the ground.
        models: their contact models' names (``contact_model`` in the robot's TOML), in order.
        constraints: the rows of the stacked constraint Jacobian ``[J_c; S_pc]`` (the contacts' and the
            position-controlled joints').
        rank: its rank at a generic posture (:func:`redundant_contacts`), below ``constraints``.
    """

    frames: tuple[str, ...]
    models: tuple[str, ...]
    constraints: int
    rank: int


def redundant_contacts(robot: Robot, flags: np.ndarray) -> RedundantContacts | None:
    """Whether the contacts ``flags`` (n_contacts,) bool on the ground together are redundant constraints: their
    stacked Jacobian (each contact model's, :meth:`~wbfriction.model.contacts.ContactModel.jacobian`, and a row per
    position-controlled joint) of rank below its rows at a generic posture (joint angles drawn uniformly within their
    limits, ±π where there are none, with a fixed seed: the rank almost every posture has, and no posture more), hence
    at every posture. Then ``J_c M^-1 J_c^T`` is singular at every sample, the contact forces are not determined,
    and the KKT route (5.10) cannot be solved: the robot's contact models do not fit its feet (a sole, six
    constraints, on a foot that touches at a point: three or four of a quadruped's 3-DoF legs so held are 18 or 24
    constraints on 15 or 18 degrees of freedom; two of one side, whose hips turn about one line, 12 of rank 11).
    None where they are not (or none is down). Memoised on the robot per pattern.
    """
    key = ("redundant contacts", np.asarray(flags, dtype=bool).tobytes())
    if key in robot.cache:
        return robot.cache[key]
    active = np.flatnonzero(flags)
    found = None
    if active.size:
        lower, upper = robot.angle_limits
        rng = np.random.default_rng(0)
        angles = rng.uniform(np.where(np.isfinite(lower), lower, -np.pi), np.where(np.isfinite(upper), upper, np.pi))
        model, data = robot.model, robot.model.createData()
        pin.computeJointJacobians(model, data, robot.configuration(angles))
        pin.updateFramePlacements(model, data)
        rows = [robot.contact_models[c].jacobian(robot, data, robot.contact_frame_ids[c]) for c in active]
        S_pc = np.zeros((len(robot.pc_index), model.nv))
        S_pc[np.arange(len(robot.pc_index)), robot.act_v_index[robot.pc_index]] = 1.0
        J = np.vstack([*rows, S_pc])
        rank = int(np.linalg.matrix_rank(J))
        if rank < J.shape[0]:
            found = RedundantContacts(tuple(robot.contact_frames[c] for c in active),
                                      tuple(robot.contact_models[c].name for c in active), J.shape[0], rank)
    robot.cache[key] = found
    return found


def check_contact_patterns(robot: Robot, contact: np.ndarray, source: str) -> None:
    """Refuse a log whose contact flags ``contact`` (N, n_contacts) put on the ground together contacts that are
    redundant constraints of the robot's contact models (:func:`redundant_contacts`), before any work: the KKT route
    would end in a singular matrix. Only a robot whose contacts each fix its base (the KKT route's, not
    :attr:`Robot.partial_contacts <wbfriction.model.robot.Robot.partial_contacts>`, whose determination is asked
    sample by sample) is checked.

    Raises:
        InputError: one line naming ``source``, the first row of such a pattern, its frames, the robot's
            ``contact_model`` and the rank.
    """
    if not robot.floating_base or robot.partial_contacts or not len(contact):
        return
    flags = np.asarray(contact, dtype=bool)
    codes, first = np.unique(flags @ (1 << np.arange(flags.shape[1], dtype=np.int64)), return_index=True)
    for k in np.argsort(first):
        found = redundant_contacts(robot, flags[first[k]])
        if found is not None:
            held = len(robot.pc_index)
            models = ", ".join(dict.fromkeys(found.models))
            raise InputError(
                f"{source}: row {int(first[k])} has {', '.join(found.frames)} on the ground: robot '{robot.name}''s "
                f"contact_model ({models}) makes them {found.constraints} constraints"
                + (f" (with {held} position-controlled joints)" if held else "")
                + f" of rank {found.rank} at any posture: redundant, their forces not determined (contact_model = "
                "\"point\" for feet that touch the ground at a point)")
