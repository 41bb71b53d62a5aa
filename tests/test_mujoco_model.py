"""The MuJoCo model built from the URDF has Pinocchio's dynamics (issue 5, item 1)."""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from wbfriction.sim.mujoco_model import (
    SOLE_THICKNESS,
    build_mujoco_robot,
    sole_footprint,
)


@pytest.fixture(scope="module")
def mj_talos(talos):
    return build_mujoco_robot(talos)


def _random_state(talos, rng):
    q = talos.configuration(rng.uniform(*talos.angle_limits))
    q[:3] = rng.normal(0, 1, 3)
    q[3:7] = pin.Quaternion(rng.normal(size=4)).normalized().coeffs()
    return q, rng.normal(0, 1, talos.model.nv)


def test_mass_matrix_gravity_and_bias_agree_with_pinocchio(talos, mj_talos):
    """M_pin = T^T M_mj T, g_pin = T^T g_mj and h_pin = T^T (h_mj + M_mj dT/dt v), with T
    mapping Pinocchio's velocities to MuJoCo's, on random states."""
    m, d = mj_talos.model, mujoco.MjData(mj_talos.model)
    data = talos.model.createData()
    rng = np.random.default_rng(0)
    M_mj = np.zeros((m.nv, m.nv))
    for _ in range(5):
        q, v = _random_state(talos, rng)
        T = mj_talos.velocity_map(q)
        d.qpos[:], d.qvel[:] = mj_talos.qpos(q), T @ v
        mujoco.mj_forward(m, d)
        mujoco.mj_fullM(m, d, M_mj)
        M = pin.crba(talos.model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        np.testing.assert_allclose(T.T @ M_mj @ T, M, atol=1e-9)
        g = pin.computeGeneralizedGravity(talos.model, data, q)
        h = pin.nonLinearEffects(talos.model, data, q, v)
        d.qvel[:] = 0
        mujoco.mj_forward(m, d)
        np.testing.assert_allclose(T.T @ d.qfrc_bias, g, atol=1e-8)
        d.qvel[:] = T @ v
        mujoco.mj_forward(m, d)
        # qvel = T v, so qacc = T a + (dT/dt) v with (dT/dt) v = (R (w x v_lin), 0, ...)
        Tdot_v = np.zeros(m.nv)
        Tdot_v[:3] = T[:3, :3] @ np.cross(v[3:6], v[:3])
        np.testing.assert_allclose(T.T @ (d.qfrc_bias + M_mj @ Tdot_v), h, atol=1e-8)
        np.testing.assert_allclose(mj_talos.q(mj_talos.qpos(q)), q, atol=1e-15)


def test_soles_are_boxes_flat_under_the_contact_frames(talos, mj_talos):
    m, d = mj_talos.model, mujoco.MjData(mj_talos.model)
    q = talos.configuration(talos.reference_angles)
    d.qpos[:] = mj_talos.qpos(q)
    mujoco.mj_kinematics(m, d)
    data = talos.model.createData()
    pin.framesForwardKinematics(talos.model, data, q)
    for frame, geom in zip(talos.contact_frames, mj_talos.sole_geoms):
        oMf = data.oMf[talos.model.getFrameId(frame)]
        centre, half = sole_footprint(talos, frame)
        expected = oMf.act(np.array([centre[0], centre[1], SOLE_THICKNESS / 2]))
        np.testing.assert_allclose(d.geom_xpos[geom], expected, atol=1e-12)
        np.testing.assert_allclose(d.geom_xmat[geom].reshape(3, 3), oMf.rotation, atol=1e-12)
        np.testing.assert_allclose(m.geom_size[geom][:2], half)
        assert m.geom_condim[geom] == 4  # torsional friction holds the stance foot's yaw
    # TALOS's foot: about 21 cm by 13 cm
    assert 0.20 < 2 * half[0] < 0.23 and 0.12 < 2 * half[1] < 0.15


def test_urdf_friction_and_damping_are_dropped(mj_talos):
    """TALOS's URDF sets damping and friction on 20 joints: the model must not apply them."""
    assert np.all(mj_talos.model.dof_damping == 0) and np.all(mj_talos.model.dof_frictionloss == 0)


def test_talos_walks_forward_and_sideways_on_mujoco(talos, mj_talos):
    """10 steps forward then 10 sideways on real contacts: no fall, joints on their
    reference, contact flags from the soles' normal forces (they differ from the plan only
    around the switches), true accelerations consistent with the logged velocities."""
    from wbfriction.sim.mujoco_sim import simulate_mujoco
    from wbfriction.walking import GaitOptions, walking_reference

    ref = walking_reference(talos, GaitOptions(gait="both", steps=10))
    res = simulate_mujoco(talos, ref, mjr=mj_talos)
    log = res.log
    assert np.abs(log.q - ref.q[:, talos.act_q_index]).max() < 0.05
    differs = np.any(log.contact != ref.contact, axis=1)
    switches = np.flatnonzero(np.any(np.diff(ref.contact, axis=0), axis=1)) + 1
    near = np.zeros(len(ref), dtype=bool)
    for j in switches:
        near[max(0, j - 100):j + 100] = True
    assert differs.any() and not (differs & ~near).any()  # measured, and within 100 ms of a planned switch
    # on average the soles carry the robot's weight
    weight = sum(i.mass for i in talos.model.inertias) * 9.81
    assert abs(res.wrench[:, :, 2].sum(axis=1).mean() / weight - 1) < 0.02
    # the logged true acceleration is the derivative of the logged true velocity (10 substeps per sample)
    a_fd = (log.qd_true[2:] - log.qd_true[:-2]) / (2 * ref.dt)
    single = ~np.any(np.diff(log.contact.astype(int), axis=0), axis=1)
    inner = single[:-1] & single[1:]
    assert np.median(np.abs(a_fd - log.qdd_true[1:-1])[inner]) < 0.5
