"""The IMU: its frame from the TOML, its readings against MuJoCo's sensors, and the base's motion recovered
from them (hypothesis: random states, the twist's angular part and the acceleration exactly)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.model.imu import Imu, add_imu_frame, base_motion_from_imu, imu_readings


def test_the_builtin_talos_imu_is_the_urdfs_imu_link(talos):
    assert talos.imu is not None
    frame = talos.model.frames[talos.imu.frame]
    link = talos.model.frames[talos.model.getFrameId("imu_link")]
    assert frame.parentJoint == link.parentJoint and frame.placement.isApprox(link.placement)
    assert Imu.columns() == ["imu.gyro_x", "imu.gyro_y", "imu.gyro_z", "imu.acc_x", "imu.acc_y", "imu.acc_z"]


@pytest.mark.parametrize(("table", "needle"), [
    ({"link": "nowhere"}, "link = 'nowhere' is not a frame"),
    ({"link": "base_link", "xyz": [1, 2]}, "xyz must be 3 numbers"),
    ({"link": "base_link", "colour": 1}, "unknown key 'colour'"),
])
def test_a_bad_imu_table_is_refused_in_one_line(talos, table, needle):
    with pytest.raises(InputError, match=needle):
        add_imu_frame(pin.Model(talos.model), table, "robot.toml")


def test_a_resting_imu_reads_gravity_upwards(talos):
    """Analytic: the robot still, the specific force is -R^T g: 9.81 m/s^2 along the IMU frame's world up."""
    q = talos.q_reference[None]
    zeros = np.zeros((1, talos.model.nv))
    reading = imu_readings(talos.model, talos.imu, q, zeros, zeros)[0]
    data = talos.model.createData()
    pin.framesForwardKinematics(talos.model, data, q[0])
    R = data.oMf[talos.imu.frame].rotation
    np.testing.assert_allclose(reading[:3], 0.0, atol=1e-15)
    np.testing.assert_allclose(reading[3:], R.T @ np.array([0.0, 0.0, 9.81]), atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_the_base_motion_comes_back_from_the_imu(talos, seed):
    """Readings of a random state, then the base's angular velocity and its acceleration from them: with the
    base's linear velocity set to zero, the solved acceleration is the true classical one (Galilean)."""
    rng = np.random.default_rng(seed)
    model = talos.model
    base = np.r_[rng.normal(size=3), pin.Quaternion(pin.rpy.rpyToMatrix(*rng.uniform(-0.4, 0.4, 3))).coeffs()]
    q = talos.configuration(talos.reference_angles + rng.uniform(-0.3, 0.3, talos.n_act), base)
    v, a = rng.normal(size=model.nv), rng.normal(size=model.nv)
    v[:3] = 0.0  # the estimator's convention: the linear part is not measured
    reading = imu_readings(model, talos.imu, q[None], v[None], a[None])
    data = model.createData()
    pin.forwardKinematics(model, data, q, v, a)
    gyro_d = pin.getFrameAcceleration(model, data, talos.imu.frame, pin.LOCAL).angular
    iv = talos.act_v_index
    v_b, a_b = base_motion_from_imu(model, talos.imu, q[None], iv, v[None, iv], a[None, iv], reading[:, :3],
                                    gyro_d[None], reading[:, 3:])
    np.testing.assert_allclose(v_b[0], np.r_[0.0, 0.0, 0.0, v[3:6]], atol=1e-10)
    np.testing.assert_allclose(a_b[0], a[:6], atol=1e-9)


def test_mujoco_reads_what_pinocchio_says(talos):
    """Two routes: MuJoCo's gyro and accelerometer at the IMU site against :func:`imu_readings` of the
    simulated motion (one physics step per period: its mean is the instant's)."""
    from wbfriction.sim import MujocoOptions, simulate_mujoco
    from wbfriction.walking import GaitOptions, walking_reference

    ref = walking_reference(talos, GaitOptions(gait="forward", steps=1))
    res = simulate_mujoco(talos, ref, None, MujocoOptions(substeps=1))
    log = res.log
    q = talos.configuration(log.q, log.base)
    a = np.zeros_like(res.v)
    a[:, :6], a[:, talos.act_v_index] = log.base_qdd_true, log.qdd_true
    truth = imu_readings(talos.model, talos.imu, q, res.v, a)
    np.testing.assert_allclose(log.imu, truth, atol=1e-9)
