"""The base's motion from the IMU and the stance legs (issue 82, item 2): the IMU's rotation composed and inverted for
any orientation; a base moving at a constant velocity and turning rigidly on feet fixed to the ground, exactly; the
refusals in one line; and on the MuJoCo twin (trot and walk, clean and with a Unitree's noise, the true contacts, its
feet firm) the orientation and the angular velocity to the IMU's precision, the linear velocity within issue 82's 5 %
(the numbers measured are in the tests' docstrings)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError, OptionError
from wbfriction.model.loading import load_robot
from wbfriction.signals.leg_odometry import (
    OdometryOptions,
    base_from_legs,
    base_rotation,
    imu_rotation,
    stance_velocities,
)

MUJOCO_FOOT = 0.023
"""The MuJoCo twin's feet's radius [m] (docs/how-to/quadrupeds.md): the robot's ``foot_radius`` for its logs."""


@pytest.fixture(scope="module")
def robot():
    """The built-in ``go2_walking`` with the MuJoCo feet's radius (its IMU on the trunk)."""
    return replace(load_robot("go2_walking"), foot_radius=MUJOCO_FOOT, cache={})


def imu_of_base(robot, base_rot: np.ndarray) -> np.ndarray:
    """The IMU frame's rotation (N, 3, 3) of base rotations (N, 3, 3): ``R_b R_bi``."""
    return base_rot @ robot.model.frames[robot.imu.frame].placement.rotation


angles = st.floats(-np.pi, np.pi, allow_nan=False)


@settings(max_examples=50, deadline=None)
@given(roll=angles, pitch=st.floats(-1.5, 1.5), yaw=angles)
def test_the_imu_rotation_composed_and_inverted_for_any_orientation(robot, roll, pitch, yaw):
    """For any roll, pitch, yaw: :func:`imu_rotation` is ``pin.rpy.rpyToMatrix``'s, the same rotation given as its
    quaternion gives the same matrix, and the base's rotation composed with the IMU's placement gives it back."""
    rpy = np.array([[roll, pitch, yaw]])
    R = imu_rotation(robot, roll_pitch_yaw=rpy)
    np.testing.assert_allclose(R[0], pin.rpy.rpyToMatrix(roll, pitch, yaw), atol=1e-12)
    quat = pin.Quaternion(R[0]).coeffs()[None]
    np.testing.assert_allclose(imu_rotation(robot, quaternion=-2.0 * quat), R, atol=1e-12)
    base = base_rotation(robot, robot.reference_angles[None], R)
    np.testing.assert_allclose(imu_of_base(robot, base), R, atol=1e-12)
    np.testing.assert_allclose(base[0] @ base[0].T, np.eye(3), atol=1e-12)


def rigid_motion(robot, n: int = 400, dt: float = 0.002):
    """A base moving at a constant world velocity and turning at a constant rate (base frame) while the four feet
    stay on the ground (the legs' joints move so that their contact points do not): ``(q, qd, base poses (N, 7),
    v0, omega)``; the angles integrated with the joint velocities each sample's constraint gives (second order)."""
    v0, omega = np.array([0.3, -0.1, 0.02]), np.array([0.1, -0.2, 0.4])
    model, data = robot.model, robot.model.createData()
    angles, base = robot.reference_angles.copy(), np.r_[0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 1.0]
    q, qd, poses = np.empty((n, robot.n_act)), np.empty((n, robot.n_act)), np.empty((n, 7))
    for k in range(n):
        full = robot.configuration(angles, base)
        pin.computeJointJacobians(model, data, full)
        pin.updateFramePlacements(model, data)
        R = data.oMi[1].rotation
        J = np.vstack([kind.jacobian(robot, data, f) for kind, f in zip(robot.contact_models, robot.contact_frame_ids)])
        Jj = J[:, 6:][:, robot.act_v_index - 6]
        twist = np.r_[R.T @ v0, omega]
        q[k], qd[k], poses[k] = angles, np.linalg.solve(Jj, -J[:, :6] @ twist), base
        angles = angles + dt * qd[k]
        base = base.copy()
        base[:3] += dt * v0
        base[3:] = pin.Quaternion(R @ pin.exp3(dt * omega)).coeffs()
    return q, qd, poses, v0, omega, dt


def test_a_base_moving_and_turning_rigidly_on_fixed_feet_is_found_exactly(robot):
    """Constant world velocity, constant rate of turn, the feet fixed: the orientation and angular velocity to
    rounding, the linear velocity, its (zero) world acceleration and Pinocchio's ``-w x v`` to 1e-6, the position
    integrated to 1e-6 m (the legs exact: their noise and the jerk's density given, the spread being zero)."""
    q, qd, poses, v0, omega, dt = rigid_motion(robot)
    n = len(q)
    R = np.array([pin.Quaternion(p[3:]).matrix() for p in poses])
    imu_R = imu_of_base(robot, R)
    gyro = np.tile(robot.model.frames[robot.imu.frame].placement.rotation.T @ omega, (n, 1))
    feet = np.ones((n, 4), dtype=bool)
    est = base_from_legs(robot, q, qd, np.zeros_like(q), imu_R, gyro, feet, feet, dt,
                         options=OdometryOptions(leg_sd=1e-6, jerk=1.0, gyro_sd=0.0, gyro_window=3))
    v_b = np.einsum("nji,j->ni", R, v0)
    np.testing.assert_allclose(est.twist[:, 3:], np.tile(omega, (n, 1)), atol=1e-12)
    np.testing.assert_allclose(est.twist[:, :3], v_b, atol=1e-6)
    np.testing.assert_allclose(est.acceleration[:, :3], -np.cross(omega, v_b), atol=1e-6)
    np.testing.assert_allclose(est.acceleration[1:-1, 3:], 0.0, atol=1e-9)
    np.testing.assert_allclose(est.pose[:, :3], poses[:, :3] - poses[0, :3], atol=1e-6)
    got = np.array([pin.Quaternion(p[3:]).matrix() for p in est.pose])
    np.testing.assert_allclose(got, R, atol=1e-12)
    assert np.all(est.stance == 4)


def test_refusals_in_one_line(robot):
    """A robot without ``[imu]``, no confident stance foot anywhere, arrays of the wrong shape, options out of range:
    each one line naming what is at fault."""
    n = 10
    q, R, gyro = np.tile(robot.reference_angles, (n, 1)), np.tile(np.eye(3), (n, 1, 1)), np.zeros((n, 3))
    down, sure = np.ones((n, 4), dtype=bool), np.ones((n, 4), dtype=bool)
    with pytest.raises(InputError, match=r"^robot 'go2_walking': no \[imu\] in its TOML") as info:
        base_from_legs(replace(robot, imu=None), q, q, q, R, gyro, down, sure, 0.002)
    assert "\n" not in str(info.value)
    with pytest.raises(InputError, match=r"^robot 'go2_walking': no \[imu\] in its TOML"):
        imu_rotation(replace(robot, imu=None), roll_pitch_yaw=np.zeros((n, 3)))
    with pytest.raises(InputError, match="^walk.parquet: no sample has a confident stance foot"):
        base_from_legs(robot, q, q, q, R, gyro, down, ~sure, 0.002, source="walk.parquet")
    with pytest.raises(InputError, match=r"^walk.parquet: the base's motion from the legs: gyro must be \(10, 3\)"):
        base_from_legs(robot, q, q, q, R, gyro[:, :2], down, sure, 0.002, source="walk.parquet")
    with pytest.raises(InputError, match="give roll, pitch, yaw or a quaternion"):
        imu_rotation(robot)
    with pytest.raises(InputError, match="quaternion at row 1 is not a rotation"):
        imu_rotation(robot, quaternion=np.array([[0, 0, 0, 1.0], [0, 0, 0, 0]]))
    with pytest.raises(OptionError, match=r"^--gyro-window must be odd and > --gyro-order 2, got 4$"):
        OdometryOptions(gyro_window=4)
    with pytest.raises(OptionError, match=r"^--leg-sd must be > 0"):
        OdometryOptions(leg_sd=0.0)


# ------------------------------------------------------------------------------------------ the MuJoCo twin
CASES = [("trot", False), ("trot", True), ("walk", False), ("walk", True)]
IMU_RPY_NOISE = 0.005
"""The white noise put on the IMU's roll, pitch and yaw in the noisy cases [rad] (a MEMS IMU's attitude filter's)."""


def simulate_twin(robot, gait: str, noisy: bool = False, contacts: str = "firm"):
    """3 s of ``gait`` on the MuJoCo twin (torque-driven, 500 Hz, normal foot forces; its feet firm, as ``simulate
    --logger raw`` makes them, or MuJoCo's default soft ones), clean or with UNITREE_NOISE."""
    from wbfriction.sim.quadruped import QuadrupedOptions
    from wbfriction.sim.quadruped_mujoco import UNITREE_NOISE, simulate_quadruped_mujoco
    from wbfriction.walking.quadruped import GaitOptions, quadruped_reference

    reference = quadruped_reference(robot, GaitOptions(gait, duration=3.0))
    return simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(foot_forces="normal", contacts=contacts),
                                     noise=UNITREE_NOISE if noisy else None)


@pytest.fixture(scope="module")
def twin_runs(robot):
    """Each case on the twin (:func:`simulate_twin`), simulated once per module."""
    return {(gait, noisy): simulate_twin(robot, gait, noisy) for gait, noisy in CASES}


def twin_inputs(robot, run, noisy: bool):
    """What the estimator gets from a twin's log: the encoders' angles, the drivers' velocities, the angles
    differentiated as the project does (the scheme chosen from the data), the IMU's rotation of the true pose (with
    :data:`IMU_RPY_NOISE` if noisy), its gyro and accelerometer, the true contacts (force > 0), all confident."""
    from wbfriction.signals.choice import choose_differentiation
    from wbfriction.signals.kinematics import measure

    log = run.log
    R = np.array([pin.Quaternion(b[3:]).matrix() for b in log.base])
    rpy = np.array([pin.rpy.matrixToRpy(M) for M in imu_of_base(robot, R)])
    if noisy:
        rpy += np.random.default_rng(3).normal(0.0, IMU_RPY_NOISE, rpy.shape)
    choice = choose_differentiation(log)
    qdd = measure(log, choice.scheme, filtering=choice.filtering).qdd
    contact = run.force[..., 2] > 0
    return (log.q, log.qd_logged, np.where(np.isfinite(qdd), qdd, 0.0), imu_rotation(robot, roll_pitch_yaw=rpy),
            log.imu[:, :3], contact, np.ones_like(contact), log.dt), R


def relative_error(estimate: np.ndarray, truth: np.ndarray) -> float:
    """RMS of the error's norm over RMS of the truth's norm (the issue's "within x % RMS of its speed")."""
    return float(np.sqrt(np.mean(np.sum((estimate - truth) ** 2, axis=1)) / np.mean(np.sum(truth**2, axis=1))))


@pytest.fixture(scope="module")
def twin_estimates(robot, twin_runs):
    """Each case's estimate without and with the accelerometer."""
    out = {}
    for (gait, noisy), run in twin_runs.items():
        args, R = twin_inputs(robot, run, noisy)
        for acc in (False, True):
            out[gait, noisy, acc] = base_from_legs(robot, *args, acc=run.log.imu[:, 3:] if acc else None), R
    return out


MEASURED_VELOCITY = {("trot", False, False): 0.0224, ("trot", False, True): 0.0108, ("trot", True, False): 0.021,
                     ("trot", True, True): 0.017, ("walk", False, False): 0.0055, ("walk", False, True): 0.0034,
                     ("walk", True, False): 0.0099, ("walk", True, True): 0.0108}
"""The linear velocity's relative error measured per (gait, noisy, accelerometer) on the twin's firm feet with each
foot's noise raised near its touch-down and lift-off (before, one legs' noise for every sample:
2.2, 0.98, 2.8, 2.0, 0.40, 0.41, 1.01, 1.04 %; on MuJoCo's soft feet 5.6-9.9 %)."""


@pytest.mark.slow
@pytest.mark.parametrize("gait, noisy", CASES)
def test_on_the_twin_the_orientation_and_rates_are_the_imus(robot, twin_runs, twin_estimates, gait, noisy):
    """The orientation is the IMU's (clean: to rounding; noisy: within twice its RMS noise, sqrt(3) x 5 mrad), the
    angular velocity the gyro's (clean: to rounding; noisy: within 1.2 times UNITREE_NOISE's 5 mrad/s per axis); the
    twist's angular standard deviation is the gyro's measured noise (within 20 %)."""
    log = twin_runs[gait, noisy].log
    for acc in (False, True):
        est, R = twin_estimates[gait, noisy, acc]
        got = np.array([pin.Quaternion(p[3:]).matrix() for p in est.pose])
        turn = np.array([np.linalg.norm(pin.log3(a.T @ b)) for a, b in zip(got, R)])
        w_err = np.sqrt(np.mean((est.twist[:, 3:] - log.base_qd_true[:, 3:]) ** 2, axis=0))
        if noisy:
            assert np.sqrt(np.mean(turn**2)) < 2 * np.sqrt(3) * IMU_RPY_NOISE
            assert np.all(w_err < 1.2 * 0.005)
            assert abs(est.twist_sd[0, 3] / 0.005 - 1) < 0.2
        else:
            assert turn.max() < 1e-9 and w_err.max() < 1e-9


@pytest.mark.slow
@pytest.mark.parametrize("gait, noisy", CASES)
def test_on_the_twin_the_linear_velocity_as_measured(robot, twin_runs, twin_estimates, gait, noisy):
    """The linear velocity's RMS error over the RMS speed, without and with the accelerometer, within 10 % of what
    was measured on the twin's firm feet (:data:`MEASURED_VELOCITY`: 0.3-2.2 %); the accelerometer helps (or does not
    hurt by more than 1 % of the speed)."""
    log = twin_runs[gait, noisy].log
    errors = {}
    for acc in (False, True):
        est, _ = twin_estimates[gait, noisy, acc]
        errors[acc] = relative_error(est.twist[:, :3], log.base_qd_true[:, :3])
        assert errors[acc] < 1.1 * MEASURED_VELOCITY[gait, noisy, acc]
        assert np.all(np.isfinite(est.twist)) and np.all(np.isfinite(est.twist_sd))
    assert errors[True] < errors[False] + 0.01


@pytest.mark.slow
@pytest.mark.parametrize("gait, noisy", CASES)
def test_on_the_twin_the_linear_velocity_within_five_percent(robot, twin_runs, twin_estimates, gait, noisy):
    """Issue 82's acceptance: the base's velocity within 5 % RMS of its speed, without and with accelerometer, on
    the twin whose feet hold (firm contacts; with MuJoCo's soft ones this failed: 6.8-9.9 % without accelerometer,
    test_the_twins_feet_hold_where_soft_feet_creep)."""
    log = twin_runs[gait, noisy].log
    for acc in (False, True):
        est, _ = twin_estimates[gait, noisy, acc]
        assert relative_error(est.twist[:, :3], log.base_qd_true[:, :3]) < 0.05


def feet_against_base(robot, run):
    """Each stance foot's (force > 0) estimate of the base's velocity from the TRUE state (N, 4, 3), the base's
    true velocity (N, 3), world, and each foot's distance to its nearest touch-down or lift-off [samples]."""
    contact = run.force[..., 2] > 0
    R = np.array([pin.Quaternion(b[3:]).matrix() for b in run.log.base])
    feet = stance_velocities(robot, run.q, run.v, R, contact)
    truth = np.einsum("nij,nj->ni", R, run.v[:, :3])
    n = np.arange(len(contact))
    switch = np.full(contact.shape, np.inf)
    for c in range(contact.shape[1]):
        at = np.flatnonzero(np.diff(contact[:, c].astype(int))) + 0.5
        if at.size:
            switch[:, c] = np.min(np.abs(n[:, None] - at[None]), axis=1)
    return feet, truth, switch


@pytest.mark.slow
@pytest.mark.parametrize("gait", ["trot", "walk"])
def test_the_twins_feet_hold_where_soft_feet_creep(robot, twin_runs, gait):
    """Why the twin's feet are firm: with MuJoCo's default soft contacts the stance feet (force > 0) slide on the
    ground at a median of over 5 % of the base's RMS speed (measured 1.4-1.6 cm/s, 7 % of 0.19-0.24 m/s), and the
    mean of the stance feet's velocities from the TRUE state is over 5 % off the base's even 10 ms (two firm time
    constants) away from every touch-down and lift-off (measured 17 % trot, 7.3 % walk): no estimator on the legs
    could meet issue 82's 5 %. On firm contacts the median is under 1 % of the speed (0.4 %: 0.07-0.10 cm/s) and the
    mean away from the switches under 5 % (3.3 % trot, 0.9 % walk)."""
    for contacts, run in (("soft", simulate_twin(robot, gait, contacts="soft")), ("firm", twin_runs[gait, False])):
        feet, truth, switch = feet_against_base(robot, run)
        speed = np.sqrt(np.mean(np.sum(truth**2, axis=1)))
        creep = np.nanmedian(np.linalg.norm(feet - truth[:, None], axis=2))
        away = np.where((switch > 5)[..., None], feet, np.nan)
        rows = np.isfinite(away[..., 0]).any(axis=1)
        error = relative_error(np.nanmean(away[rows], axis=1), truth[rows])
        if contacts == "soft":
            assert creep > 0.05 * speed and error > 0.05
        else:
            assert creep < 0.01 * speed and error < 0.05


def test_a_landing_foots_noise_is_read_from_its_disagreement_with_the_others():
    """Four feet agreeing to 1e-4 m/s; foot 0 lands every 50 samples off by 0.3, 0.1, 0.03 m/s on its first three
    samples: :func:`~wbfriction.signals.leg_noise.stance_noise` gives those three a noise near that error,
    non-increasing, the stance level (the pooled spread) to the other feet, and to foot 0 from its fifth sample on
    (the fourth shares the third's octave, 3-4 samples) within the spread's sampling error (20 %); NaN where a foot
    does not measure."""
    from wbfriction.signals.leg_noise import pooled_spread, stance_noise

    rng = np.random.default_rng(0)
    n, period = 2000, 50
    v = rng.normal(0.0, 1e-4, (n, 4, 3))
    starts = np.arange(period, n - period, period)
    for start in starts:
        v[start - 25:start, 0] = np.nan  # foot 0 swings, lands at `start`
        v[start:start + 3, 0] += np.array([0.3, 0.1, 0.03])[:, None] * rng.choice([-1, 1], (3, 3))
    floor = pooled_spread(v)
    sd = stance_noise(v, floor)
    np.testing.assert_allclose(floor, 1e-4, rtol=0.2)
    near = np.zeros(n, dtype=bool)
    near[(starts[:, None] + np.arange(4)).ravel()] = True
    np.testing.assert_array_equal(sd[:, 1:], np.broadcast_to(floor, (n, 3, 3)))
    settled = ~near & np.isfinite(v[:, 0, 0])
    np.testing.assert_allclose(sd[settled, 0], np.broadcast_to(floor, (settled.sum(), 3)), rtol=0.2)
    first, second, third = (sd[starts + k, 0] for k in range(3))
    assert np.all(first >= second) and np.all(second >= third)
    assert np.all((first > 0.1) & (first < 0.5)) and np.all(third > 0.01)
    assert np.all(np.isnan(sd[~np.isfinite(v[..., 0])]))


@pytest.mark.slow
def test_on_the_raw_twin_the_clean_firm_trot_within_five_percent(tmp_path):
    """The raw route (contacts inferred, ``studies/walking_logs``' scoring) on 8 s of the firm twin's clean trot: the
    base's velocity within 5 % RMS of its speed (measured 3.0 %). With one legs' noise for every sample it was 38 %:
    on noise-free joints the stance feet agree to 0.1-0.8 mm/s, a landing foot is off by 3-400 mm/s for a few
    samples, the gate rejected every foot of those samples and the smoother drifted by up to 0.86 m/s."""
    import subprocess
    import sys

    import pyarrow.parquet as pq

    from wbfriction.logs.options import ReadOptions
    from wbfriction.model.loading import RobotSpec
    from wbfriction.pipeline.raw_log import prepare_raw
    from wbfriction.studies.walking_logs import RATE, TWIN_ROBOT

    out = tmp_path / "trot_firm.parquet"
    done = subprocess.run([sys.executable, "-m", "wbfriction", "simulate", "--robot", str(TWIN_ROBOT), "--simulator",
                           "mujoco", "--gait", "trot", "--duration", "8", "--logger", "raw", "--contacts", "firm",
                           "-o", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    robot = RobotSpec.given(str(TWIN_ROBOT)).load()
    prepared = prepare_raw(pq.read_table(out), robot, str(out), ReadOptions(rate=float(RATE)))
    table = prepared.table
    truth = np.column_stack([np.asarray(table.column(f"base_qd_true.{a}")) for a in ("vx", "vy", "vz")])
    assert relative_error(prepared.base.twist[:, :3], truth) < 0.05
