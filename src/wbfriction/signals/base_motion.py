"""The floating base's twist and acceleration from its logged pose, differentiated on SO(3).

The base pose ``(x, y, z, qx, qy, qz, qw)`` is differentiated with the joints' scheme and filter
(:func:`~wbfriction.signals.kinematics.measure` passes its seven columns through the same path as
the joint positions), the quaternion's four components made sign-continuous first (``q`` and
``-q`` are one rotation). No Euler angles: with ``R`` the base orientation (base to world) and
``q̄`` the conjugate quaternion, ``q̇ = 1/2 q ⊗ (0, ω)`` gives

.. math::

    \\omega = 2\\,\\mathrm{vec}(\\bar q \\otimes \\dot q) / |q|^2, \\qquad
    \\dot\\omega = 2\\,\\mathrm{vec}(\\bar q \\otimes \\ddot q) / |q|^2

(the scalar ``|q̇|^2`` of ``d/dt(q̄) ⊗ q̇`` has no vector part), exact for any smooth unit quaternion;
dividing by ``|q|^2`` undoes the few 1e-6 a filter takes off the norm. The result is Pinocchio's
free-flyer velocity and acceleration, in the base frame:

.. math:: v = (R^T \\dot p, \\omega), \\qquad a = (R^T \\ddot p - \\omega \\times R^T \\dot p, \\dot\\omega).
"""

from __future__ import annotations

import numpy as np


def continuous_quaternions(base: np.ndarray) -> np.ndarray:
    """``base`` (N, 7) with each quaternion's sign chosen to continue the previous one's (a copy):
    the components then vary smoothly and can be differentiated."""
    out = np.array(base, dtype=float)
    flips = np.einsum("ij,ij->i", out[1:, 3:], out[:-1, 3:]) < 0
    sign = np.where(np.concatenate([[False], np.cumsum(flips) % 2 == 1]), -1.0, 1.0)
    out[:, 3:] *= sign[:, None]
    return out


def _conjugate_product(q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The vector part of ``q̄ ⊗ p`` for quaternions (N, 4) in (x, y, z, w) order, (N, 3)."""
    qv, qw, pv, pw = q[:, :3], q[:, 3:], p[:, :3], p[:, 3:]
    return qw * pv - pw * qv - np.cross(qv, pv)


def base_twist_and_acceleration(base: np.ndarray, base_d: np.ndarray, base_dd: np.ndarray
                                ) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's free-flyer velocity and acceleration (module docstring) from the base pose and its
    first and second time derivatives, component-wise.

    Args:
        base: poses (N, 7) (position [m], quaternion x, y, z, w), sign-continuous
            (:func:`continuous_quaternions`), possibly filtered (not exactly unit).
        base_d, base_dd: their derivatives (N, 7) [per s, per s^2].

    Returns:
        ``(v, a)``: (N, 6) each, base frame: ``v`` [m/s, rad/s], ``a`` [m/s^2, rad/s^2]; NaN where an
        input is.
    """
    quat = base[:, 3:]
    norm2 = np.einsum("ij,ij->i", quat, quat)[:, None]
    R = _rotation_matrices(quat / np.sqrt(norm2))
    omega = 2.0 * _conjugate_product(quat, base_d[:, 3:]) / norm2
    omega_d = 2.0 * _conjugate_product(quat, base_dd[:, 3:]) / norm2
    v_lin = np.einsum("nji,nj->ni", R, base_d[:, :3])
    a_lin = np.einsum("nji,nj->ni", R, base_dd[:, :3]) - np.cross(omega, v_lin)
    return np.hstack([v_lin, omega]), np.hstack([a_lin, omega_d])


def _rotation_matrices(quat: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) of unit quaternions (N, 4) in (x, y, z, w) order."""
    x, y, z, w = quat.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=-2)
