"""The generalized momentum of a tree and its rate of change without friction (issue 38).

On a tree with configuration ``q`` and velocity ``v`` (Pinocchio's conventions), the generalized momentum
is ``p = M(q) v`` and, since ``dM/dt = C + C^T``, the equation of motion
``M qdd + C(q, v) v + g(q) = S^T (tau + tau_f) + sum_e J_e^T f_e`` reads

.. math::

    \\dot p = S^T (\\tau + \\tau_f) + C(q, v)^T v - g(q) + \\sum_e J_e^T f_e ,

with no acceleration in it: the friction's impulse over a step is ``Delta p`` less the integral of the
other terms (De Luca and Mattone's momentum residual: A. De Luca, R. Mattone, "Actuator failure detection
and isolation using generalized momenta", IEEE ICRA 2003; M. Gautier's energy model of identification is
the same integral taken along ``v``). Each row holds on its own: a row whose joint torque is unknown (a
position-controlled joint) is simply not used.

:func:`momentum_and_drift` computes ``p``, ``b = C^T v - g`` and ``e = sum_e J_e^T f_e`` per sample with
Pinocchio (``crba``, ``computeCoriolisMatrix``, ``computeGeneralizedGravity``; the external wrenches through
``rnea`` with ``fext`` at rest, ``rnea(q, 0, 0, fext) = g - sum J^T f``). ``e`` is apart from ``b`` because a
sensor's wrench is read as the torques are (held over a period, or at the instants) and is integrated as they
are, where ``b`` is a smooth function of the state.

On a fixed-base tree of 1-DoF joints without external forces, :func:`tree_momentum_and_drift` gives ``p`` and
``b`` for all samples at once, in O(n) per sample: with ``H_i`` the spatial momentum of the subtree carried by
joint ``i`` and ``F_i`` its weight at rest (both in joint ``i``'s frame), ``p_i = S_i^T H_i`` (+ armature) and,
since the axis ``S_i`` turns with the body's twist ``v_i`` (``dS_i/dt = v_i x S_i``),

.. math::

    \\dot p_i = S_i^T \\dot H_i + (v_i \\times S_i)^T H_i
             = \\tau_i + \\tau_{f,i} - g_i - S_i^T (v_i \\times^* H_i),
    \\qquad b_i = (C^T v - g)_i = -S_i^T (v_i \\times^* H_i + F_i)

(Featherstone's spatial algebra, ``(v x m)^T f = -m^T (v x* f)``; ``g_i = S_i^T F_i``, ``rnea(q, 0, 0)``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import ModelError
from wbfriction.progress import Progress


def momentum_and_drift(model: pin.Model, q: np.ndarray, v: np.ndarray, rows: np.ndarray | None = None,
                       fext: Callable[[int], list] | None = None, gravity: np.ndarray | None = None,
                       progress: Progress | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``p = M(q) v``, ``b = C(q, v)^T v - g(q)`` and ``e = sum_e J_e^T f_e`` (module docstring) of each sample.

    Args:
        model: the tree (its armature is in ``M``: ``crba`` includes it).
        q: configurations (N, nq); v: velocities (N, nv).
        rows: the rows (M,) of ``rows`` of ``v`` (default all) to compute; the others are NaN.
        fext: the external forces of sample ``k`` as Pinocchio's per-joint list (joint frames), or None
            (no external force on the tree).
        gravity: the gravity vector of each sample (N, 3) [m/s²] in the tree's root frame, or None (the
            model's own): a welded foot that is not flat sees gravity tilted.
        progress: optional callable receiving numbers of samples done.

    Returns:
        ``(p, b, e)``, (N, nv) each: [kg·m²/s or kg·m/s], [N·m or N], [N·m or N] in the rows of ``v``; ``e`` zero
        without ``fext``.
    """
    n = len(q)
    p, b, e = (np.full((n, model.nv), np.nan) for _ in range(3))
    if gravity is not None:
        model = pin.Model(model)  # a copy whose gravity changes sample by sample
    data = model.createData()
    zero = np.zeros(model.nv)
    todo = np.arange(n) if rows is None else np.asarray(rows)
    for count, k in enumerate(todo, 1):
        if gravity is not None:
            model.gravity = pin.Motion(gravity[k], np.zeros(3))
        p[k] = pin.crba(model, data, q[k]) @ v[k]  # Pinocchio 4: both triangles filled
        C = pin.computeCoriolisMatrix(model, data, q[k], v[k])
        g = pin.computeGeneralizedGravity(model, data, q[k])
        b[k] = C.T @ v[k] - g
        # rnea at rest with the external forces: g - sum J^T f
        e[k] = 0.0 if fext is None else g - pin.rnea(model, data, q[k], zero, zero, fext(k))
        if progress is not None and count % 1024 == 0:
            progress(1024)
    if progress is not None and len(todo) % 1024:
        progress(len(todo) % 1024)
    return p, b, e


@dataclass(frozen=True)
class _Joint:
    """One 1-DoF joint of a tree: its parent's index (0: the fixed root), placement in the parent (R0 (3, 3),
    p0 (3,)), axis (linear part, angular part; (3,) each), the body it carries (mass [kg], centre of mass
    (3,) [m] and rotational inertia about it (3, 3) [kg m^2], in the joint's frame), its armature and its
    configuration and velocity indices (``nq`` 2: a continuous joint's (cos, sin))."""

    parent: int
    R0: np.ndarray
    p0: np.ndarray
    lin: np.ndarray
    ang: np.ndarray
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    armature: float
    iq: int
    nq: int
    iv: int


def _joints(model: pin.Model) -> list[_Joint]:
    """The joints of a fixed-base tree of 1-DoF joints (:class:`_Joint`), in Pinocchio's order.

    Raises:
        ModelError: a joint with more than one velocity, or one whose motion is a screw (helical).
    """
    out = []
    data = model.createData()
    # each joint's motion subspace: its own column of its Jacobian in its frame (standard calls that return copies;
    # the same bytes as a JointData's S on every built-in robot, without a JointData per joint)
    pin.computeJointJacobians(model, data, pin.neutral(model))
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv != 1:
            raise ModelError(f"joint '{model.names[j]}' has {joint.nv} velocities: a tree of 1-DoF joints is needed")
        S = pin.getJointJacobian(model, data, j, pin.LOCAL)[:, joint.idx_v].copy()
        if np.any(S[:3]) and np.any(S[3:]):
            raise ModelError(f"joint '{model.names[j]}' is helical: not supported")
        M, Y = model.jointPlacements[j], model.inertias[j]
        out.append(_Joint(model.parents[j], M.rotation.copy(), M.translation.copy(), S[:3].copy(), S[3:].copy(),
                          Y.mass, Y.lever.copy(), Y.inertia.copy(), float(model.armature[joint.idx_v]),
                          joint.idx_q, joint.nq, joint.idx_v))
    return out


def _skew(x: np.ndarray) -> np.ndarray:
    """The matrix (3, 3) of ``y -> x × y``."""
    return np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]], [-x[1], x[0], 0.0]])


def _placement(jt: _Joint, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rotation (3, 3, N) and origin (3, N) or (3, 1) of the joint's frame in its parent's at positions ``x``
    (N,) [rad or m], component first: its placement times the joint's motion (Rodrigues's formula for a
    revolute joint)."""
    if np.any(jt.ang):
        K = _skew(jt.ang)
        RK, RKK = (jt.R0 @ K)[..., None], (jt.R0 @ K @ K)[..., None]
        return jt.R0[..., None] + np.sin(x) * RK + (1.0 - np.cos(x)) * RKK, jt.p0[:, None]
    return np.broadcast_to(jt.R0[..., None], (3, 3, len(x))), jt.p0[:, None] + (jt.R0 @ jt.lin)[:, None] * x


BLOCK = 4096
"""Samples :func:`tree_momentum_and_drift` takes at once: its arrays, about 8 kB a sample on a humanoid, stay
near 35 MB however long the stretch."""


def tree_momentum_and_drift(model: pin.Model, q: np.ndarray, v: np.ndarray,
                            gravity: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``p = M(q) v`` and ``b = C(q, v)^T v - g(q)`` (module docstring) of a fixed-base tree of 1-DoF joints,
    batched: one pass over the joints, each on all the samples at once.

    Args:
        model: the tree (revolute, prismatic and continuous joints; its armature is in ``M``).
        q: configurations (N, nq); v: velocities (N, nv).
        gravity: the gravity vector of each sample (N, 3) [m/s²] in the root frame, or None (the model's own).

    Returns:
        ``(p, b)``, (N, nv) each: [kg·m²/s or kg·m/s], [N·m or N]; as :func:`momentum_and_drift` to rounding.

    Raises:
        ModelError: a joint that is not a 1-DoF revolute or prismatic joint.
    """
    joints = _joints(model)
    p, b = np.empty((len(q), model.nv)), np.empty((len(q), model.nv))
    for start in range(0, len(q), BLOCK):
        sl = slice(start, start + BLOCK)
        p[sl], b[sl] = _tree_block(model, joints, q[sl], v[sl], None if gravity is None else gravity[sl])
    return p, b


def _tree_block(model: pin.Model, joints: list[_Joint], q: np.ndarray, v: np.ndarray,
                gravity: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`tree_momentum_and_drift` of a block of samples, the tree's :func:`_joints` given."""
    n = len(q)
    q, v = q.T, np.ascontiguousarray(v.T)  # component first below: (3, ..., N)
    g = np.broadcast_to(model.gravity.linear[:, None] if gravity is None else gravity.T, (3, n))
    # forward: each body's rotation R and origin p in its parent's frame and, in its own frame, its twist (linear
    # u, angular w) and the acceleration at rest that stands for gravity (-g, linear only): motion[j] = (u, w, a)
    R: list[np.ndarray] = []
    pos: list[np.ndarray] = []
    motion: list[np.ndarray] = []
    root = np.zeros((3, 3, n))
    root[:, 2] = -g
    for jt in joints:
        Rj, pj = _placement(jt, q[jt.iq] if jt.nq == 1 else np.arctan2(q[jt.iq + 1], q[jt.iq]))
        par = (root if jt.parent == 0 else motion[jt.parent - 1]).copy()
        par[:, 0] -= _cross(pj, par[:, 1])
        mine = Rj[0, :, None] * par[0] + Rj[1, :, None] * par[1] + Rj[2, :, None] * par[2]  # R^T par
        mine[:, 0] += jt.lin[:, None] * v[jt.iv]
        mine[:, 1] += jt.ang[:, None] * v[jt.iv]
        R.append(Rj)
        pos.append(pj)
        motion.append(mine)
    # backward: the subtree's momentum H and weight F at rest, in each joint's frame: load[j] = (H_lin, H_ang,
    # F_lin, F_ang); the body's own: h = I v (Pinocchio's lever form), f = I a
    load = np.zeros((len(joints), 3, 4, n))
    p, b = np.zeros((model.nv, n)), np.zeros((model.nv, n))
    for j in range(len(joints) - 1, -1, -1):
        jt, (u, w, a) = joints[j], motion[j].transpose(1, 0, 2)
        C = _skew(jt.com)
        mine = load[j]
        h_lin, f_lin = jt.mass * (u - C @ w), jt.mass * a
        mine[:, 0] += h_lin
        mine[:, 1] += jt.inertia @ w + C @ h_lin
        mine[:, 2] += f_lin
        mine[:, 3] += C @ f_lin
        H_lin, H_ang, F_lin, F_ang = mine.transpose(1, 0, 2)
        p[jt.iv] = jt.lin @ H_lin + jt.ang @ H_ang + jt.armature * v[jt.iv]
        turn = _cross(w[:, None], mine[:, :2])  # v x* H = (w x H_lin, w x H_ang + u x H_lin)
        b[jt.iv] = -(jt.lin @ (turn[:, 0] + F_lin) + jt.ang @ (turn[:, 1] + _cross(u, H_lin) + F_ang))
        if jt.parent > 0:
            Rj = R[j]
            moved = Rj[:, 0, None] * mine[0] + Rj[:, 1, None] * mine[1] + Rj[:, 2, None] * mine[2]  # R load
            moved[:, 1::2] += _cross(pos[j][:, None], moved[:, 0::2])
            load[jt.parent - 1] += moved
    return p.T, b.T


def _cross(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``x × y`` along the first axis (3, ...), broadcast."""
    return np.stack([x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]])
