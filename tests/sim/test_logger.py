"""The simulated twin's raw log (issue 82, :mod:`wbfriction.sim.logger`): its rows repeat exactly where the logger's
and the drives' clocks say (``sample_true``), the IMU's at its own rate; the currents times the nominal constants are
the applied torque off by exactly the drawn error; the IMU's roll, pitch, yaw give back the IMU frame's true rotation;
no contact, base or force column; ``--logger full`` writes today's log byte for byte; the same seed the same bytes."""

from __future__ import annotations

import io
from importlib import resources
from pathlib import Path

import numpy as np
import pinocchio as pin
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import run_cli_printed
from wbfriction.logs.columns import is_truth_column
from wbfriction.logs.log import write_log
from wbfriction.logs.metadata import read_metadata
from wbfriction.model.loading import load_robot
from wbfriction.sim.logger import LoggerOptions, logger_clocks, write_raw_log
from wbfriction.sim.options import SensorNoise
from wbfriction.sim.quadruped import QuadrupedOptions
from wbfriction.sim.quadruped_mujoco import UNITREE_NOISE, simulate_quadruped_mujoco
from wbfriction.walking.quadruped import GaitOptions, quadruped_reference

TOML = Path(str(resources.files("wbfriction.model.robots").joinpath("go2_logged.toml")))  # the built-in twin's
RAW_PREFIXES = ("q", "q_cos", "q_sin", "qd", "current", "foot_count")
RAW_IMU = {f"imu.{a}" for a in ("roll", "pitch", "yaw", "gyro_x", "gyro_y", "gyro_z")}


@pytest.fixture(scope="module")
def robot():
    return load_robot(config=TOML)


@pytest.fixture(scope="module")
def trot(robot):
    """A 1.5 s trot on MuJoCo (2 ms samples, 0.5 ms physics steps), the twin's armature, exact sensors."""
    reference = quadruped_reference(robot, GaitOptions("trot", duration=1.5))
    return simulate_quadruped_mujoco(robot, reference, QuadrupedOptions())


@pytest.fixture(scope="module")
def raw(robot, trot):
    return write_raw_log(trot, robot, LoggerOptions(foot_counts=True))


def column(table: pa.Table, name: str) -> np.ndarray:
    return table[name].to_numpy()


def test_rows_repeat_exactly_where_the_clocks_say(robot, trot, raw):
    """Row ``i`` (at ``i x 1.22 ms``) holds drive sample ``floor(i x 1.22 / 2)`` (integer arithmetic), its values
    exactly; rows holding the same sample are equal in every measured column, rows holding the next one differ; every
    drive sample is logged."""
    sample = column(raw, "sample_true")
    rows = np.arange(raw.num_rows)
    np.testing.assert_array_equal(sample, rows * 122 // 200)
    assert sample[-1] == len(trot.log) - 1 and raw.num_rows == (len(trot.log) * 200 - 1) // 122 + 1
    np.testing.assert_array_equal(np.unique(sample), np.arange(len(trot.log)))
    measured = np.column_stack([column(raw, c) for c in raw.column_names if c.partition(".")[0] in RAW_PREFIXES])
    repeat = sample[1:] == sample[:-1]
    assert repeat.mean() == pytest.approx(1 - 1.22 / 2, abs=2 / raw.num_rows)
    same = np.all(measured[1:] == measured[:-1], axis=1)
    np.testing.assert_array_equal(same, repeat)  # a row equal to the previous one is exactly a repeat
    for i, j in enumerate(robot.actuated):
        np.testing.assert_array_equal(column(raw, f"q.{j}"), trot.log.q[sample, i])
        np.testing.assert_array_equal(column(raw, f"qd.{j}"), trot.log.qd_logged[sample, i])
    np.testing.assert_array_equal(column(raw, "time_true"), trot.log.time[sample])
    md = read_metadata(raw)
    assert md["logger"]["period"] == 1.22e-3 and md["logger_true"]["repeated_rows"] == int(repeat.sum())


@settings(max_examples=60, deadline=None)
@given(st.floats(0.3e-3, 4e-3), st.floats(1e-3, 20e-3), st.integers(2, 400))
def test_the_clocks_hold_the_latest_sample(period, imu_period, n):
    """Any logger and IMU period: each tick holds the latest drive sample at or before it and the latest IMU update,
    the last tick within a logger period of the run's end; the repeats are the rows less the distinct samples."""
    drive = 2e-3
    c = logger_clocks(n, drive, LoggerOptions(period=period, imu_period=imu_period))
    assert np.all(np.diff(c.sample) >= 0) and c.sample[0] == 0 and (c.sample[-1] + 1) * drive > n * drive - period
    if period <= drive:  # a logger faster than the drives logs every sample
        np.testing.assert_array_equal(np.unique(c.sample), np.arange(n))
    assert np.all(c.sample * drive <= c.tick + 1e-12) and np.all(c.tick < (c.sample + 1) * drive + 1e-12)
    assert np.all(c.imu_update * imu_period <= c.tick + 1e-12) and np.all(c.tick < (c.imu_update + 1) * imu_period
                                                                          + 1e-12)
    assert np.all(c.imu_sample * drive <= c.imu_update * imu_period + 1e-12) and np.all(c.imu_sample <= c.sample)
    assert c.repeats().sum() == len(c.sample) - len(np.unique(c.sample))
    assert c.imu_repeats().sum() == len(c.sample) - len(np.unique(c.imu_update))


@pytest.mark.parametrize("imu_period", [5e-3, 4e-3])
def test_the_imu_repeats_at_its_rate(robot, trot, imu_period):
    """The IMU's columns change only at its updates (every ``imu_period``): the share of rows repeating them is
    ``1 - 1.22 / imu_period`` within a row; each holds the sample at or before its update."""
    raw = write_raw_log(trot, robot, LoggerOptions(imu_period=imu_period))
    imu = np.column_stack([column(raw, c) for c in sorted(RAW_IMU)])
    repeat = np.all(imu[1:] == imu[:-1], axis=1)
    assert repeat.mean() == pytest.approx(1 - 1.22e-3 / imu_period, abs=2 / raw.num_rows)
    update = np.arange(raw.num_rows) * 1220 // int(round(imu_period * 1e6))
    np.testing.assert_array_equal(repeat, update[1:] == update[:-1])
    np.testing.assert_array_equal(column(raw, "imu_sample_true"), update * int(round(imu_period * 1e6)) // 2000)
    np.testing.assert_array_equal(column(raw, "imu.gyro_z"), trot.log.imu[column(raw, "imu_sample_true"), 2])


def test_currents_are_the_applied_torque_off_by_the_drawn_error(robot, trot, raw):
    """``current x nominal constant x (1 + e)`` is the torque MuJoCo's actuator applied (its joint's armature the
    rotor), ``e`` the metadata's, each within the ±3 % drawn and not zero; the twin ran with the TOML's armature."""
    md = read_metadata(raw)
    errors = md["logger_true"]["torque_constant_error"]
    sample = column(raw, "sample_true")
    assert md["armature_true"] == pytest.approx(dict(zip(robot.actuated, robot.model.armature[robot.act_v_index])))
    for i, j in enumerate(robot.torque_controlled):
        e = errors[j]
        assert 0 < abs(e) <= 0.03
        nominal = column(raw, f"current.{j}") * robot.torque_constants[j]
        np.testing.assert_allclose(nominal * (1 + e), trot.tau_motor[sample, i], rtol=1e-13, atol=1e-13)
        moving = np.abs(nominal) > 0.5
        np.testing.assert_allclose(trot.tau_motor[sample, i][moving] / nominal[moving] - 1, e, atol=1e-12)
    assert len(set(errors.values())) == len(errors)


def test_roll_pitch_yaw_give_back_the_imu_frame_rotation(robot, trot):
    """``rpyToMatrix(roll, pitch, yaw)`` is the IMU frame's world rotation at the sample its update holds; the
    cosine/sine pairs give back the angles; the orientation's noise turns it by about its standard deviation."""
    raw = write_raw_log(trot, robot, LoggerOptions(angles="cos-sin"))
    noisy = write_raw_log(trot, robot, LoggerOptions(orientation_std=1e-3))
    model, data, frame = robot.model, robot.model.createData(), robot.imu.frame
    held = column(raw, "imu_sample_true")
    turned = []
    for row in range(0, raw.num_rows, 37):
        pin.forwardKinematics(model, data, trot.q[held[row]])
        R = pin.updateFramePlacement(model, data, frame).rotation
        rpy = [column(raw, c)[row] for c in ("imu.roll", "imu.pitch", "imu.yaw")]
        np.testing.assert_allclose(pin.rpy.rpyToMatrix(*rpy), R, atol=1e-12)
        noisy_rpy = [column(noisy, c)[row] for c in ("imu.roll", "imu.pitch", "imu.yaw")]
        turned.append(np.linalg.norm(pin.log3(R.T @ pin.rpy.rpyToMatrix(*noisy_rpy))))
    assert 1e-3 < np.sqrt(np.mean(np.square(turned)) / 3) * 2 < 4e-3  # sqrt(3) sigma's norm, within a factor 2
    sample = column(raw, "sample_true")
    for i, j in enumerate(robot.actuated):
        angle = np.arctan2(column(raw, f"q_sin.{j}"), column(raw, f"q_cos.{j}"))
        np.testing.assert_allclose(angle, trot.log.q[sample, i], atol=1e-14)


def test_no_contact_base_or_force_column(robot, trot, raw):
    """Every column is one a robot's logger writes or the truth (:func:`~wbfriction.logs.columns.is_truth_column`):
    no ``time``, ``contact.*``, ``base.*``, ``force.*``, ``tau.*`` or accelerometer; the truth's contacts are the
    simulator's (a nonzero normal force on the foot); the foot counts are its force through their drawn calibration."""
    for name in raw.column_names:
        assert name in RAW_IMU or name.partition(".")[0] in RAW_PREFIXES or is_truth_column(name), name
    assert not [c for c in raw.column_names if c == "time" or c.partition(".")[0] in ("contact", "base", "force",
                                                                                      "tau", "wrench")]
    sample = column(raw, "sample_true")
    calibration = read_metadata(raw)["logger_true"]["foot_counts"]
    for c, f in enumerate(robot.contact_frames):
        normal = trot.force[sample, c, 2]
        np.testing.assert_array_equal(column(raw, f"contact_true.{f}"), normal != 0)
        counts = column(raw, f"foot_count.{f}")
        offset, scale = calibration["offset"][c], calibration["scale"][c]
        assert np.abs((counts - offset) / scale - normal).max() <= 0.5 / scale + 1e-9
        assert 0.1 < (normal > 0).mean() < 0.9  # a trot: each foot swings and stands
    stamped = write_raw_log(trot, robot, LoggerOptions(stamps="logger", accelerometer=True))
    np.testing.assert_allclose(np.diff(column(stamped, "time")), 1.22e-3, rtol=1e-9)
    assert {"imu.acc_x", "imu.acc_y", "imu.acc_z"} <= set(stamped.column_names)


def parquet_bytes(table: pa.Table) -> bytes:
    out = io.BytesIO()
    pq.write_table(table, out)
    return out.getvalue()


def test_same_seed_same_bytes(robot, trot, raw):
    """The same run and seed give the same bytes; another seed other torque-constant errors, the same clocks; asking
    for foot counts changes no other column."""
    again = write_raw_log(trot, robot, LoggerOptions(foot_counts=True))
    assert parquet_bytes(again) == parquet_bytes(raw)
    other = write_raw_log(trot, robot, LoggerOptions(foot_counts=True, seed=1))
    assert parquet_bytes(other) != parquet_bytes(raw)
    np.testing.assert_array_equal(column(other, "sample_true"), column(raw, "sample_true"))
    bare = write_raw_log(trot, robot, LoggerOptions())
    for name in bare.column_names:
        np.testing.assert_array_equal(column(bare, name), column(raw, name))


def test_cli_full_is_todays_log_and_raw_is_deterministic(robot, capsys, tmp_path):
    """``simulate`` on MuJoCo: ``--logger full`` (and no ``--logger``) writes the simulator's log as the library
    writes it; ``--logger raw`` twice, with a Unitree-like robot's noise, the same bytes, its rows repeating exactly
    where ``sample_true`` says."""
    base = ("simulate", "--robot", TOML, "--simulator", "mujoco", "--gait", "walk", "--duration", "0.6")
    for name, extra in (("default", ()), ("full", ("--logger", "full"))):
        code, _, err = run_cli_printed(capsys, *base, *extra, "-o", tmp_path / f"{name}.parquet")
        assert code == 0, err
    reference = quadruped_reference(robot, GaitOptions("walk", duration=0.6))
    run = simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(noise=SensorNoise()))  # the command's options
    write_log(run.log, robot, tmp_path / "library.parquet")
    library = (tmp_path / "library.parquet").read_bytes()
    assert (tmp_path / "default.parquet").read_bytes() == library == (tmp_path / "full.parquet").read_bytes()
    noisy = (*base, "--logger", "raw", "--sensor-noise", "unitree", "--angles", "cos-sin", "--foot-counts")
    for name in ("a", "b"):
        code, out, err = run_cli_printed(capsys, *noisy, "-o", tmp_path / f"{name}.parquet")
        assert code == 0, err
    assert "repeating the drives' sample" in out + err
    assert (tmp_path / "a.parquet").read_bytes() == (tmp_path / "b.parquet").read_bytes()
    table = pq.read_table(tmp_path / "a.parquet")
    md = read_metadata(table)
    assert md["noise"]["gyro_std"] == UNITREE_NOISE.gyro_std and md["logger_true"]["orientation_std"] > 0
    sample = column(table, "sample_true")
    measured = np.column_stack([column(table, c) for c in table.column_names if c.partition(".")[0] in RAW_PREFIXES])
    np.testing.assert_array_equal(np.all(measured[1:] == measured[:-1], axis=1), sample[1:] == sample[:-1])


@pytest.mark.parametrize(("args", "message"), [
    (("--robot", "go2_walking", "--logger", "raw"), "[torque_constants] lacks 'FL_hip_joint'"),
    (("--robot", TOML, "--logger-period", "1"), "--logger-period: an option of the raw log"),
    (("--robot", TOML, "--logger", "raw", "--kt-error", "0.7"), "--kt-error must be in [0, 0.5)"),
    (("--robot", TOML, "--logger", "raw", "--sensor-noise", "unitree", "--torque-noise", "0.1"),
     "--torque-noise: --sensor-noise unitree gives every sensor's noise"),
])
def test_refused_in_one_line_before_the_simulation(capsys, tmp_path, args, message):
    """A robot without what the raw log needs, a raw option with the full log, a value out of range, a noise option
    the preset replaces: one line, before anything is simulated (a 60 s gait would take a minute)."""
    code, out, err = run_cli_printed(capsys, "simulate", *args, "--simulator", "mujoco", "--duration", "60",
                                     "-o", tmp_path / "x.parquet")
    assert code != 0 and message in err and "simulate:" not in out + err
    assert not (tmp_path / "x.parquet").exists()


def test_a_robot_named_by_its_toml():
    """``--robot`` ending in ``.toml`` is the robot TOML (as ``--config``): the twin's loads so."""
    from wbfriction.model.loading import RobotSpec

    assert RobotSpec.given(str(TOML)) == RobotSpec(None, None, str(TOML))
    assert RobotSpec.given("go2_walking") == RobotSpec("go2_walking")
