"""A quadruped's foot forces in the log format (wbfriction.logs.foot_forces): read as written, contact flags from
them, what is refused; point contacts in the robot TOML."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pytest

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.log import log_from_table
from wbfriction.model.loading import build_robot, example_robot_data_dir, load_robot

FEET = ("FL_foot", "FR_foot", "RL_foot", "RR_foot")


@pytest.fixture(scope="module")
def go2():
    return load_robot("go2_walking")


def table(robot, n: int = 50, contact: bool = True, **extra) -> pa.Table:
    cols = {"time": np.arange(n) * 0.002}
    cols.update({f"q.{j}": np.full(n, a) for j, a in zip(robot.actuated, robot.reference_angles)})
    cols.update({f"tau.{j}": np.zeros(n) for j in robot.torque_controlled})
    if contact:
        cols.update({f"contact.{f}": np.ones(n, dtype=np.int8) for f in FEET})
    cols.update(extra)
    return pa.table(cols)


def test_three_components_and_normals_are_read(go2):
    n = 50
    fz = np.linspace(0, 80, n)
    extra = {f"force.FL_foot.{a}": v for a, v in zip("xyz", (np.ones(n), 2 * np.ones(n), fz))}
    extra["force.RR_foot"] = fz
    log = log_from_table(table(go2, **extra), go2, "walk.parquet")
    assert log.foot_force.shape == (n, 4, 3)
    assert np.array_equal(log.foot_force[:, 0, 2], fz) and (log.foot_force[:, 0, 1] == 2).all()
    assert np.isnan(log.foot_force[:, 3, :2]).all() and np.array_equal(log.foot_force[:, 3, 2], fz)
    assert np.isnan(log.foot_force[:, 1:3]).all()
    back = log.to_table(go2)
    assert {c for c in back.column_names if c.startswith("force.")} == set(extra)


def test_contact_flags_from_normal_forces(go2):
    """No contact.* column: each foot's flag from its normal force, with the robot's hysteresis (on above 10 % of
    the weight, off below 5 %)."""
    n = 60
    weight = 16.085 * 9.81
    fz = np.r_[np.zeros(20), np.full(20, 0.5 * weight), np.full(10, 0.07 * weight), np.zeros(10)]
    extra = {f"force.{f}": fz for f in FEET}
    log = log_from_table(table(go2, n, contact=False, **extra), go2, "walk.parquet")
    expected = np.r_[np.zeros(20), np.ones(30), np.zeros(10)].astype(bool)  # 7 % keeps the flag on
    assert (log.contact == expected[:, None]).all()


@pytest.mark.parametrize("extra, message", [
    ({"force.FL_foot.x": np.zeros(50), "force.FL_foot.z": np.zeros(50)}, "missing column 'force.FL_foot.y'"),
    ({"force.FL_foot": np.zeros(50), **{f"force.FL_foot.{a}": np.zeros(50) for a in "xyz"}}, "not both"),
    ({"force.LF_foot": np.zeros(50)}, "unknown foot"),
])
def test_bad_force_columns_are_refused(go2, extra, message):
    with pytest.raises(ColumnError, match=message):
        log_from_table(table(go2, **extra), go2, "walk.parquet")


def test_contact_model_in_the_toml():
    urdf = example_robot_data_dir() / "go2_description" / "urdf" / "go2.urdf"
    base = {"name": "q", "contact_frames": list(FEET)}
    robot = build_robot(urdf, {**base, "contact_model": {"FL_foot": "point"}})
    assert robot.contact_dims == (3, 6, 6, 6) and robot.partial_contacts
    assert build_robot(urdf, base).contact_dims == (6, 6, 6, 6)
    with pytest.raises(InputError, match="contact_model of 'FL_foot' is 'ball'"):
        build_robot(urdf, {**base, "contact_model": {"FL_foot": "ball"}})
    with pytest.raises(InputError, match="not one of contact_frames"):
        build_robot(urdf, {**base, "contact_model": {"base": "point"}})
