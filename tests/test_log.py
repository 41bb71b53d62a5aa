"""The log format: round trip, and one clear error for each kind of bad input."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from wbfriction.exceptions import InputError
from wbfriction.log import Log, log_from_table, read_log, write_log, write_table


@pytest.fixture(scope="module")
def good(talos):
    n = 50
    rng = np.random.default_rng(0)
    contact = np.zeros((n, 2), dtype=bool)
    contact[:, 0] = True
    return Log(time=np.arange(n) * 1e-3, q=rng.normal(0, 0.1, (n, talos.n_act)),
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
    (lambda c: c["time"].__setitem__(10, c["time"][9]), "not strictly increasing at row 10"),
    (lambda c: c["time"].__setitem__(slice(20, None), c["time"][20:] + 0.5), "irregular at row 20"),
    (lambda c: c["q.leg_left_4_joint"].__setitem__(7, np.nan), "'q.leg_left_4_joint' has a non-finite value (NaN or inf) at row 7"),
    (lambda c: c["contact.left_sole_link"].__setitem__(3, 2), "must hold 0 or 1, found 2 at row 3"),
    (lambda c: c.__setitem__("base.x", c["time"]), "base pose is partial"),
])
def test_bad_input_names_the_fault(talos, good, edit, message):
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        log_from_table(_bad(talos, good, edit), talos, source="x.parquet")


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

    def half_written(tbl, path):
        original(tbl, path)
        raise OSError("disk full")

    monkeypatch.setattr(pq, "write_table", half_written)
    with pytest.raises(OSError):
        write_table(table, target)
    monkeypatch.undo()
    assert target.read_bytes() == b"previous"
    assert [p.name for p in tmp_path.iterdir()] == ["out.parquet"]
    write_table(table, target)
    assert pq.read_table(target).num_rows == 2
