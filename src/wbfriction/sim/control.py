"""Walking controller: constrained inverse dynamics feed-forward plus joint PD.

Feed-forward (thesis 4.4 with the contact wrench as unknown): for the reference
``(q, v, a)`` with the feet in contact ``c``, ``b = M a + h`` (``pin.rnea``) must equal
``S^T tau + J_c^T lambda``. The six base rows fix the total contact wrench:
``b_base = J_c,base^T lambda``. In single support ``J_c,base`` is square and ``lambda``
unique; in double support the wrench is shared between the feet by the weighted
minimum norm

.. math:: \\lambda = W^{-1} J_b (J_b^T W^{-1} J_b)^{-1} b_{base},
          \\quad W = \\mathrm{diag}(I_6/\\alpha_L, I_6/\\alpha_R),

with ``alpha`` the share of each foot, from the position of the ZMP reference between
the feet (1 on the foot the ZMP is over, 0 on the other). The joint torques are then
``tau = b_joint - J_c,joint^T lambda``. Wrenches ``lambda`` are in each sole's LOCAL frame.

PD gains come from each joint's effective inertia ``1 / G_jj``, with ``G`` the
constrained inverse inertia (the inverse of the KKT matrix on the joint rows), for each
contact state at the reference posture; the controller switches them with the state.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.model.rerooted import stance_model
from wbfriction.model.robot import Robot
from wbfriction.walking import WalkingReference


def contact_jacobian(robot: Robot, data: pin.Data, contacts: np.ndarray) -> np.ndarray:
    """Stacked 6D Jacobians (6 n_active, nv) of the active soles in their LOCAL frames.

    Requires ``pin.computeJointJacobians`` and ``pin.updateFramePlacements`` on ``data``.
    """
    ids = [robot.contact_frame_ids[c] for c in np.flatnonzero(contacts)]
    if not ids:
        return np.zeros((0, robot.model.nv))
    return np.vstack([pin.getFrameJacobian(robot.model, data, f, pin.LOCAL) for f in ids])


def foot_shares(zmp: np.ndarray, feet_xy: np.ndarray) -> np.ndarray:
    """Share (N, 2) of each foot in the contact wrench: the ZMP's position along the segment
    between the feet, 1 on the foot it is over, clipped to [0, 1]."""
    d = feet_xy[:, 0] - feet_xy[:, 1]
    s = np.einsum("ij,ij->i", zmp - feet_xy[:, 1], d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-12)
    s = np.clip(s, 0.0, 1.0)
    return np.column_stack([s, 1.0 - s])


def feedforward(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray, contact: np.ndarray,
                share: np.ndarray, min_share: float = 0.05) -> tuple[np.ndarray, np.ndarray]:
    """Joint torques and contact wrenches of a reference motion (module docstring).

    Single-support samples are computed in one batched RNEA pass on the robot re-rooted at
    the stance sole (:mod:`wbfriction.model.rerooted`: the same solution, since the reference keeps
    the stance sole still), double-support samples one by one with the weighted sharing.

    Args:
        q, v, a: reference configurations (N, nq), velocities and accelerations (N, nv),
            with the soles in contact at rest: ``J_c v = 0``, ``J_c a + Jdot_c v = 0``.
        contact: active contacts (N, n_contacts).
        share: each foot's share of the wrench in double support (N, n_contacts).

    Returns:
        tau (N, n_act) [N·m] for every actuated joint, and the contact wrenches
        (N, n_contacts, 6) (force [N], moment [N·m]) in the soles' LOCAL frames, zero
        for feet not in contact.

    Raises:
        ValueError: a sample with no foot in contact.
    """
    iv, iq = robot.act_v_index, robot.act_q_index
    n, nc = len(q), len(robot.contact_frames)
    n_active = contact.sum(axis=1)
    if np.any(n_active == 0):
        raise InputError(f"feed-forward: no foot in contact at sample {int(np.argmin(n_active))}")
    tau = np.zeros((n, robot.n_act))
    wrench = np.zeros((n, nc, 6))
    for c in range(nc):
        rows = np.flatnonzero(contact[:, c] & (n_active == 1))
        if rows.size:
            sole_pose = np.tile([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0], (rows.size, 1))  # flat; the result is invariant
            tau[rows], wrench[rows, c] = stance_model(robot, c).inverse_dynamics(
                sole_pose, q[rows][:, iq], v[rows][:, iv], a[rows][:, iv])
    double = np.flatnonzero(n_active > 1)
    if double.size:
        tau[double], wrench[double] = _shared_wrench_dynamics(robot, q[double], v[double], a[double],
                                                              contact[double], share[double], min_share)
    return tau, wrench


def _shared_wrench_dynamics(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray, contact: np.ndarray,
                            share: np.ndarray, min_share: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`feedforward` of samples with several feet in contact: the weighted minimum-norm
    sharing of the module docstring.

    ``b = M a + h`` comes from one batched RNEA (``pin.rneaInParallel``), the contact
    Jacobians (LOCAL) from Pinocchio sample by sample, the sharing from batched linear algebra.

    Args:
        q (n, nq), v, a (n, nv): reference states; contact: active contacts (n, n_contacts);
        share: each foot's share (n, n_contacts), floored at ``min_share``.

    Returns:
        tau (n, n_act) [N·m] and wrenches (n, n_contacts, 6), zero for feet not in contact.
    """
    model, data = robot.model, robot.model.createData()
    iv = robot.act_v_index
    n, nc = len(q), len(robot.contact_frames)
    b = pin.rneaInParallel(1, pin.ModelPool(model, 1), q.T, v.T, a.T).T  # (n, nv)
    # stacked Jacobians of all feet (n, 6 n_contacts, nv), those not in contact zeroed
    Jc = np.zeros((n, 6 * nc, model.nv))
    feet = [(slice(6 * c, 6 * c + 6), f) for c, f in enumerate(robot.contact_frame_ids)]
    for k, row in enumerate(contact.tolist()):
        pin.computeJointJacobians(model, data, q[k])  # getFrameJacobian places the frame from its joint
        for (rows, f), on in zip(feet, row):
            if on:
                Jc[k, rows] = pin.getFrameJacobian(model, data, f, pin.LOCAL)
    Jb = Jc[:, :, :6]
    w_inv = np.repeat(np.where(contact, np.maximum(share, min_share), 0.0), 6, axis=1)  # (n, 6 nc)
    JW = Jb * w_inv[:, :, None]
    mu = np.linalg.solve(np.einsum("nij,nik->njk", Jb, JW), b[:, :6, None])  # (n, 6, 1)
    lam = (JW @ mu)[:, :, 0]  # (n, 6 nc), zero off contact
    tau = b[:, iv] - np.einsum("nij,ni->nj", Jc[:, :, iv], lam)
    return tau, lam.reshape(n, nc, 6)


def constrained_inverse_inertia(robot: Robot, data: pin.Data, q: np.ndarray, contacts: np.ndarray) -> np.ndarray:
    """``G`` (nv, nv): joint-space acceleration per unit generalised force with the active
    soles fixed and the position-controlled joints locked (eq. 5.10 without the drift)."""
    model = robot.model
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    S_pc = np.zeros((robot.pc_index.size, model.nv))
    S_pc[np.arange(robot.pc_index.size), robot.act_v_index[robot.pc_index]] = 1.0
    J = np.vstack([contact_jacobian(robot, data, contacts), S_pc])
    Minv = np.linalg.inv(M)
    MJ = Minv @ J.T
    return Minv - MJ @ np.linalg.solve(J @ MJ, MJ.T)


def pd_gains(robot: Robot, q: np.ndarray, bandwidth: float, damping: float = 0.9
             ) -> dict[tuple[bool, ...], tuple[np.ndarray, np.ndarray]]:
    """PD gains per contact state, per torque-controlled joint: ``kp = I w^2``, ``kd = 2 zeta I w``
    with ``w = 2 pi bandwidth`` and ``I = 1 / G_jj`` the joint's effective inertia in that state.

    A stance leg carries the whole body as an inverted pendulum and needs the large gains
    its large effective inertia gives; a swinging leg would go unstable with them at
    1 kHz. The controller therefore switches gains with the contact state.

    Args:
        q: configuration at which the inertias are evaluated (the reference posture).
        bandwidth: closed-loop bandwidth [Hz]; damping: ratio zeta.

    Returns:
        ``{contact flags: (kp [N·m/rad], kd [N·m·s/rad])}`` for double support and each
        single support.
    """
    data = robot.model.createData()
    nc = len(robot.contact_frames)
    states = [np.ones(nc, bool)] + [np.eye(nc, dtype=bool)[c] for c in range(nc)]
    iv_tc = robot.act_v_index[robot.tc_index]
    gains = {}
    for s in states:
        inertia = 1.0 / np.diag(constrained_inverse_inertia(robot, data, q, s))[iv_tc]
        gains[tuple(bool(x) for x in s)] = pd_from_inertia(inertia, bandwidth, damping)
    return gains


def pd_from_inertia(inertia: np.ndarray, bandwidth: float, damping: float) -> tuple[np.ndarray, np.ndarray]:
    """``kp = I w^2`` [N·m/rad], ``kd = 2 zeta I w`` [N·m·s/rad] for inertias ``I`` [kg m^2],
    ``w = 2 pi bandwidth`` [Hz] and damping ratio ``zeta``."""
    w = 2 * np.pi * bandwidth
    return inertia * w**2, 2 * damping * inertia * w


def gain_schedule(gains: dict[tuple[bool, ...], tuple[np.ndarray, np.ndarray]], contact: np.ndarray,
                  dt: float, blend: float) -> tuple[np.ndarray, np.ndarray]:
    """PD gains at every sample of a contact sequence.

    At each change of contact state the gains that rise (a landing leg's) ramp linearly to
    those of the new state over ``blend`` seconds, so that a landing leg's small tracking
    error times the stance gains does not pull the foot on the ground; the gains that fall
    (a lifting leg's) apply at once.

    Args:
        gains: :func:`pd_gains` output.
        contact: contact flags (N, n_contacts).
        dt: sampling period [s]; blend: ramp time [s] (0: switch at once).

    Returns:
        kp, kd: (N, n_tc) arrays.
    """
    n = len(contact)
    kp_first = next(iter(gains.values()))[0]
    kp, kd = np.empty((n, kp_first.size)), np.empty((n, kp_first.size))
    starts = np.flatnonzero(np.any(np.diff(contact, axis=0, prepend=~contact[:1]), axis=1))
    for i, s in enumerate(starts):
        e = starts[i + 1] if i + 1 < len(starts) else n
        to = gains[tuple(bool(x) for x in contact[s])]
        kp[s:e], kd[s:e] = ramp_gains(to if s == 0 else (kp[s - 1], kd[s - 1]), to,
                                      np.arange(e - s)[:, None] * dt, blend)
    return kp, kd


def ramp_gains(current: tuple[np.ndarray, np.ndarray], target: tuple[np.ndarray, np.ndarray],
               elapsed, blend: float) -> tuple[np.ndarray, np.ndarray]:
    """Gains ``elapsed`` seconds after a switch from ``current`` to ``target`` (kp, kd): the
    falling ones at once, the rising ones linearly over ``blend`` seconds (0: at once)."""
    r = np.minimum(1.0, np.asarray(elapsed) / blend) if blend > 0 else 1.0
    start = [np.minimum(c, t) for c, t in zip(current, target)]
    return tuple(s + r * (t - s) for s, t in zip(start, target))


def attitude_ankle_torques(R: np.ndarray, omega: np.ndarray, R_ref: np.ndarray, omega_ref: np.ndarray,
                           gains: tuple[float, float], ankle_axes: list[np.ndarray],
                           load: np.ndarray) -> list[np.ndarray]:
    """Torques of the stance ankles that right the base (an ankle strategy on the IMU).

    The base's tilt error ``e = log(R R_ref^T)`` and rate error ``omega - omega_ref`` (both
    in the world frame) call for the moment ``m = -(K e + D (omega - omega_ref))`` on the
    body, its vertical component dropped (the heading is left to the legs' PD). A joint
    torque ``t`` about a world axis ``a`` acts on the body above the joint with ``-t a``,
    so each stance ankle joint gets ``t = -a . m`` times its foot's share of the load.
    The rate comes from the body, not from the ankle joint: its damping is not bound by
    the foot's small inertia as the joint PD's is
    (:func:`~wbfriction.sim.mujoco_sim.simulate_mujoco`).

    Args:
        R, R_ref: measured and reference base orientations (3, 3).
        omega, omega_ref: measured and reference base angular velocities, world frame [rad/s].
        gains: (K [N·m/rad], D [N·m·s/rad]).
        ankle_axes: per foot, the world axes (n_j, 3) of its ankle joints.
        load: each foot's normal force [N] (0: not in contact).

    Returns:
        Per foot, torques (n_j,) [N·m] to add to its ankle joints' commands.
    """
    K, D = gains
    m = -(K * pin.log3(R @ R_ref.T) + D * (omega - omega_ref))
    m[2] = 0.0
    share = load / load.sum() if load.sum() > 0 else np.zeros_like(load)
    return [-s * (axes @ m) for s, axes in zip(share, ankle_axes)]


def reference_feedforward(robot: Robot, reference: WalkingReference) -> np.ndarray:
    """:func:`feedforward` torques (N, n_act) of a walking reference, the wrench shared
    between the feet by its ZMP (:func:`foot_shares`)."""
    ref = reference
    return feedforward(robot, ref.q, ref.v, ref.a, ref.contact, foot_shares(ref.zmp, ref.feet[:, :, :2]))[0]
