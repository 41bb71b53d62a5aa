"""The walking reference's faster whole-body IK (issue 41) gives the reference of the route it replaced, bit for bit.

The previous route is written out here as it was (:func:`previous_motion`): per Newton iteration, the task
Jacobian and error assembled from Pinocchio's getters into fresh slices, products by ``@``, the step by
``np.linalg.solve``, then ``np.linalg.inv`` for the velocity and the acceleration, and the next sample started
from ``q + v dt + a dt^2 / 2``. It runs on the targets the reference records (feet, centre of mass, ZMP, the
prescribed joints, which the IK copies as they are), and every array is compared with ``np.array_equal``. No
test here is timed: ``benchmarks/bench_simulate.py`` measures the speed."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.model.robot import Robot
from wbfriction.walking import GaitOptions, WalkingReference, standing_configuration, walking_reference
from wbfriction.walking.com import lipm_com
from wbfriction.walking.indexing import as_slice
from wbfriction.walking.reference import yaw_rotations
from wbfriction.walking.swing import feet_trajectory

LWA = pin.LOCAL_WORLD_ALIGNED
DT = 1e-3


def _rates(feet: np.ndarray, com: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Task rates (N, 18) in the IK's row order: per sole x, y, z and the yaw rate; the CoM's x, y (z at rest);
    the base's yaw rate."""
    x = np.zeros((len(com), 18))
    for i in range(2):
        x[:, 6 * i:6 * i + 3] = feet[:, i, :3]
        x[:, 6 * i + 5] = feet[:, i, 3]
    x[:, 12:14] = com
    x[:, 17] = yaw
    return x


def previous_motion(robot: Robot, ref: WalkingReference, tol: float = 1e-11
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Configurations (N, nq), velocities and accelerations (N, nv) of the walk ``ref`` plans, by the IK route
    before issue 41 (module docstring)."""
    model, data, n = robot.model, robot.model.createData(), len(ref)
    legs = sorted({robot.actuated.index(j) for f in robot.contact_frames for j in robot.limb(f)})
    free = [i for i in range(robot.n_act) if i not in legs]
    sel = as_slice(np.concatenate([np.arange(6), robot.act_v_index[legs]]))  # views where consecutive, as before
    rest, iq_free = as_slice(robot.act_v_index[free]), as_slice(robot.act_q_index[free])
    feet, feet_d, feet_dd = feet_trajectory(ref.plan, ref.time)
    _, cd, cdd = lipm_com(ref.zmp, DT, ref.com[0, 2])
    yaw = [x[:, :, 3].mean(1) for x in (feet, feet_d, feet_dd)]
    sole_R, base_R = yaw_rotations(feet[:, :, 3]), yaw_rotations(yaw[0])
    xd, xdd = _rates(feet_d, cd, yaw[1]), _rates(feet_dd, cdd, yaw[2])
    free_q, free_qd, free_qdd = ref.q[:, iq_free], ref.v[:, rest], ref.a[:, rest]
    J, e = np.empty((18, model.nv)), np.empty(18)
    Q, V, A = np.empty((n, model.nq)), np.empty((n, model.nv)), np.empty((n, model.nv))
    q, v, a = standing_configuration(robot), np.zeros(model.nv), np.zeros(model.nv)
    for k in range(n):
        q = pin.integrate(model, q, v * DT + 0.5 * a * DT**2)
        q[iq_free] = free_q[k]
        for _ in range(20):
            pin.computeJointJacobians(model, data, q)
            for i, f in enumerate(robot.contact_frame_ids):
                J[6 * i:6 * i + 6] = pin.getFrameJacobian(model, data, f, LWA)
            J[12:15] = pin.jacobianCenterOfMass(model, data, True)
            J[15:18] = pin.getJointJacobian(model, data, 1, LWA)[3:]
            for i, f in enumerate(robot.contact_frame_ids):
                M = data.oMf[f]
                e[6 * i:6 * i + 3] = feet[k, i, :3] - M.translation
                e[6 * i + 3:6 * i + 6] = pin.log3(sole_R[k, i] @ M.rotation.T)
            e[12:15] = ref.com[k] - data.com[0]
            e[15:18] = pin.log3(base_R[k] @ data.oMi[1].rotation.T)
            if abs(e).max() < tol:
                break
            dv = np.zeros(model.nv)
            dv[sel] = np.linalg.solve(J[:, sel], e)
            q = pin.integrate(model, q, dv)
        Js_inv, Jr = np.linalg.inv(J[:, sel]), J[:, rest]
        v, a = np.zeros(model.nv), np.zeros(model.nv)
        v[rest] = free_qd[k]
        v[sel] = Js_inv @ (xd[k] - Jr @ free_qd[k])
        pin.centerOfMass(model, data, q, v, np.zeros(model.nv))
        drift = np.zeros(18)
        for i, f in enumerate(robot.contact_frame_ids):
            drift[6 * i:6 * i + 6] = pin.getFrameClassicalAcceleration(model, data, f, LWA).vector
        drift[12:15] = data.acom[0]
        a[rest] = free_qdd[k]
        a[sel] = Js_inv @ (xdd[k] - drift - Jr @ free_qdd[k])
        Q[k], V[k], A[k] = q, v, a
    return Q, V, A


@pytest.mark.parametrize("robot", ["talos", "toro"])
def test_reference_is_the_previous_route_bit_for_bit(robot, request):
    """A combined walk (forward, sideways, turning both ways; single and double support, the position-controlled
    joints' sine) on both humanoids: q, v and a equal the previous route's, array by array."""
    r = request.getfixturevalue(robot)
    ref = walking_reference(r, GaitOptions(gait="combined", steps=2), DT)
    for name, before in zip("qva", previous_motion(r, ref)):
        assert np.array_equal(getattr(ref, name), before), name
