"""Issue 65, class 2: the physical range of every number a user gives, in one table
(:data:`wbfriction.quantities.RANGES`), refused outside it in one line naming the file and key, the column and row,
or the option; nothing written. Before: ``[armature] = 1e6``, ``[encoder_offset] = 100`` rad, ``foot_radius = 5`` m,
logged gains of -25, set-points in degrees, ``--encoder-bits 0``, ``--delay 1e6``, ``--physics-dt 1e-12`` were
taken silently; ``--duration nan`` / ``1e9`` and ``--excitation-seed -1`` ended in tracebacks."""

from __future__ import annotations

import math
import re

import numpy as np
import pyarrow as pa
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import run_cli, said
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.model import load_robot
from wbfriction.quantities import RANGES, first_outside, in_range


def outside(quantity: str) -> st.SearchStrategy:
    """Values a quantity must refuse: beyond either bound, the low one itself when open, a fraction where whole
    numbers are asked, non-finite numbers, booleans and text."""
    rng = RANGES[quantity]
    span = max(abs(rng.high - rng.low), 1.0)
    beyond = st.one_of(st.floats(rng.high + 1e-6 * span, rng.high + 1e3 * span, exclude_min=True),
                       st.floats(rng.low - 1e3 * span, rng.low - 1e-6 * span, exclude_max=True))
    odd = st.sampled_from([math.nan, math.inf, -math.inf, True, "1"])
    extra = [st.just(rng.low)] if rng.low_open else []
    if rng.integer:
        extra.append(st.just(rng.low + 0.5))
    return st.one_of(beyond, odd, *extra)


def inside(quantity: str) -> st.SearchStrategy:
    rng = RANGES[quantity]
    if rng.integer:
        return st.integers(int(rng.low), int(rng.high))
    return st.floats(rng.low, rng.high, exclude_min=rng.low_open)


@settings(max_examples=30, deadline=None)
@given(data=st.data(), quantity=st.sampled_from(sorted(RANGES)))
def test_every_quantity_takes_its_range_and_refuses_the_rest_naming_where(data, quantity):
    value = data.draw(inside(quantity))
    assert in_range(quantity, value, "where") == float(value)
    bad = data.draw(outside(quantity))
    with pytest.raises(InputError, match=r"^where: ") as err:
        in_range(quantity, bad, "where")
    assert RANGES[quantity].span() in str(err.value) and "\n" not in str(err.value)


def test_first_outside_finds_the_first_bad_element_and_skips_missing_data():
    assert first_outside("kp", np.array([[25.0, math.nan], [25.0, -1.0], [-2.0, 3.0]])) == 3
    assert first_outside("kp", np.array([0.0, 1e5])) is None
    assert first_outside("duration", np.array([0.0])) == 0  # its low bound is open


GO2_LINES = {  # per quantity: the line of the built-in go2's TOML it replaces, the key the refusal names
    "armature": ("FL_hip_joint = 0.0110", "FL_hip_joint = {}", "[armature] FL_hip_joint"),
    "encoder_offset": ("FL_hip_joint = 0.020", "FL_hip_joint = {}", "[encoder_offset] FL_hip_joint"),
    "kp": ("kp = 25.0", "kp = {}", "[pd] kp of 'FL_hip_joint'"),
    "kd": ("kd = 0.5", "kd = {}", "[pd] kd of 'FL_hip_joint'"),
    "pd_delay": ("delay = 0.012", "delay = {}", "[pd] delay"),
    "torque_limit": ("delay = 0.012", "delay = 0.012\ntorque_limit = {}", "[pd] torque_limit of 'FL_hip_joint'"),
}


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    return {math.inf: "inf", -math.inf: "-inf"}.get(value, "nan" if value != value else repr(float(value)))


@settings(max_examples=25, deadline=None)
@given(data=st.data(), quantity=st.sampled_from(sorted(GO2_LINES)))
def test_a_robot_toml_with_a_value_out_of_range_is_refused_in_one_line(tmp_path_factory, data, quantity):
    from wbfriction.cli.common import config_text

    text, _ = config_text("go2", None)
    line, replacement, key = GO2_LINES[quantity]
    assert text.count(f"\n{line}\n") == 1
    bad = data.draw(outside(quantity))
    path = tmp_path_factory.mktemp("toml") / "go2.toml"
    path.write_text(text.replace(f"\n{line}\n", "\n" + replacement.format(_toml_value(bad)) + "\n"))
    with pytest.raises(InputError) as err:
        load_robot(None, config=path)
    assert str(err.value).startswith(f"{path}: {key}: ") and "\n" not in str(err.value), str(err.value)


def test_a_foot_radius_of_five_metres_is_refused(tmp_path):
    from wbfriction.cli.common import config_text

    text, _ = config_text("go2_walking", None)
    path = tmp_path / "big_feet.toml"
    path.write_text(f"foot_radius = 5.0\n{text}")
    with pytest.raises(InputError, match=re.escape(f"{path}: foot_radius: 5 m is outside [0, 0.25] m")):
        load_robot(None, config=path)


@pytest.mark.parametrize("groups, needle", [
    ("knee = 3", "[groups] knee must be a list of joint names"),
    ('knee = "FL_calf_joint"', "[groups] knee must be a list of joint names"),
])
def test_a_group_that_is_not_a_list_of_joints_is_refused(tmp_path, groups, needle):
    """Issue 65, class 4: ``[groups] knee = 3`` was a TypeError, ``knee = "FL_calf_joint"`` read letter by
    letter."""
    from wbfriction.cli.common import config_text

    text, _ = config_text("go2_walking", None)
    path = tmp_path / "groups.toml"
    path.write_text(text.replace("[groups]\n", f"[groups]\n{groups}\n"))
    with pytest.raises(InputError, match=re.escape(needle)):
        load_robot(None, config=path)


@pytest.mark.parametrize("args, needle", [
    (("simulate", "--robot", "go2", "--duration", "nan"), "--duration must be a number in (0, 3600] s ("),
    (("simulate", "--robot", "go2", "--duration", "1e9"), "--duration must be a number in (0, 3600] s ("),
    (("simulate", "--robot", "go2", "--excitation-seed", "-1"),
     "--excitation-seed must be a whole number in [0, 4294967295] ("),
    (("simulate", "--robot", "go2", "--encoder-bits", "0"), "--encoder-bits must be a whole number in [8, 32] ("),
    (("simulate", "--robot", "go2", "--delay", "1e6"), "--delay must be a number in [0, 500] ms ("),
    (("simulate", "--robot", "panda", "--position-noise", "-1"), "--position-noise must be a number in [0, 0.1] rad"),
    (("identify", "LOG", "--robot", "go2", "--actuator", "pd", "--delay", "20"),
     "--delay must be a number in [0, 0.5] s ("),
])
def test_an_option_out_of_range_is_refused_before_the_work(tmp_path, capsys, args, needle):
    """One line, exit 2, nothing written: the range's refusal, before the log is read or the simulation starts."""
    log = tmp_path / "in.parquet"
    log.write_bytes(b"refused before it is read")
    args = tuple(log if a == "LOG" else a for a in args)
    out = tmp_path / ("log.parquet" if args[0] == "simulate" else "out.json")  # each output named as its kind
    code, err = run_cli(capsys, *args, *(("-o", out) if args[0] == "simulate" else ("--json", out)))
    assert code == 2 and err.startswith(f"error: {needle}"), err
    assert len(said(err)) == 1 and not out.exists()


def test_an_export_physics_step_of_a_picosecond_is_refused(tmp_path, capsys):
    """``export --physics-dt 1e-12`` wrote ``min_delay: 11319580463`` steps."""
    (tmp_path / "p.json").write_text("{}")  # refused before it is read
    code, err = run_cli(capsys, "export", tmp_path / "p.json", "--robot", "go2", "--physics-dt", "1e-12", "-o",
                        tmp_path / "go2.yaml")
    assert code == 2 and "--physics-dt must be a number in [1e-05, 0.1] s (" in err, err
    assert not (tmp_path / "go2.yaml").exists()


@pytest.fixture(scope="module")
def go2():
    return load_robot("go2")


@pytest.fixture(scope="module")
def hung_log(go2):
    """A short log of the hung Go2 (every PD-driven joint's angle, velocity and set-point)."""
    from wbfriction.sim.hung import simulate_hung
    from wbfriction.sim.pd_options import HungOptions

    return simulate_hung(go2, HungOptions(duration=1.0)).table


def test_a_negative_logged_gain_is_refused_naming_its_column_and_row(go2, hung_log):
    from wbfriction.logs.log import log_from_table

    n = hung_log.num_rows
    kp = np.full(n, 25.0)
    kp[7] = -25.0
    table = hung_log.append_column("kp.FL_thigh_joint", pa.array(kp))
    for j in go2.pd.joints:
        if j != "FL_thigh_joint":
            table = table.append_column(f"kp.{j}", pa.array(np.full(n, 25.0)))
    with pytest.raises(ColumnError, match=re.escape("column 'kp.FL_thigh_joint' at row 7: -25 N·m/rad is outside "
                                                    "[0, 100000] N·m/rad")) as err:
        log_from_table(table, go2, "hung.parquet")
    assert (err.value.column, err.value.row) == ("kp.FL_thigh_joint", 7)


def test_set_points_in_degrees_are_refused_before_the_work(go2, hung_log, tmp_path, capsys):
    """The real Aliengo's set-points in degrees: ``estimate`` wrote torques at the drivers' limits on nearly every
    sample without a word, and ``identify --actuator pd`` ended in a ZeroDivisionError after the whole
    identification."""
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    table = hung_log
    for j in go2.pd.joints:
        k = table.column_names.index(f"q_des.{j}")
        table = table.set_column(k, f"q_des.{j}", pc.multiply(table.column(k), 180.0 / math.pi))
    log = tmp_path / "degrees.parquet"
    pq.write_table(table, log)
    for command in (("estimate", log, "--robot", "go2", "-o", tmp_path / "f.parquet"),
                    ("identify", log, "--robot", "go2", "--actuator", "pd", "--json", tmp_path / "a.json")):
        code, err = run_cli(capsys, *command)
        assert code == 2 and "column 'q_des." in err and "wrong units (degrees for radians)?" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["degrees.parquet"]


def test_the_robots_reference_gives_every_range():
    """The manual's table (docs/reference/robots.md, "Physical ranges") holds each quantity's range and reason as
    the code checks them."""
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "reference" / "robots.md").read_text()
    rows = [ln for ln in page.splitlines() if ln.startswith("| `")]
    for quantity, rng in RANGES.items():
        assert any(f"| {rng.span()} | {rng.why} |" in row for row in rows), quantity
