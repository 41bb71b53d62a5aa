"""Logs as loggers write them (wbfriction.logs.raw_table): no stamps, angles as cosine/sine pairs, rows repeating
the drives' samples, an IMU and foot counts at their own slower rates; and a log in the log format unchanged."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pytest

from helpers import logger_sampling
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.angles import angles_from_pairs, rpy_quaternions
from wbfriction.logs.log import check_schema, log_from_table
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.raw_table import condition_raw_table
from wbfriction.model.loading import load_robot

DRIVE, LOGGER, IMU, FEET = 2e-3, 1.22e-3, 5e-3, 3.3e-3


@pytest.fixture(scope="module")
def walker():
    return load_robot("go2_walking")


def raw_log(robot, duration=4.0, hold=0.02, stamped=False, seed=0):
    """A raw log as the issue's quadruped writes it: a logger at 1.22 ms over drives at 2 ms (some periods held),
    angles as cosine/sine pairs, an IMU (roll, pitch, yaw, yaw wrapping; gyro, no accelerometer) at 5 ms and foot
    counts at 3.3 ms, each repeating on the logger's rows; no stamps unless ``stamped``. Returns the table and the
    truth."""
    rng = np.random.default_rng(seed)
    stamps, _, true, shown = logger_sampling(DRIVE, LOGGER, duration, hold, seed=seed)
    lo, hi = robot.angle_limits
    n = len(robot.actuated)
    f = 1.0 + 0.1 * np.arange(n)
    q = 0.5 * (lo + hi) + 0.3 * np.sin(np.outer(true, f) + np.arange(n))  # the thighs beyond pi: 3.3 rad
    q[:, 1] = 3.3 + 0.1 * np.sin(true)
    tau = 2.0 * np.sin(np.outer(true, 2 * f)) + 0.01 * rng.normal(size=q.shape)
    cols: dict[str, np.ndarray] = {"time": stamps} if stamped else {}
    for i, j in enumerate(robot.actuated):
        cols[f"q_cos.{j}"], cols[f"q_sin.{j}"] = np.cos(q[shown, i]), np.sin(q[shown, i])
        cols[f"qd.{j}"] = np.cos(true)[shown] * f[i]
        cols[f"tau.{j}"] = tau[shown, i]
    it = 0.7e-3 + IMU * np.arange(int(true[-1] / IMU) + 2)
    rpy = np.column_stack([0.1 * np.sin(it), 0.05 * np.cos(2 * it), np.pi - 0.2 + 0.5 * it])
    ishown = np.maximum(np.searchsorted(it, stamps, side="right") - 1, 0)
    for k, a in enumerate(("roll", "pitch", "yaw")):
        cols[f"imu.{a}"] = np.angle(np.exp(1j * rpy[ishown, k]))
    for k, a in enumerate(("gyro_x", "gyro_y", "gyro_z")):
        cols[f"imu.{a}"] = np.column_stack([np.cos(it), np.sin(it), 0.5 + 0 * it])[ishown, k]
    ft = 1.1e-3 + FEET * np.arange(int(true[-1] / FEET) + 2)
    fshown = np.maximum(np.searchsorted(ft, stamps, side="right") - 1, 0)
    for k, frame in enumerate(robot.contact_frames):
        cols[f"foot_count.{frame}"] = (100 + 50 * np.sin(ft + k))[fshown]
        cols[f"contact.{frame}"] = np.ones(len(stamps), dtype=np.int8)
    return pa.table(cols), {"true": true, "shown": shown, "q": q, "stamps": stamps}


def test_a_raw_log_is_read_at_its_drives_sample_times(walker):
    table, truth = raw_log(walker)
    log = log_from_table(table, walker, "raw", ReadOptions(rate=1 / LOGGER))
    used = np.unique(truth["shown"])
    assert len(log) == used.size  # one row per distinct sample
    # the nominal stamps count from the first row: the truth's first tick is the logger's origin
    err = log.time + truth["stamps"][0] - truth["true"][used]
    assert np.abs(err).max() < 0.1 * LOGGER
    np.testing.assert_allclose(log.q, truth["q"][used], atol=1e-12)  # atan2, on the turn within the limits
    # the drives' clock with its holds, on the stamps as re-estimated: not receive-time jitter
    assert log.clock.kind == "skipping" and log.clock.lattice == pytest.approx(DRIVE, rel=1e-4)
    assert len(log.clock.segments) == 1
    (line,) = [w for w in log.warnings if "repeat" in w]
    assert "merged; drive period 2.00 ms re-estimated" in line and "no time stamps" in line
    # the IMU at the joints' true sample times: its gyro, and its orientation in pinocchio's rpy convention
    at = log.time + truth["stamps"][0]
    gyro = np.column_stack([np.cos(at), np.sin(at), 0.5 + 0 * at])
    assert np.abs(log.imu[:, :3] - gyro).max() < 1e-3  # within half a logger period's motion
    assert np.isnan(log.imu[:, 3:]).all()  # no accelerometer
    rpy = np.column_stack([0.1 * np.sin(at), 0.05 * np.cos(2 * at), np.pi - 0.2 + 0.5 * at])
    dots = np.abs(np.sum(log.imu_orientation * rpy_quaternions(rpy), axis=1))
    assert np.degrees(2 * np.arccos(np.clip(dots, -1, 1))).max() < 0.05  # the wrapping yaw unwrapped first
    counts = np.column_stack([100 + 50 * np.sin(at + k) for k in range(4)])
    assert log.foot_counts.shape == (len(log), 4) and np.abs(log.foot_counts - counts).max() < 0.1


def test_a_stamped_raw_log_reads_as_the_unstamped_one(walker):
    table, truth = raw_log(walker, stamped=True)
    _, report = condition_raw_table(table, walker, "raw")
    assert report.rate is None and report.samples == np.unique(truth["shown"]).size
    assert report.drive_period == pytest.approx(DRIVE, rel=1e-4)
    assert report.repeated["joints"] == pytest.approx(1 - report.samples / report.rows)
    assert report.repeated["imu"] > 0.7 and report.resampled == ("imu", "foot_count")
    log = log_from_table(table, walker, "raw")
    assert np.abs(log.time - truth["true"][np.unique(truth["shown"])]).max() < 0.1 * LOGGER


def test_repeats_kept_on_request(walker):
    table, _ = raw_log(walker)
    log = log_from_table(table, walker, "raw", ReadOptions(rate=1 / LOGGER, repeats="keep"))
    assert len(log) == table.num_rows
    assert any("kept (--repeats keep)" in w for w in log.warnings)


def test_stamps_from_a_nominal_rate_are_exact_ticks(walker):
    table, _ = raw_log(walker, duration=1.0)
    table = table.drop_columns([c for c in table.column_names if c.startswith(("imu.", "foot_count."))])
    log = log_from_table(table, walker, "raw", ReadOptions(rate=500.0, repeats="keep"))
    np.testing.assert_array_equal(log.time, np.arange(table.num_rows) / 500.0)
    assert log.clock.kind == "uniform" and log.clock.step == pytest.approx(2e-3)


def test_a_log_without_time_names_the_rate_option(walker):
    table, _ = raw_log(walker, duration=0.5)
    with pytest.raises(ColumnError, match=r"missing column 'time'.*--rate HZ"):
        log_from_table(table, walker, "raw")
    with pytest.raises(ColumnError, match=r"--rate HZ"):
        check_schema(table.schema, walker, "raw")
    check_schema(raw_log(walker, duration=0.5, stamped=True)[0].schema, walker, "raw")  # its raw columns known


def test_too_few_distinct_samples_are_refused_with_the_counts(walker):
    table, truth = raw_log(walker, duration=0.05, stamped=True)
    k = np.unique(truth["shown"]).size
    with pytest.raises(InputError, match=rf"{table.num_rows} rows hold only {k} distinct samples"):
        condition_raw_table(table, walker, "raw", min_samples=k + 1)


def test_cosine_sine_pairs_refused_when_they_are_none_or_twice(walker):
    table, _ = raw_log(walker, duration=0.2, stamped=True)
    j = walker.actuated[3]
    bad = table.column(f"q_cos.{j}").to_numpy().copy()
    bad[7] = 3.0
    with pytest.raises(ColumnError, match=rf"'q_cos.{j}' and 'q_sin.{j}' are no cosine/sine pair at row 7"):
        condition_raw_table(table.set_column(table.schema.get_field_index(f"q_cos.{j}"), f"q_cos.{j}",
                                             pa.array(bad)), walker, "raw")
    with pytest.raises(ColumnError, match=rf"joint '{j}' is given twice"):
        condition_raw_table(table.append_column(f"q.{j}", table.column(f"q_sin.{j}")), walker, "raw")
    with pytest.raises(ColumnError, match=rf"missing column 'q_sin.{j}'"):
        condition_raw_table(table.drop_columns([f"q_sin.{j}"]), walker, "raw")


def test_a_continuous_joints_turns_are_kept():
    q = np.linspace(0.0, 6 * np.pi, 500)
    np.testing.assert_allclose(angles_from_pairs(np.cos(q), np.sin(q), "wheel", "raw"), q, atol=1e-12)


def test_a_gyro_without_accelerometer_refuses_the_imu_base_motion(walker):
    from wbfriction.signals.kinematics import measure

    table, _ = raw_log(walker, duration=0.3, stamped=True)
    log = log_from_table(table, walker, "raw")
    with pytest.raises(InputError, match=r"--base-motion imu needs .* gyro without an accelerometer"):
        measure(log, imu=True)


def test_a_log_in_the_log_format_is_not_changed(combined_walk, talos):
    """The demo's simulated walk: no repeat, its stamps, q columns: the same table, the same log."""
    table = combined_walk.log.to_table(talos)
    out, report = condition_raw_table(table, talos, "walk")
    assert out is table and not report.changed and report.reason == ""
    assert report.repeated["joints"] == 0.0
    log = log_from_table(table, talos, "walk")
    assert not any("repeat" in w for w in log.warnings)
    np.testing.assert_array_equal(log.time, table.column("time").to_numpy())


@pytest.mark.parametrize("kwargs, option", [({"rate": 0.0}, "--rate"), ({"rate": float("nan")}, "--rate"),
                                            ({"repeats": "drop"}, "--repeats")])
def test_read_options_refuse_a_rate_or_a_policy_out_of_range(kwargs, option):
    from wbfriction.exceptions import OptionError

    with pytest.raises(OptionError, match=rf"^{option} must be"):
        ReadOptions(**kwargs)
