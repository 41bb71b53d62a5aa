"""The base's twist and acceleration from its pose, on SO(3): analytic motions, both quaternion signs."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.signals.base_motion import base_twist_and_acceleration, continuous_quaternions


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions (N, 4) in (x, y, z, w) order."""
    av, aw, bv, bw = a[:, :3], a[:, 3:], b[:, :3], b[:, 3:]
    return np.hstack([aw * bv + bw * av + np.cross(av, bv), aw * bw - np.einsum("ij,ij->i", av, bv)[:, None]])


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_a_rotation_about_a_body_axis_gives_its_rate_and_acceleration(seed):
    """R(t) = R0 exp(theta(t) u): omega = theta' u and omega' = theta'' u in the base frame, with the pose's
    exact derivatives; the linear part from p(t) = p0 + c t^2 / 2: v = R^T p', a = R^T p'' - omega x v."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2, 50)
    u = rng.normal(size=3)
    u /= np.linalg.norm(u)
    A, w = rng.uniform(0.2, 2.0), rng.uniform(0.5, 5.0)
    th, thd, thdd = A * np.sin(w * t), A * w * np.cos(w * t), -A * w * w * np.sin(w * t)
    q0 = pin.Quaternion(pin.exp3(rng.normal(size=3))).coeffs()[None].repeat(len(t), 0)
    s, c = np.sin(th / 2)[:, None], np.cos(th / 2)[:, None]
    e = np.hstack([u * s, c])
    ed = np.hstack([u * c, -s]) * (thd / 2)[:, None]
    edd = np.hstack([u * c, -s]) * (thdd / 2)[:, None] + np.hstack([-u * s, -c]) * ((thd / 2) ** 2)[:, None]
    quat, quat_d, quat_dd = _quat_mul(q0, e), _quat_mul(q0, ed), _quat_mul(q0, edd)
    cvec = rng.normal(size=3)
    p, pd, pdd = cvec * (t**2 / 2)[:, None], cvec * t[:, None], np.tile(cvec, (len(t), 1))
    v, a = base_twist_and_acceleration(np.hstack([p, quat]), np.hstack([pd, quat_d]), np.hstack([pdd, quat_dd]))
    np.testing.assert_allclose(v[:, 3:], thd[:, None] * u, atol=1e-12)
    np.testing.assert_allclose(a[:, 3:], thdd[:, None] * u, atol=1e-12)
    R = np.array([pin.Quaternion(*np.roll(qk, 1)).toRotationMatrix() for qk in quat])  # Quaternion(w, x, y, z)
    v_lin = np.einsum("nji,nj->ni", R, pd)
    np.testing.assert_allclose(v[:, :3], v_lin, atol=1e-12)
    np.testing.assert_allclose(a[:, :3], np.einsum("nji,nj->ni", R, pdd) - np.cross(v[:, 3:], v_lin), atol=1e-12)


def test_quaternion_signs_are_made_continuous():
    rng = np.random.default_rng(3)
    angles = np.linspace(0, 3, 200)
    quat = np.array([pin.Quaternion(pin.exp3(np.array([0.3, -0.2, 1.0]) * th)).coeffs() for th in angles])
    flipped = quat * np.where(rng.random(len(quat)) < 0.5, -1.0, 1.0)[:, None]
    base = np.hstack([np.zeros((len(quat), 3)), flipped])
    out = continuous_quaternions(base)
    assert np.all(np.einsum("ij,ij->i", out[1:, 3:], out[:-1, 3:]) > 0)
    assert np.allclose(np.abs(np.einsum("ij,ij->i", out[:, 3:], quat)), 1.0)
    assert np.shares_memory(out, base) is False
