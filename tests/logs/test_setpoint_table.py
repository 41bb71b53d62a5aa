"""The set-points table ``excite`` writes and ``simulate --play`` reads (:mod:`wbfriction.logs.setpoint_table`):
what is written is read back, in every format, and a table that cannot be played is refused in one line naming the
file and the column."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import wbfriction
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.setpoint_table import read_setpoint_table, setpoint_table
from wbfriction.logs.tables import write_table


@pytest.fixture(scope="module")
def go2():
    return wbfriction.load_robot("go2")


@settings(max_examples=15, deadline=None)
@given(n=st.integers(2, 50), rate=st.sampled_from([100.0, 200.0, 500.0, 1000.0]), seed=st.integers(0, 2**16),
       suffix=st.sampled_from([".parquet", ".csv"]), velocity=st.booleans())
def test_what_is_written_is_read_back(go2, tmp_path_factory, n, rate, seed, suffix, velocity):
    rng = np.random.default_rng(seed)
    time = np.arange(n) / rate
    q_des, qd_des = _valid_table(go2, n, seed)[1], rng.normal(size=(n, go2.n_act)) * velocity
    path = tmp_path_factory.mktemp("sp") / f"design{suffix}"
    write_table(setpoint_table(go2.name, go2.actuated, time, q_des, qd_des), path)
    read = read_setpoint_table(path, go2)
    assert read.joints == go2.actuated and read.rate == pytest.approx(rate)
    assert read.duration == pytest.approx(n / rate)
    np.testing.assert_array_equal(read.q_des, q_des)
    np.testing.assert_array_equal(read.qd_des, qd_des)


def test_a_table_that_cannot_be_played_is_refused_naming_its_column(go2, tmp_path):
    time = np.arange(10) / 200.0
    q = _valid_table(go2, 10, 0)[1]
    table = setpoint_table(go2.name, go2.actuated, time, q, q)
    path = tmp_path / "d.parquet"
    write_table(table.drop_columns([f"q_des.{go2.actuated[3]}"]), path)
    with pytest.raises(ColumnError, match=f"missing column 'q_des.{go2.actuated[3]}'"):
        read_setpoint_table(path, go2)
    write_table(table.drop_columns([f"qd_des.{go2.actuated[0]}"]), path)
    with pytest.raises(ColumnError, match="qd_des.\\* is given for some joints only"):
        read_setpoint_table(path, go2)
    uneven = setpoint_table(go2.name, go2.actuated, np.r_[time[:5], time[5:] + 0.001], q, q)
    write_table(uneven, path)
    with pytest.raises(ColumnError, match="row 5 of column 'time'") as err:
        read_setpoint_table(path, go2)
    assert err.value.row == 5 and str(path) in str(err.value)


@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
def test_a_stances_series_and_foot_are_read_back(go2, tmp_path, suffix):
    """A one-foot stance's table (``excite --stance``): the series of some joints only, named, and the foot."""
    time = np.arange(10) / 1000.0
    q = _valid_table(go2, 10, 0)[1]
    series = {"center": [0.1, -0.2], "a": [[0.3, 0.4], [0.5, 0.6]], "b": [[0.0, 0.1], [0.2, 0.3]], "omega": 1.5}
    joints = (go2.actuated[2], go2.actuated[5])
    path = tmp_path / f"stance{suffix}"
    write_table(setpoint_table(go2.name, go2.actuated, time, q, q, series, fourier_joints=joints, stance="right"),
                path)
    read = read_setpoint_table(path, go2)
    assert read.stance == "right" and read.fourier_joints == joints and read.fourier is not None
    for key, value in series.items():
        np.testing.assert_array_equal(read.fourier[key], value)
    write_table(setpoint_table(go2.name, go2.actuated, time, q, q, series, fourier_joints=("knee", joints[1])), path)
    with pytest.raises(InputError, match="its Fourier series names joint 'knee'"):
        read_setpoint_table(path, go2)
    write_table(setpoint_table(go2.name, go2.actuated, time, q, q, series, fourier_joints=joints[:1]), path)
    with pytest.raises(InputError, match="its Fourier coefficients are of 2 joints, it names 1"):
        read_setpoint_table(path, go2)
    write_table(setpoint_table(go2.name, go2.actuated, time, q, q, stance="both"), path)
    with pytest.raises(InputError, match="its stance 'both' is not 'left' or 'right'"):
        read_setpoint_table(path, go2)


@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
def test_a_three_feet_stances_swing_foot_and_height_are_read_back(tmp_path, suffix):
    """A quadruped's three-feet stance (``excite --swing``): the foot lifted, one of the robot's, and the base's
    height, which the stance needs to be rebuilt."""
    go2 = wbfriction.load_robot("go2_walking")
    time = np.arange(10) / 500.0
    q = _valid_table(go2, 10, 0)[1]
    series = {"center": [0.1], "a": [[0.3]], "b": [[0.2]], "omega": 1.5}
    path = tmp_path / f"tripod{suffix}"
    write_table(setpoint_table(go2.name, go2.actuated, time, q, q, series, fourier_joints=go2.actuated[3:4],
                               swing="FR_foot", base_height=0.3), path)
    read = read_setpoint_table(path, go2)
    assert (read.swing, read.base_height, read.stance, read.fourier_joints) == ("FR_foot", 0.3, None, ("FR_hip_joint",))
    for swing, height, line in [("FR", 0.3, "its swing foot 'FR' is not one of robot 'go2_walking''s feet (FL_foot, "),
                                ("RL_foot", None, "its swing foot RL_foot without a base height > 0"),
                                ("RL_foot", -0.1, "its swing foot RL_foot without a base height > 0")]:
        write_table(setpoint_table(go2.name, go2.actuated, time, q, q, swing=swing, base_height=height), path)
        with pytest.raises(InputError, match=line.replace("(", r"\(")):
            read_setpoint_table(path, go2)


def _valid_table(robot, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``(time, q_des)``: ``n`` set-points within the joints' limits (encoder coordinates), at 500 Hz."""
    rng = np.random.default_rng(seed)
    lower, upper = robot.angle_limits
    middle, half = (lower + upper) / 2, (upper - lower) / 2
    return np.arange(n) / 500.0, middle + 0.9 * half * rng.uniform(-1, 1, (n, robot.n_act)) + robot.offset_vector


def _first_beyond(robot, q: np.ndarray) -> tuple[str, int]:
    """The first column (the robot's order) with a value beyond its limits by more than the margin, and its row."""
    lower, upper = robot.angle_limits
    for i, j in enumerate(robot.actuated):
        off = robot.encoder_offset.get(j, 0.0)
        out = np.flatnonzero((q[:, i] < lower[i] + off - 0.2) | (q[:, i] > upper[i] + off + 0.2))
        if out.size:
            return f"q_des.{j}", int(out[0])
    raise AssertionError("nothing beyond the limits")


@settings(max_examples=25, deadline=None)
@given(factor=st.one_of(st.sampled_from([180 / np.pi, 1000.0, 0.0, 1 / (2 * np.pi)]), st.floats(4.0, 1e4),
                        st.floats(0.0, 0.2)),
       n=st.integers(2, 40), seed=st.integers(0, 2**16), suffix=st.sampled_from([".parquet", ".csv"]))
def test_set_points_in_other_units_are_refused_naming_the_column_and_the_robot(go2, tmp_path_factory, factor, n, seed,
                                                                               suffix):
    """Round 5 (class 4): set-points in degrees drove a calf to -129 rad and wrote a log ``identify`` refused. A table
    within the joints' limits reads; the same scaled by a factor no unit of angle makes plausible (degrees,
    milliradians, turns: x4 and beyond, x0.2 and below put the Go2's calves beyond their limits) is refused as
    ``identify`` refuses a log's, in one line naming the file, the first column beyond its limits, the row and the
    robot."""
    time, q = _valid_table(go2, n, seed)
    path = tmp_path_factory.mktemp("units") / f"design{suffix}"
    write_table(setpoint_table(go2.name, go2.actuated, time, q, np.zeros_like(q)), path)
    np.testing.assert_array_equal(read_setpoint_table(path, go2).q_des, q)
    write_table(setpoint_table(go2.name, go2.actuated, time, factor * q, np.zeros_like(q)), path)
    column, row = _first_beyond(go2, factor * q)
    with pytest.raises(ColumnError) as err:
        read_setpoint_table(path, go2)
    assert (err.value.column, err.value.row) == (column, row), err.value
    line = str(err.value)
    assert line.startswith(f"{path}: column '{column}' is ") and f"at row {row}, beyond its limits" in line
    assert "wrong units" in line and "robot 'go2'" in line and "\n" not in line


def test_a_table_made_for_another_robot_is_refused_naming_both(go2, tmp_path):
    """Round 5 (class 4): a Go2's design played on the Aliengo (the same joints' names, the table's metadata says
    ``go2``). The robot a table was made for is its metadata's; a table that records none (written by hand) is
    played on any robot with its joints."""
    time, q = _valid_table(go2, 10, 0)
    path = tmp_path / "go2.parquet"
    write_table(setpoint_table(go2.name, go2.actuated, time, q, q * 0), path)
    aliengo = dataclasses.replace(go2, name="aliengo")
    with pytest.raises(InputError, match=f"^{path}: set-points made for robot 'go2' \\(its metadata\\), not for "
                                         "robot 'aliengo': play them on 'go2'"):
        read_setpoint_table(path, aliengo)
    write_table(setpoint_table(go2.name, go2.actuated, time, q, q * 0).replace_schema_metadata(None), path)
    np.testing.assert_array_equal(read_setpoint_table(path, aliengo).q_des, q)
