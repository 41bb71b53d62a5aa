"""Quintic swing-foot trajectories with a set lift height.

Horizontal position and yaw follow a quintic from the start to the target footprint
with zero velocity and acceleration at both ends; the height rises along a quintic to
``lift_height`` at mid-swing and falls along a quintic back to the ground, so the foot
leaves and lands with zero velocity and acceleration.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from wbfriction.walking.footsteps import FootstepPlan


def foot_placement(pose: np.ndarray) -> pin.SE3:
    """A sole placement from a planned pose (x, y, z [m], yaw [rad]): flat, heading ``yaw``."""
    c, s = np.cos(pose[3]), np.sin(pose[3])
    return pin.SE3(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), np.array(pose[:3], dtype=float))


def quintic(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Smooth step ``10 s^3 - 15 s^4 + 6 s^5`` on [0, 1] (clipped outside), with its first and
    second derivatives with respect to ``s``."""
    s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
    return (s**3 * (10 - 15 * s + 6 * s**2), 30 * s**2 * (1 - s) ** 2, 60 * s * (1 - s) * (1 - 2 * s))


def feet_trajectory(plan: FootstepPlan, time: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Planned planar-plus-height motion of both feet.

    Args:
        plan: a :class:`~wbfriction.walking.footsteps.FootstepPlan`.
        time: sample times (N,) [s].

    Returns:
        pose, velocity, acceleration, each (N, 2, 4): per foot x, y, z [m] and yaw [rad],
        in the world frame (z = 0 on the ground), and their time derivatives.
    """
    time = np.asarray(time, dtype=float)
    n = len(time)
    pose = np.zeros((n, 2, 4))
    vel = np.zeros((n, 2, 4))
    acc = np.zeros((n, 2, 4))
    for foot in range(2):
        pose[:, foot, [0, 1, 3]] = plan.initial_feet[foot]
    h = plan.options.lift_height
    for st in plan.steps:
        T = st.touch_down - st.lift_off
        after = time >= st.touch_down
        pose[after, st.foot, :] = [st.target[0], st.target[1], 0.0, st.target[2]]
        during = (time >= st.lift_off) & (time < st.touch_down)
        s = (time[during] - st.lift_off) / T
        x, dx, ddx = quintic(s)
        delta = np.array([st.target[0] - st.start[0], st.target[1] - st.start[1], 0.0,
                          st.target[2] - st.start[2]])
        start = np.array([st.start[0], st.start[1], 0.0, st.start[2]])
        pose[during, st.foot] = start + x[:, None] * delta
        vel[during, st.foot] = (dx / T)[:, None] * delta
        acc[during, st.foot] = (ddx / T**2)[:, None] * delta
        up = s < 0.5
        z, dz, ddz = quintic(np.where(up, 2 * s, 2 - 2 * s))
        sign = np.where(up, 1.0, -1.0)
        pose[during, st.foot, 2] = h * z
        vel[during, st.foot, 2] = h * sign * dz * 2 / T
        acc[during, st.foot, 2] = h * ddz * 4 / T**2
    return pose, vel, acc
