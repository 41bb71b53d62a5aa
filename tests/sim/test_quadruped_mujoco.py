"""The walking Go2 on MuJoCo (issue 56): it stays up and trots on its diagonals; the logged base twist and
acceleration are its logged pose differentiated (Pinocchio's convention, on a robot walking along world y so that a
world-frame velocity would show); the logged forces, torques and friction balance an independent inverse dynamics
(Pinocchio) exactly with the forces at MuJoCo's contact points and within the point-foot model's error at the foot
frames; the IMU agrees with Pinocchio's; the PD-driven robot's torque is the lead's ``pd_torque`` of its logged
columns; the sensors' noise is what it says."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.exceptions import OptionError
from wbfriction.model.imu import imu_readings
from wbfriction.model.loading import load_robot
from wbfriction.model.pd import pd_torque
from wbfriction.sim.quadruped import QuadrupedOptions
from wbfriction.sim.quadruped_mjcf import build_quadruped_model
from wbfriction.sim.quadruped_mujoco import UNITREE_NOISE, simulate_quadruped_mujoco
from wbfriction.walking.quadruped import GaitOptions, quadruped_reference

LWA = pin.LOCAL_WORLD_ALIGNED


@pytest.fixture(scope="module")
def robot():
    return load_robot("go2_walking")


@pytest.fixture(scope="module")
def mjr(robot):
    return build_quadruped_model(robot)


def turned(reference, yaw: float):
    """The reference turned about the world's vertical by ``yaw`` (the ground is flat: the same walk): the base's pose
    and the feet's world positions, velocities and accelerations turned; the base's twist (base frame) and the joints
    as they are."""
    Rz = pin.rpy.rpyToMatrix(0.0, 0.0, yaw)
    base = reference.base.copy()
    base[:, :3] = reference.base[:, :3] @ Rz.T
    base[:, 3:] = [pin.Quaternion(Rz @ pin.Quaternion(b[3:]).matrix()).coeffs() for b in reference.base]
    return dataclasses.replace(reference, base=base, feet=reference.feet @ Rz.T, feet_v=reference.feet_v @ Rz.T,
                               feet_a=reference.feet_a @ Rz.T)


@pytest.fixture(scope="module")
def trot(robot, mjr):
    """A 2.5 s trot along world y (the reference turned 90 degrees), torque-driven, logged at 1 kHz with one physics
    step per sample (MuJoCo's semi-implicit Euler then relates consecutive samples exactly), 3-D foot forces."""
    reference = turned(quadruped_reference(robot, GaitOptions("trot", duration=2.5, dt=0.001)), np.pi / 2)
    return simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(physics_dt=0.001, foot_forces="3d"), mjr=mjr)


@pytest.fixture(scope="module")
def pd_trot(robot, mjr):
    """A 2 s PD-driven trot at 500 Hz, physics at 2 kHz, a Unitree-like robot's sensor noise."""
    reference = quadruped_reference(robot, GaitOptions("trot", duration=2.0))
    return simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(drive="pd", foot_forces="normal"),
                                     noise=UNITREE_NOISE, mjr=mjr)


def test_the_trot_stays_up_and_steps_on_its_diagonals(robot, trot):
    """The base stays within 1 cm of its planned height (measured: 4 mm) and ends within 3 cm of its planned place;
    the measured contacts (normal force with hysteresis) follow the plan on at least 95 % of the samples of each
    foot, and where two feet are down they are a diagonal pair but for 3 % of those samples (measured: 1 %, a foot
    landing before the other diagonal's has lifted)."""
    log, ref = trot.log, trot.reference
    assert np.abs(trot.q[:, 2] - ref.base[:, 2]).max() < 0.01
    assert np.linalg.norm(trot.q[-1, :2] - ref.base[-1, :2]) < 0.03
    assert ref.base[-1, 1] > 0.3  # it walked along y
    assert np.all((log.contact == ref.contact).mean(axis=0) > 0.95)
    two = log.contact.sum(axis=1) == 2
    assert two.mean() > 0.4
    FL, FR, RL, RR = (robot.contact_frames.index(f) for f in ("FL_foot", "FR_foot", "RL_foot", "RR_foot"))
    diagonal = (log.contact[:, FL] & log.contact[:, RR]) | (log.contact[:, FR] & log.contact[:, RL])
    assert diagonal[two].mean() > 0.97


def test_the_base_twist_and_acceleration_are_the_pose_differentiated(trot):
    """One semi-implicit Euler step per sample: the logged pose moves by the next sample's twist
    (``p+ = p + T R+ v+``, ``R+ = R exp(T w+)``) and the twist by the sample's acceleration in Pinocchio's convention
    (``R+ v+ - R v = T R (a_lin + w x v)``, ``w+ - w = T w_dot``), to rounding; the same pose read with the
    world-frame velocity (MuJoCo's) misses by the walk's speed."""
    log, T = trot.log, trot.reference.dt
    p, R = log.base[:, :3], np.array([pin.Quaternion(b[3:]).matrix() for b in log.base])
    v, w = log.base_qd_true[:, :3], log.base_qd_true[:, 3:]
    a, w_dot = log.base_qdd_true[:, :3], log.base_qdd_true[:, 3:]
    world_v = np.einsum("nij,nj->ni", R, v)
    np.testing.assert_allclose(np.diff(p, axis=0), T * world_v[1:], atol=1e-12)
    turn = np.array([pin.log3(R[k].T @ R[k + 1]) for k in range(len(R) - 1)])
    np.testing.assert_allclose(turn, T * w[1:], atol=1e-10)
    np.testing.assert_allclose(np.diff(world_v, axis=0), T * np.einsum("nij,nj->ni", R, a + np.cross(w, v))[:-1],
                               atol=1e-10)
    np.testing.assert_allclose(np.diff(w, axis=0), T * w_dot[:-1], atol=1e-10)
    assert np.median(np.abs(np.diff(p, axis=0) / T - v[1:])[:, :2]) > 0.1  # the base frame's velocity is not world


def point_jacobian(model, data, frame: int, point: np.ndarray) -> np.ndarray:
    """The linear Jacobian (3, nv) of the point ``point`` (world) rigidly attached to ``frame``."""
    J = pin.getFrameJacobian(model, data, frame, LWA)
    r = point - data.oMf[frame].translation
    return J[:3] - pin.skew(r) @ J[3:]


def balance(robot, run, at_contact_point: bool) -> np.ndarray:
    """``M qdd + h - S^T (tau + tau_f) - sum_c J_c^T f_c`` (N, nv) at the samples: Pinocchio's inverse dynamics of
    the logged truth, with each foot's Jacobian at MuJoCo's contact point or at the foot frame's origin."""
    model = pin.Model(robot.model)
    model.armature[robot.act_v_index] = [run.log.metadata["armature_true"][j] for j in robot.actuated]
    data = model.createData()
    out = np.empty_like(run.v)
    for k in range(len(run.q)):
        rhs = pin.rnea(model, data, run.q[k], run.v[k], run.a[k]).copy()
        rhs[robot.act_v_index] -= run.tau_motor[k] + run.tau_f[k]
        pin.computeJointJacobians(model, data, run.q[k])
        pin.updateFramePlacements(model, data)
        for c, frame in enumerate(robot.contact_frame_ids):
            if run.force[k, c].any():
                J = (point_jacobian(model, data, frame, run.contact_point[k, c]) if at_contact_point
                     else pin.getFrameJacobian(model, data, frame, LWA)[:3])
                rhs -= J.T @ run.force[k, c]
        out[k] = rhs
    return out


def test_the_logged_forces_balance_the_dynamics(robot, trot):
    """The logged torques (the command: no noise here), friction and 3-D foot forces balance Pinocchio's inverse
    dynamics of the logged state and acceleration: to 1e-7 with the forces at MuJoCo's contact points; at the foot
    frames' origins (the point-foot model: the force's moment ``r x f`` about the sphere's centre left out) within
    what was measured (this trot: up to 0.95 N·m on the base's moment rows, 0.47 N·m on a joint (a hip), RMS
    0.05-0.09 N·m per joint)."""
    np.testing.assert_array_equal(trot.log.tau, trot.tau_motor)
    np.testing.assert_array_equal(trot.log.foot_force, trot.force)
    np.testing.assert_allclose(balance(robot, trot, at_contact_point=True), 0.0, atol=1e-7)
    residual = balance(robot, trot, at_contact_point=False)
    joints = residual[:, robot.act_v_index]
    assert np.abs(residual[:, :3]).max() < 1e-7  # the forces are right: only their moments are off
    assert np.abs(residual).max() < 1.5
    assert np.sqrt((joints**2).mean(axis=0)).max() < 0.12
    assert np.abs(joints).max() > 0.05  # the point-foot model's error is there


def test_the_friction_and_the_imu_are_the_truth(robot, trot):
    """``tau_f_true`` is ``-f(qd_true)`` of the metadata's parameters, (3.5) written out (every joint its own); the
    IMU's readings (MuJoCo's gyro and accelerometer) are Pinocchio's of the logged state and acceleration."""
    log = trot.log
    params = log.metadata["friction_true"]
    assert len({(p["F_c"], p["F_v"]) for p in params.values()}) == robot.n_act == len(params)
    for i, joint in enumerate(robot.actuated):
        p, v = params[joint], log.qd_true[:, i]
        f = (p["F_v"] * v + p["F_c"] * (1 + p["S"] * np.exp(-np.abs(v / p["v_s"]) ** p["delta_s"]))
             * np.tanh(p["a"] * v) + p["tau_os"])
        np.testing.assert_allclose(log.tau_f_true[:, i], -f, rtol=0, atol=1e-12)
    np.testing.assert_allclose(log.imu, imu_readings(robot.model, robot.imu, trot.q, trot.v, trot.a), atol=1e-8)


def test_the_pd_driven_torque_is_the_pd_law_of_the_logged_columns(robot, pd_trot):
    """The torque the drivers applied at each sample is ``pd_torque`` of the logged encoder angles, driver
    velocities and set-points (noise included: the drivers act on the readings logged), to rounding; the log
    carries the set-points, not the torque."""
    log = pd_trot.log
    sp = log.setpoints
    assert log.torque_source == "pd" and sp is not None
    q_logged = log.q + np.array([robot.encoder_offset.get(j, 0.0) for j in robot.actuated])
    law = pd_torque(robot.pd, log.time, q_logged, sp.qd, sp.q_des, sp.qd_des, sp.tau_ff)
    np.testing.assert_allclose(pd_trot.tau_motor, law, atol=1e-9)
    np.testing.assert_allclose(log.tau, law, atol=1e-9)
    assert np.abs(np.diff(sp.q_des, axis=0)).max() > 1e-3  # set-points that move every sample
    assert np.abs(pd_trot.reference.q - log.q).max() < 0.2  # tracking


def test_the_sensors_noise(robot, pd_trot):
    """UNITREE_NOISE: the angles on the 15-bit lattice, within half a step of the truth; the IMU's and the normal
    foot forces' noise of their standard deviations; the tangential forces not logged."""
    log, noise = pd_trot.log, UNITREE_NOISE
    steps = log.q / noise.encoder_resolution
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-6)
    assert np.abs(log.q - pd_trot.q[:, robot.act_q_index]).max() <= 0.5 * noise.encoder_resolution + 1e-12
    err = log.imu - pd_trot.imu_true
    np.testing.assert_allclose(err.std(axis=0), [noise.gyro_std] * 3 + [noise.acc_std] * 3, rtol=0.1)
    assert np.isnan(log.foot_force[..., :2]).all()
    assert abs((log.foot_force[..., 2] - pd_trot.force[..., 2]).std() / noise.force_std - 1) < 0.1


def test_the_held_torque_is_a_real_robots_zero_order_hold(robot, mjr):
    """Four physics steps per period (the default, 500 Hz): the command ``tau[k]`` acts over ``[t_k, t_k+1)`` as on a
    real robot (the period's first step takes the trapezoid's half step), and the sample's truth is the command's:
    the logged torques, friction and 3-D forces balance the logged state and acceleration to 1e-7. Central
    differences then see the torque as ``zoh`` does: on a 3 s trot without foot forces (each hip seen as its leg
    swings; with 3-D forces the sphere feet's moment is a model error of its own) every hip's fitted F_v within 5 %
    of the injected one (2.6 % at worst; MuJoCo's semi-implicit Euler applied the command half a physics step early:
    1.3-18 % high, issue 63)."""
    from wbfriction.fit.joints import fit_estimate
    from wbfriction.fit.options import FitOptions
    from wbfriction.friction.estimate import estimate_log
    from wbfriction.friction.options import EstimateOptions
    from wbfriction.sim.quadruped import default_quadruped_friction
    from wbfriction.studies.quadruped import QuadrupedCase, case_robot

    reference = quadruped_reference(robot, GaitOptions("trot", duration=3.0))
    run = simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(foot_forces="3d"), mjr=mjr)
    run_none = simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(), mjr=mjr)
    assert run.log.metadata["torque_alignment"] == "zoh" and run.log.metadata["physics_step"] == 0.0005
    np.testing.assert_allclose(balance(robot, run, at_contact_point=True), 0.0, atol=1e-7)
    est = estimate_log(case_robot(robot, QuadrupedCase(simulator="mujoco")), run_none.log,
                       EstimateOptions(diff="central", route="acceleration", base_motion="logged", check_route=False))
    fits = {f.joint: f for f in fit_estimate(est, FitOptions(model="thesis"), fixed={"S": 0.0, "v_s": 0.1})}
    truth = default_quadruped_friction(robot)
    errors = {j: fits[j].params.F_v / truth[j].F_v - 1 for j in robot.actuated if "hip" in j}
    assert max(abs(e) for e in errors.values()) < 0.05, errors


def test_firm_contacts_are_set_on_the_runs_copy_and_recorded_and_soft_logs_are_as_before(robot, mjr):
    """``contacts = "firm"`` (issue 82): the run's model gets elliptic cones, impratio 10 and a 5 ms time constant
    (recorded in the log's ``feet`` metadata and options), the shared model is left soft; a soft run's metadata has
    no trace of the option (its log's bytes are those written before it); another value is refused naming
    ``--contacts``."""
    import mujoco

    from wbfriction.sim.quadruped_mjcf import FIRM_IMPRATIO, FIRM_TIMECONST

    reference = quadruped_reference(robot, GaitOptions("trot", duration=0.2))
    firm = simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(contacts="firm"), mjr=mjr).log.metadata
    soft = simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(), mjr=mjr).log.metadata
    assert firm["feet"]["cone"] == "elliptic" and firm["feet"]["impratio"] == FIRM_IMPRATIO
    assert firm["feet"]["timeconst"] == FIRM_TIMECONST and firm["options"]["contacts"] == "firm"
    assert "contacts" not in soft["options"] and set(soft["feet"]) == {"radius", "friction", "contact_force"}
    assert mjr.model.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL and mjr.model.opt.impratio == 1.0
    with pytest.raises(OptionError, match="--contacts"):
        QuadrupedOptions(contacts="hard")
