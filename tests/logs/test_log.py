"""The log format: round trip, and one clear error for each kind of bad input."""

from __future__ import annotations

import re

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from wbfriction.exceptions import InputError, OptionError, OutputError
from wbfriction.logs.log import Log, log_from_table, write_log
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.source import read_log
from wbfriction.logs.tables import write_table


@pytest.fixture(scope="module")
def good(talos):
    n = 50
    rng = np.random.default_rng(0)
    contact = np.zeros((n, 2), dtype=bool)
    contact[:, 0] = True
    q = np.clip(rng.normal(0, 0.1, (n, talos.n_act)), *talos.angle_limits)
    return Log(time=np.arange(n) * 1e-3, q=q,
               tau=rng.normal(0, 1, (n, len(talos.torque_controlled))), contact=contact,
               metadata={"friction_true": {"leg_right_4_joint": {"F_c": 1.0}}})


def test_round_trip_parquet_and_csv(talos, good, tmp_path):
    for name in ("log.parquet", "log.csv"):
        write_log(good, talos, tmp_path / name)
        back = read_log(tmp_path / name, talos)
        np.testing.assert_array_equal(back.q, good.q)
        np.testing.assert_array_equal(back.tau, good.tau)
        np.testing.assert_array_equal(back.contact, good.contact)
    assert read_log(tmp_path / "log.parquet", talos).metadata == good.metadata


def test_columns_are_mapped_by_name_not_order(talos, good):
    table = good.to_table(talos)
    shuffled = table.select(list(reversed(table.column_names)))
    back = log_from_table(shuffled, talos)
    np.testing.assert_array_equal(back.q, good.q)


def _bad(talos, good, edit):
    cols = {n: good.to_table(talos).column(n).to_numpy().copy() for n in good.to_table(talos).column_names}
    edit(cols)
    return pa.table(cols)


@pytest.mark.parametrize("edit, message", [
    (lambda c: c.pop("q.leg_left_4_joint"), "missing column 'q.leg_left_4_joint'"),
    (lambda c: c.pop("tau.arm_left_1_joint"), "missing column 'tau.arm_left_1_joint'"),
    (lambda c: c.pop("contact.right_sole_link"), "missing column 'contact.right_sole_link'"),
    (lambda c: c.pop("time"), "missing column 'time'"),
    (lambda c: c.__setitem__("q.leg_middle_1_joint", c["time"]), "unknown joint 'leg_middle_1_joint'"),
    (lambda c: c.__setitem__("contact.nose", c["time"]), "unknown contact frame 'nose'"),
    (lambda c: c["time"].__setitem__(10, c["time"][9]), "duplicated stamp at row 10"),
    (lambda c: c["time"].__setitem__(10, c["time"][9] - 1e-4), "decreasing stamp at row 10"),
    (lambda c: c["q.leg_left_4_joint"].__setitem__(12, 57.3), "column 'q.leg_left_4_joint' is 57.3 at row 12, "
                                                              "beyond its limits [0, 2.618]"),
    (lambda c: c["q.leg_left_4_joint"].__setitem__(7, np.nan),
     "'q.leg_left_4_joint' has a non-finite value (NaN or inf) at row 7"),
    (lambda c: c["contact.left_sole_link"].__setitem__(3, 2), "must hold 0 or 1, found 2 at row 3"),
    (lambda c: c.__setitem__("base.x", c["time"]), "base pose is partial"),
])
def test_bad_input_names_the_fault(talos, good, edit, message):
    with pytest.raises(InputError, match=re.escape(message)):
        log_from_table(_bad(talos, good, edit), talos, source="x.parquet")


@pytest.mark.parametrize("step", [2, 3, 6, 500])
def test_time_gaps_split_the_log_into_segments(talos, good, step):
    """A step of two periods or more (dropped samples, a pause) ends a segment, unless it is a few ticks
    (up to 4 periods) of exact stamps taken as recorded: a clock that skipped samples (issue 53)."""
    table = _bad(talos, good, lambda c: c["time"].__setitem__(slice(20, None), c["time"][20:] + (step - 1) * 1e-3))
    skipped = step <= 4
    for time_base in ("auto", "regularised"):
        log = log_from_table(table, talos, source="x.parquet", read=ReadOptions(time_base=time_base))
        if skipped and time_base == "auto":  # one segment, differentiated on the stamps as recorded
            assert log.segments == [(0, 50)] and log.clock.kind == "skipping"
            assert log.clock.lattice == pytest.approx(1e-3)
            np.testing.assert_array_equal(log.clock.t, log.time - log.time[0])
            continue
        assert log.segments == [(0, 20), (20, 50)]  # a regularised clock counts samples: a skip is a gap
        a, b = log.parts()
        np.testing.assert_array_equal(b.q, good.q[20:])
        assert len(a.time) == 20 and b.time[0] == pytest.approx(0.019 + step * 1e-3)
    # with a larger max_gap, the same step is a clock that skipped samples: one segment
    if skipped:
        log = log_from_table(table, talos, source="x.parquet", read=ReadOptions(max_gap=5))
        assert log.segments == [(0, 50)] and log.clock.kind == "skipping"


def test_irregular_steps_are_read_with_the_clock_that_explains_them(talos, good):
    """Steps that are not uniform are no longer refused: the log is read whole and its clock says
    what it found (here exact stamps of a 0.5 ms clock: steps of 1 and 1.5 ms)."""
    table = _bad(talos, good, lambda c: c["time"].__setitem__(slice(20, None), c["time"][20:] + 0.5e-3))
    log = log_from_table(table, talos, source="x.parquet")
    assert log.segments == [(0, 50)] and log.clock.kind == "skipping"
    assert "exact stamps of a 0.5 ms clock skipping samples (steps 1-1.5 ms = 2-3 ticks)" in log.clock.reason
    assert log.dt == pytest.approx(1e-3)
    forced = log_from_table(table, talos, source="x.parquet", read=ReadOptions(time_base="regularised"))
    assert forced.clock.kind == "jittered" and "as asked" in forced.clock.reason


def test_integer_nanosecond_stamps(talos, good):
    """An integer ``time`` column needs its unit: refused without one; in nanoseconds (epoch),
    read as seconds, its clock exact."""
    ns = 1_700_000_000_123_456_789 + np.arange(len(good.time), dtype=np.int64) * 1_000_000
    table = _bad(talos, good, lambda c: c.__setitem__("time", ns))
    with pytest.raises(InputError, match="holds integers .* --time-unit"):
        log_from_table(table, talos, source="x.parquet")
    log = log_from_table(table, talos, source="x.parquet", read=ReadOptions(time_unit="ns"))
    assert log.clock.kind == "uniform" and log.dt == 1e-3 and log.clock.t0 == pytest.approx(1.7e9)
    np.testing.assert_allclose(log.clock.t, good.time, rtol=0, atol=1e-15)
    np.testing.assert_allclose(log.time, ns * 1e-9, rtol=1e-15)
    dup = ns.copy()
    dup[10] = dup[9]
    with pytest.raises(InputError, match="duplicated stamp at row 10"):
        log_from_table(_bad(talos, good, lambda c: c.__setitem__("time", dup)), talos, source="x.parquet",
                       read=ReadOptions(time_unit="ns"))


def test_unreadable_and_missing_files(talos, tmp_path):
    with pytest.raises(InputError, match="file not found"):
        read_log(tmp_path / "none.parquet", talos)
    (tmp_path / "junk.parquet").write_text("not parquet")
    with pytest.raises(InputError, match="cannot be read"):
        read_log(tmp_path / "junk.parquet", talos)
    (tmp_path / "x.txt").write_text("")
    with pytest.raises(InputError, match="unknown file type"):
        read_log(tmp_path / "x.txt", talos)


def test_outputs_are_written_whole_or_not_at_all(tmp_path, monkeypatch):
    target = tmp_path / "out.parquet"
    target.write_bytes(b"previous")
    table = pa.table({"a": [1, 2]})
    original = pq.write_table

    def half_written(tbl, path, **options):
        original(tbl, path, **options)
        raise OSError("disk full")

    monkeypatch.setattr(pq, "write_table", half_written)
    with pytest.raises(OutputError) as info:
        write_table(table, target)
    assert str(info.value) == f"{target}: cannot be written: disk full (the previous file is kept)"
    monkeypatch.undo()
    assert target.read_bytes() == b"previous"
    assert [p.name for p in tmp_path.iterdir()] == ["out.parquet"]
    write_table(table, target)
    assert pq.read_table(target).num_rows == 2


def test_the_float32_warning_gives_each_columns_unit():
    """Issue 53, class 15: a float32 temperature column was said to hold '2.4e-7 rad at 2 rad'. Each kind of column
    is given its own unit and size, and the differentiated ones what their rounding costs."""
    from wbfriction.logs.log import check_schema
    from wbfriction.model.loading import load_robot

    panda = load_robot("panda")
    joint = panda.torque_controlled[0]
    fields = [("time", pa.float64())] + [(f"q.{j}", pa.float64()) for j in panda.actuated] + \
        [(f"tau.{j}", pa.float64()) for j in panda.actuated]
    warm = pa.schema(fields + [(f"temperature.{joint}", pa.float32())])
    (line,) = check_schema(warm, panda, "log.parquet")
    assert "rad" not in line and "°C" in line and f"temperature.{joint}" in line and "accelerations" not in line
    both = pa.schema([(n, pa.float32() if n == f"q.{joint}" else t) for n, t in fields]
                     + [(f"temperature.{joint}", pa.float32())])
    (line,) = check_schema(both, panda, "log.parquet")
    assert "2.4e-07 rad at 2 rad" in line and "°C" in line and "accelerations" in line


def test_read_options_are_checked_where_made():
    """The read settings are one value (issue 54), refused when made, naming the option as the command line does."""
    assert ReadOptions() == ReadOptions(max_gap=2.0, limit_margin=0.2, time_base="auto", time_unit=None)
    assert ReadOptions(max_gap=np.float64(5), limit_margin=np.inf).limit_margin == np.inf
    for kw, option in (({"max_gap": 1.0}, "--max-gap"), ({"max_gap": float("nan")}, "--max-gap"),
                       ({"limit_margin": -0.1}, "--limit-margin"), ({"limit_margin": "0.2"}, "--limit-margin"),
                       ({"time_base": "exact"}, "--time-base"), ({"time_unit": "h"}, "--time-unit")):
        with pytest.raises(OptionError) as err:
            ReadOptions(**kw)
        assert err.value.option == option and err.value.value is next(iter(kw.values()))
        assert str(err.value).startswith(f"{option} must be ")
