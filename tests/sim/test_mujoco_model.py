"""The MuJoCo model built from the URDF has Pinocchio's dynamics (issue 5, item 1)."""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from wbfriction.friction.models import FrictionParams
from wbfriction.logs.contacts import normal_forces
from wbfriction.model.footprint import sole_footprint
from wbfriction.sim.mujoco_model import SOLE_THICKNESS, build_mujoco_robot


@pytest.fixture(scope="module")
def mj_talos(talos):
    return build_mujoco_robot(talos)


def _random_state(talos, rng):
    q = talos.configuration(rng.uniform(*talos.angle_limits))
    q[:3] = rng.normal(0, 1, 3)
    q[3:7] = pin.Quaternion(rng.normal(size=4)).normalized().coeffs()
    return q, rng.normal(0, 1, talos.model.nv)


@pytest.mark.parametrize("robot_name", ["talos", "toro"])
def test_mass_matrix_gravity_and_bias_agree_with_pinocchio(robot_name, request):
    """M_pin = T^T M_mj T, g_pin = T^T g_mj and h_pin = T^T (h_mj + M_mj dT/dt v), with T
    mapping Pinocchio's velocities to MuJoCo's, on random states."""
    robot = request.getfixturevalue(robot_name)
    mjr = request.getfixturevalue("mj_talos") if robot_name == "talos" else build_mujoco_robot(robot)
    m, d = mjr.model, mujoco.MjData(mjr.model)
    data = robot.model.createData()
    rng = np.random.default_rng(0)
    M_mj = np.zeros((m.nv, m.nv))
    for _ in range(5):
        q, v = _random_state(robot, rng)
        T = mjr.velocity_map(q)
        d.qpos[:], d.qvel[:] = mjr.qpos(q), T @ v
        mujoco.mj_forward(m, d)
        mujoco.mj_fullM(m, d, M_mj)
        M = pin.crba(robot.model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        np.testing.assert_allclose(T.T @ M_mj @ T, M, atol=1e-9)
        g = pin.computeGeneralizedGravity(robot.model, data, q)
        h = pin.nonLinearEffects(robot.model, data, q, v)
        d.qvel[:] = 0
        mujoco.mj_forward(m, d)
        np.testing.assert_allclose(T.T @ d.qfrc_bias, g, atol=1e-8)
        d.qvel[:] = T @ v
        mujoco.mj_forward(m, d)
        # qvel = T v, so qacc = T a + (dT/dt) v with (dT/dt) v = (R (w x v_lin), 0, ...)
        Tdot_v = np.zeros(m.nv)
        Tdot_v[:3] = T[:3, :3] @ np.cross(v[3:6], v[:3])
        np.testing.assert_allclose(T.T @ (d.qfrc_bias + M_mj @ Tdot_v), h, atol=1e-8)
        np.testing.assert_allclose(mjr.q(mjr.qpos(q)), q, atol=1e-15)


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


@pytest.mark.slow
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


def test_mujoco_friction_torque_is_the_force_mujoco_applied(talos, mj_talos):
    """MuJoCo's own joint friction (frictionloss + damping): the torque read from the
    constraint and damper forces is what closes MuJoCo's equation of motion, M qacc + c =
    tau_f on the friction joints and 0 elsewhere (robot in the air: no contact, no torque),
    and it dissipates."""
    import copy

    from wbfriction.fit.targets import friction_by_group
    from wbfriction.sim.common import injected_friction
    from wbfriction.sim.mujoco_sim import mujoco_friction_torque, set_mujoco_friction

    params = {j: FrictionParams(F_v=0.3, F_c=1.5) for j in friction_by_group(talos.groups)}
    injected = injected_friction(talos, params)
    dofs = mj_talos.dof_index[talos.tc_index][injected.joints]
    model = copy.copy(mj_talos.model)
    set_mujoco_friction(model, dofs, injected)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(3)
    data.qpos[:] = mj_talos.qpos(talos.configuration(talos.reference_angles))
    data.qpos[2] = 5.0
    data.qvel[6:] = rng.normal(0, 1.0, model.nv - 6)
    data.qvel[dofs[:3]] = [1e-4, -2e-4, 0.0]  # in the sticking region too
    mujoco.mj_forward(model, data)
    assert data.ncon == 0
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    closing = M @ data.qacc + data.qfrc_bias
    tau_f = mujoco_friction_torque(data, dofs)
    np.testing.assert_allclose(closing[dofs], tau_f, atol=1e-8)
    others = np.setdiff1d(np.arange(model.nv), dofs)
    np.testing.assert_allclose(closing[others], 0.0, atol=1e-8)
    assert np.all(data.qvel[dofs] * tau_f <= 1e-12) and np.abs(tau_f).max() > 1.0
    # the shared model is untouched
    assert np.all(mj_talos.model.dof_frictionloss == 0)


def test_swing_estimate_is_reliable_and_stance_is_not_on_mujoco(talos, mj_talos):
    """Thesis 6.2 (Fig. 6.4): on real (soft) contacts the right knee's friction, estimated
    with central differences, is close to the truth while its leg swings, and far off while
    it stands; contact flags come from measured forces."""
    from wbfriction.fit.targets import THESIS_TARGETS
    from wbfriction.friction.estimate import estimate_log
    from wbfriction.friction.options import EstimateOptions
    from wbfriction.sim.mujoco_sim import simulate_mujoco
    from wbfriction.walking import GaitOptions, walking_reference

    knee = "leg_right_4_joint"
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=4))
    log = simulate_mujoco(talos, ref, {knee: THESIS_TARGETS["knee"]}, mjr=mj_talos).log
    assert log.metadata["contact_source"].startswith("sole normal force")
    est = estimate_log(talos, log, EstimateOptions(mask="single", base_motion="contact", wrenches=False))  # thesis
    i = est.joints.index(knee)
    err = est.tau_f[:, i] - est.tau_f_true[:, i]
    right = talos.contact_of(knee)
    swing = est.valid[:, i] & ~est.contact[:, right]
    stance = est.valid[:, i] & est.contact[:, right]
    rms = lambda m: float(np.sqrt(np.mean(err[m] ** 2)))  # noqa: E731
    assert swing.sum() > 1000 and stance.sum() > 1000
    # the rows where the landing foot already pushes (below the 50 N of its touch flag) are the
    # flags' lag, not the swing estimate: what the measured force says of them is left out
    pushing = normal_forces(talos, log.wrench)[:, right] > 0  # in the air: minus the plate's weight
    assert np.mean(pushing[swing]) < 0.02
    assert rms(swing & ~pushing) < 0.1 * THESIS_TARGETS["knee"].F_c  # measured 0.03 N·m
    assert rms(stance) > 10 * rms(swing & ~pushing)  # measured 3 N·m


def test_sensor_noise_quantisation_and_delay_in_the_loop(talos, mj_talos):
    """With sensors on, the log holds encoder counts of the noisy true position, the
    delay must be whole control periods, and the walk still completes with a 2 ms delay."""
    from wbfriction.exceptions import InputError
    from wbfriction.sim import MujocoOptions, SensorNoise, simulate_mujoco
    from wbfriction.walking import GaitOptions, walking_reference

    ref = walking_reference(talos, GaitOptions(gait="forward", steps=2))
    noise = SensorNoise(position_std=1e-4, encoder_bits=19, torque_std=0.05, seed=4)
    res = simulate_mujoco(talos, ref, options=MujocoOptions(sensors=noise, delay=0.002), mjr=mj_talos)
    counts = res.log.q / noise.resolution
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-6)
    diff = res.log.q - res.q[:, talos.act_q_index]
    assert abs(diff.std() - 1e-4) < 1e-5 and np.abs(diff).max() < 6e-4
    again = simulate_mujoco(talos, ref, options=MujocoOptions(sensors=noise, delay=0.002), mjr=mj_talos)
    np.testing.assert_array_equal(again.log.tau, res.log.tau)  # seeded: the same run twice
    with pytest.raises(InputError, match="multiple of the control period"):
        simulate_mujoco(talos, ref, options=MujocoOptions(delay=0.0015), mjr=mj_talos)


def test_mujoco_warnings_go_to_the_logger_not_to_a_file(talos, tmp_path, monkeypatch, caplog):
    """An unstable step's warning reaches the ``wbfriction.mujoco`` logger; no ``MUJOCO_LOG.TXT`` is written in
    the working directory (MuJoCo's default)."""
    monkeypatch.chdir(tmp_path)
    mjr = build_mujoco_robot(talos)
    data = mujoco.MjData(mjr.model)
    data.qvel[:] = 1e20
    with caplog.at_level("WARNING", logger="wbfriction.mujoco"):
        mujoco.mj_step(mjr.model, data)
    assert any("unstable" in r.getMessage() for r in caplog.records)
    assert list(tmp_path.iterdir()) == []
