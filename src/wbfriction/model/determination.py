"""Which joints' torques the contacts leave determined, sample by sample (issue 56).

With the base's motion measured (its logged pose differentiated, or the IMU), every acceleration is known and the
equation of motion

.. math:: M \\ddot q + h - J_m^T \\lambda_m = S^T \\tau_{joint} + J_u^T \\lambda_u

has as unknowns the actuated joints' torques ``tau_joint`` (``tau + tau_f`` of a torque-controlled joint, the
whole torque of a position-controlled one) and the contact forces not measured, ``lambda_u``; ``lambda_m`` are the
measured ones (a quadruped's foot sensors, :mod:`wbfriction.logs.foot_forces`). Whether ``tau_joint`` of joint
``j`` is unique is the rank question of the stacked ``[S^T  J_u^T]``: joint ``j`` is determined when no null vector
of it moves ``tau_joint[j]``. Since ``S^T`` holds an identity on the joint rows, the null space is
``{(-J_{u,j}^T n, n) : J_{u,b}^T n = 0}`` (``J_{u,b}`` the base columns of the contact Jacobian): the contact
forces that exert no wrench on the base (internal forces, one foot pushing against another) and the joint torques
they would need. So

* the rank of ``[S^T  J_u^T]`` is ``n_act + rank(J_{u,b}^T)``, decided on the 6 x m matrix ``J_{u,b}^T`` by its
  singular values (those below ``sigma_max /`` :data:`COND_MAX` count as zero, Conditioning below);
* joint ``j`` is determined when ``|J_{u,j}^T N|_j`` (``N`` the orthonormal null basis) is below
  :data:`LEAK_TOL` [m]: the free internal forces exert no torque on it;
* the determined torques are those of the least-norm solution, ``lambda_u = J_{u,b}^{T+} r_b``,
  ``tau_joint = r_j - J_{u,j}^T lambda_u``, with ``r = M qdd + h - J_m^T lambda_m`` (one RNEA pass);
* the base rows left unexplained, ``r_b - J_{u,b}^T lambda_u``, are a cross-check (zero for consistent data; in
  flight, all six rows).

What that gives a quadruped on point feet (three unknowns per foot down, :attr:`Robot.contact_kinds`):

* one or no foot down: every joint determined;
* two feet down (a trot's stance): ``J_{u,b}^T`` is 6 x 6 but of rank 5: the two feet can squeeze (or pull apart)
  along the line joining them with no wrench on the base. The swing legs are determined, the stance legs are not
  (unless a stance leg's joint axis sees no moment from that line);
* three or four feet down: three (six) such internal forces; the swinging leg, if any, is determined;
* measured 3-D foot forces remove their foot's unknowns: every joint determined. A measured normal force alone
  removes only the normal component; the internal forces of feet on flat ground are horizontal, so normal forces
  do not determine a stance leg.

A humanoid's sole (six unknowns, a wrench) fits the same: single support determines every joint (thesis 5.13),
double support the joints off the legs' closed chain.

Conditioning: a singular value of ``J_{u,b}^T`` below ``sigma_max /`` :data:`COND_MAX` counts as zero: the
internal force along it would need a thousandfold the base rows' error to be told apart, so it is left free like an
exact null vector, and only the joints it moves lose their determination. Three feet nearly on a line, or feet whose
normal forces are measured standing at heights a few micrometres apart (flat ground: the horizontal forces' moments
about the base are then nearly those of their sum), leave the stance legs not determined and every swinging leg
determined (issue 63: a trot's swinging legs were 0-1 % determined when the whole sample was dropped). ``cond =
sigma_max / sigma_r`` of the kept singular values (forces in N, moments in N·m, so lengths in metres), at most
:data:`COND_MAX`: how much an error in the base rows can grow in the contact forces, and so in the stance legs'
torques.

Sign convention: ``tau_f = tau_joint - tau``, the torque friction exerts on the joint.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.model.robot import Robot
from wbfriction.progress import Progress

LEAK_TOL = 1e-9
"""[m] A joint is determined when the free internal contact forces move its torque by less than this per newton."""
COND_MAX = 1e3
"""A singular value of ``J_{u,b}^T`` below ``sigma_max / COND_MAX`` counts as zero (its internal force left free,
module docstring): an error of the base rows would grow a thousandfold in the contact forces. Regular stances of a
quadruped are about 3-10 (the Go2: two to four feet, no force measured). Feet on flat ground whose normal forces are
measured leave a direction that is exactly free on level feet and conditioned by their heights' differences: 1e6-1e9
on the ideal simulator's trot and walk (micrometres), 2.1e3-1.5e7 on MuJoCo's soft-footed trot (issue 63)."""


@dataclass
class Determination:
    """Which joint torques the contacts leave determined, per sample (module docstring).

    Attributes:
        determined: (N, n_act) joint ``j``'s torque is unique: no free internal force moves it.
        nullity: (N,) the dimension of the internal contact forces the equations leave free (singular values below
            ``sigma_max /`` :data:`COND_MAX` counted as zero).
        cond: (N,) the conditioning of ``J_{u,b}^T`` on its kept singular values, at most :data:`COND_MAX` (1 with
            no unknown contact force).
        residual: (N, 6) the base rows left unexplained [N, N·m], base frame.
    """

    determined: np.ndarray
    nullity: np.ndarray
    cond: np.ndarray
    residual: np.ndarray


@dataclass
class ContactSolution:
    """Output of :func:`joint_torques`.

    Attributes:
        tau: (N, n_act) the actuated joints' torques ``S (M qdd + h - J^T lambda)`` [N·m], NaN where not determined.
        force: (N, m_max) the unknown contact forces of the least-norm solution, stacked in contact order (3 per point
            foot in world axes [N], 6 per sole in its frame [N, N·m]), NaN-padded; a reading aid, not unique.
        determination: :class:`Determination`.
    """

    tau: np.ndarray
    force: np.ndarray
    determination: Determination


def contact_jacobian(robot: Robot, data: pin.Data, c: int) -> np.ndarray:
    """The constraint Jacobian of contact ``c`` (dims, nv) after ``pin.computeJointJacobians`` and
    ``pin.updateFramePlacements`` on ``data``: its contact model's
    (:meth:`ContactModel.jacobian <wbfriction.model.contacts.ContactModel.jacobian>`): a sole's six LOCAL rows, a
    point's three rows in world axes, the velocity of its contact point (the sphere's lowest point with
    :attr:`~wbfriction.model.robot.Robot.foot_radius`)."""
    return robot.contact_models[c].jacobian(robot, data, robot.contact_frame_ids[c])


def measured_components(robot: Robot, foot_force: np.ndarray | None) -> np.ndarray:
    """(n_contacts, 3) which components of each contact's force the foot sensors measure: a foot's finite columns
    (every row or none, :mod:`wbfriction.logs.foot_forces`) of a contact whose model takes world-axes forces
    (:attr:`ContactModel.world_force <wbfriction.model.contacts.ContactModel.world_force>`: a point foot); none of
    another's (a sole's wrench, a contact in its own axes)."""
    measured = np.zeros((len(robot.contact_frames), 3), dtype=bool)
    if foot_force is not None and len(foot_force):
        measured = np.isfinite(foot_force).all(axis=0)
    return measured & np.array([m.world_force for m in robot.contact_models], dtype=bool)[:, None]


def determine(base_map: np.ndarray, joint_map: np.ndarray, r_base: np.ndarray, r_joint: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, Determination]:
    """The rank decision and least-norm solution of one contact pattern, batched (module docstring).

    Args:
        base_map: ``J_{u,b}^T`` (N, 6, m); joint_map: ``J_{u,j}^T`` (N, n_act, m) (m may be 0).
        r_base: (N, 6) and r_joint: (N, n_act): ``M qdd + h - J_m^T lambda_m``, base and joint rows.

    Returns:
        ``(tau, force, determination)``: (N, n_act) joint torques (every row, determined or not), (N, m) the
        least-norm forces, and the :class:`Determination`.
    """
    n, n_act, m = joint_map.shape
    if m == 0:  # no unknown force (flight, or every force measured): every torque follows
        return (r_joint.copy(), np.zeros((n, 0)),
                Determination(np.ones((n, n_act), dtype=bool), np.zeros(n, dtype=int), np.ones(n), r_base.copy()))
    U, s, Vt = np.linalg.svd(base_map, full_matrices=True)  # (N,6,6), (N,k), (N,m,m); k = min(6, m)
    kept = s > s[:, :1] / COND_MAX  # round-off (a two-feet stance's sixth value: 1e-17 of the first) and worse
    rank = kept.sum(axis=1)
    inv = np.where(kept, 1.0 / np.where(kept, s, 1.0), 0.0)
    k = s.shape[1]
    force = np.einsum("nji,nj,nkj,nk->ni", Vt[:, :k], inv, U[:, :, :k], r_base)  # V diag(1/s) U^T r_b
    tau = r_joint - np.einsum("nai,ni->na", joint_map, force)
    residual = r_base - np.einsum("nbi,ni->nb", base_map, force)
    # the null basis: the rows of Vt past the rank (rows k..m-1 always; rows rank..k-1 where a kept is False)
    null = np.concatenate([Vt[:, :k] * ~kept[..., None], Vt[:, k:]], axis=1)  # (N, m, m): zero rows are not null
    leak = np.linalg.norm(np.einsum("nai,nri->nar", joint_map, null), axis=2)
    cond = s[:, 0] / np.take_along_axis(s, np.maximum(rank - 1, 0)[:, None], axis=1)[:, 0]
    determined = leak <= LEAK_TOL
    return tau, force, Determination(determined, m - rank, cond, residual)


def joint_torques(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray, contact: np.ndarray,
                  foot_force: np.ndarray | None = None, progress: Progress | None = None) -> ContactSolution:
    """The actuated joints' torques the measured motion needs, where the contacts leave them determined (module
    docstring).

    Args:
        robot: the robot (its :attr:`~wbfriction.model.robot.Robot.contact_kinds`).
        q: configurations (N, nq), the base pose included; v: velocities (N, nv), the base twist in the base frame;
            a: accelerations (N, nv), the base's measured (Pinocchio's free-flyer ``a[:6]``).
        contact: contact flags (N, n_contacts).
        foot_force: measured forces of point feet (N, n_contacts, 3), world axes [N], NaN where not measured
            (:mod:`wbfriction.logs.foot_forces`), or None. A foot in contact has its finite components as known
            forces; a foot off the ground none.
        progress: optional callable receiving numbers of samples done.

    Returns:
        :class:`ContactSolution`.
    """
    model = robot.model
    data = model.createData()
    n, iv = len(q), robot.act_v_index
    measured = measured_components(robot, foot_force)  # a foot's components: all rows or none
    dims = robot.contact_dims
    r = np.empty((n, model.nv))
    patterns, pattern_of = np.unique(contact.astype(bool), axis=0, return_inverse=True)
    pattern_of = pattern_of.ravel()
    sizes = [sum(dims[c] - int(measured[c].sum()) for c in np.flatnonzero(p)) for p in patterns]
    m_max = max(sizes, default=0)
    J_u = np.zeros((n, m_max, model.nv))
    for k in range(n):
        r[k] = pin.rnea(model, data, q[k], v[k], a[k])
        active = np.flatnonzero(patterns[pattern_of[k]])
        if not active.size:
            continue
        pin.computeJointJacobians(model, data, q[k])
        pin.updateFramePlacements(model, data)
        row = 0
        for c in active:
            free = ~measured[c] if robot.contact_models[c].world_force else np.ones(dims[c], dtype=bool)
            J_u[k, row:row + int(free.sum())] = contact_jacobian(robot, data, int(c))[free]
            row += int(free.sum())
    r -= foot_force_torques(robot, q, contact, foot_force)
    tau = np.full((n, robot.n_act), np.nan)
    force = np.full((n, m_max), np.nan)
    det = Determination(np.zeros((n, robot.n_act), dtype=bool), np.zeros(n, dtype=int), np.full(n, np.nan),
                        np.full((n, 6), np.nan))
    for p, size in enumerate(sizes):
        rows = np.flatnonzero(pattern_of == p)
        Jt = np.swapaxes(J_u[rows, :size], 1, 2)  # (N, nv, m)
        t, f, d = determine(Jt[:, :6], Jt[:, iv], r[rows, :6], r[rows][:, iv])
        tau[rows] = np.where(d.determined, t, np.nan)
        force[rows, :size] = f
        det.determined[rows], det.nullity[rows], det.cond[rows], det.residual[rows] = (
            d.determined, d.nullity, d.cond, d.residual)
        if progress is not None:
            progress(len(rows))
    return ContactSolution(tau, force, det)


def free_rows(robot: Robot, contact: np.ndarray, foot_force: np.ndarray | None = None) -> np.ndarray:
    """(N, n_tc) the torque-controlled joints whose own row of the equations of motion holds no unknown contact
    force: no foot on the ground on their limb (:attr:`~wbfriction.model.robot.Robot.limb_mask`), or only feet whose
    three force components are measured. Such a row needs neither the base's rows nor the rank decision: the
    momentum route takes it as it is (:mod:`wbfriction.friction.momentum`)."""
    measured = measured_components(robot, foot_force)
    unknown = contact.astype(bool) & ~measured.all(axis=1)  # (N, n_contacts): on the ground, force not all measured
    return ~((unknown.astype(float) @ robot.limb_mask.astype(float)) > 0)


def foot_force_torques(robot: Robot, q: np.ndarray, contact: np.ndarray, foot_force: np.ndarray | None
                       ) -> np.ndarray:
    """``sum_c J_c^T f_c`` (N, nv) [N·m] over the feet on the ground and their measured force components (world axes,
    :func:`contact_jacobian`), zero without foot forces: the measured forces' generalized torque."""
    out = np.zeros((len(q), robot.model.nv))
    if foot_force is None:
        return out
    measured = measured_components(robot, foot_force)
    data = robot.model.createData()
    for k in np.flatnonzero(np.any(contact.astype(bool) & measured.any(axis=1), axis=1)):
        pin.computeJointJacobians(robot.model, data, q[k])
        pin.updateFramePlacements(robot.model, data)
        for c in np.flatnonzero(contact[k]):
            if measured[c].any():
                J = contact_jacobian(robot, data, int(c))
                out[k] += J[measured[c]].T @ foot_force[k, c, measured[c]]
    return out


def determination(robot: Robot, q: np.ndarray, contact: np.ndarray, foot_force: np.ndarray | None = None
                  ) -> Determination:
    """The rank decision alone (module docstring) at configurations ``q`` (N, nq) with the feet ``contact``
    (N, n_contacts) down and the ``foot_force`` components measured: it depends on the contact Jacobians only
    (:func:`joint_torques` at rest; its residual is then meaningless)."""
    zeros = np.zeros((len(q), robot.model.nv))
    return joint_torques(robot, q, zeros, zeros, contact, foot_force).determination
