"""How joint angles map to a Pinocchio configuration vector (revolute, prismatic and continuous joints), and the one
number a continuous joint's angle is written as (:func:`principal_angle`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin


def principal_angle(q: np.ndarray | float) -> np.ndarray:
    """Angles ``q`` [rad] (any shape) reduced modulo 2π into (−π, π]: the one number of a continuous joint's physical
    angle (its configuration is (cos q, sin q)), whatever branch a log held it on; an angle already in (−π, π] is
    returned exactly."""
    q = np.asarray(q, dtype=float)
    return q - 2.0 * np.pi * np.ceil((q - np.pi) / (2.0 * np.pi))


@dataclass(frozen=True)
class JointLayout:
    """How joint angles map to a Pinocchio configuration vector of a given model.

    Single-coordinate joints (revolute, prismatic) take the angle itself; continuous
    joints (unbounded revolute, nq = 2) take (cos, sin). ``sign`` flips a joint's
    direction (used for the re-rooted models of :mod:`wbfriction.model.rerooted`).
    """

    nq: int
    q1_index: np.ndarray  # configuration index of each single-coordinate joint
    q1_joint: np.ndarray  # its position in the angle vector
    q2_index: np.ndarray  # configuration index (cos) of each continuous joint
    q2_joint: np.ndarray
    root_nq: int

    def configuration(self, angles: np.ndarray, base: np.ndarray | None = None,
                      sign: np.ndarray | None = None) -> np.ndarray:
        a = np.asarray(angles, dtype=float)
        single = a.ndim == 1
        a = np.atleast_2d(a)
        if sign is not None:
            a = a * sign
        q = np.zeros((a.shape[0], self.nq))
        if self.root_nq == 7:
            q[:, 6] = 1.0
            if base is not None:
                q[:, :7] = np.atleast_2d(base)
        q[:, self.q1_index] = a[:, self.q1_joint]
        q[:, self.q2_index] = np.cos(a[:, self.q2_joint])
        q[:, self.q2_index + 1] = np.sin(a[:, self.q2_joint])
        return q[0] if single else q

    def principal(self, angles: np.ndarray) -> np.ndarray:
        """Joint angles (n,) or (N, n) [rad] with every continuous joint's reduced into (−π, π]
        (:func:`principal_angle`; the others as given): one number per configuration."""
        a = np.array(angles, dtype=float)
        if len(self.q2_joint):
            a[..., self.q2_joint] = principal_angle(a[..., self.q2_joint])
        return a

    def unwrap(self, angles: np.ndarray) -> np.ndarray:
        """Joint angles (N, n) [rad] of consecutive samples with every continuous joint's column unwrapped: a step of
        more than π between two rows is a wrap, and the angle continues by whole turns from the first row's; the
        others as given (``angles`` itself without a continuous joint). The first row's branch is the log's (its
        convention, (−π, π] or [0, 2π), and where its window starts): what is a function of the angle reduces it
        (:meth:`principal`); the differences, from which the clock, the noise and the derivatives are decided, are
        the motion's."""
        if not len(self.q2_joint):
            return angles
        out = np.array(angles, dtype=float)
        out[:, self.q2_joint] = np.unwrap(out[:, self.q2_joint], axis=0)
        return out

    def angles(self, q: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`configuration` (without sign): joint positions from configurations."""
        q = np.asarray(q, dtype=float)
        single = q.ndim == 1
        q = np.atleast_2d(q)
        n_joints = len(self.q1_joint) + len(self.q2_joint)
        a = np.empty((q.shape[0], n_joints))
        a[:, self.q1_joint] = q[:, self.q1_index]
        a[:, self.q2_joint] = np.arctan2(q[:, self.q2_index + 1], q[:, self.q2_index])
        return a[0] if single else a


def joint_layout(model: pin.Model, joints: tuple[str, ...]) -> JointLayout:
    """The :class:`JointLayout` of the joints named ``joints`` (in that order) in ``model``."""
    q1_index, q1_joint, q2_index, q2_joint = [], [], [], []
    for k, name in enumerate(joints):
        jid = model.getJointId(name)
        if model.nqs[jid] == 1:
            q1_index.append(model.idx_qs[jid])
            q1_joint.append(k)
        else:
            q2_index.append(model.idx_qs[jid])
            q2_joint.append(k)
    root_nq = model.nqs[1] if model.njoints > 1 else 0
    as_int = lambda x: np.array(x, dtype=int)  # noqa: E731
    return JointLayout(model.nq, as_int(q1_index), as_int(q1_joint), as_int(q2_index), as_int(q2_joint), root_nq)
