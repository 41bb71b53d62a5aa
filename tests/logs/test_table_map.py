"""A table log read through the --map TOML: joints renamed, contact flags from force columns with a threshold,
gives the original log's arrays; bad map entries name the map file and the key."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from helpers import mapped_copy
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.source import open_log, read_log


@pytest.fixture(scope="module")
def walk_log(talos, tmp_path_factory):
    from wbfriction.logs.log import write_log
    from wbfriction.sim import simulate_ideal
    from wbfriction.walking import GaitOptions, walking_reference

    sim = simulate_ideal(talos, walking_reference(talos, GaitOptions(gait="forward", steps=1)))
    path = tmp_path_factory.mktemp("walk") / "walk.parquet"
    write_log(sim.log, talos, path)
    return path


def test_mapped_table_log_gives_the_same_log(talos, walk_log, tmp_path):
    table = pq.read_table(walk_log)
    mapped, toml = mapped_copy(table, talos.contact_frames)
    pq.write_table(mapped, tmp_path / "mapped.parquet")
    (tmp_path / "map.toml").write_text(toml)
    a = read_log(walk_log, talos)
    b = read_log(tmp_path / "mapped.parquet", talos, tmp_path / "map.toml")
    for name in ("time", "q", "tau", "contact", "base", "tau_f_true"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    blocks = list(open_log(tmp_path / "mapped.parquet", tmp_path / "map.toml", talos).blocks(700))
    assert pa.concat_tables(blocks).column("q.leg_left_4_joint").equals(table.column("q.leg_left_4_joint"))
    assert blocks[0].schema.metadata == table.schema.metadata


def test_bad_map_entries_name_the_map_and_key(talos, walk_log, tmp_path):
    table = pq.read_table(walk_log)
    mapped, toml = mapped_copy(table, talos.contact_frames)
    log = tmp_path / "mapped.parquet"
    pq.write_table(mapped, log)
    cases = {
        toml.replace("LLeg_knee = ", "LLeg_kne = "): r"map.toml: \[joint_states\] rename LLeg_kne: no column",
        toml.replace('"leg_left_4_joint"', '"leg_left_9_joint"'):
            r"map.toml: \[joint_states\] rename LLeg_knee = 'leg_left_9_joint': not a joint of robot 'talos'",
        toml.replace('column = "foot1.fz"', 'column = "foot1.fx"'):
            r"map.toml: \[\[contacts\]\] entry 2: column 'foot1.fx' is not in",
        toml.replace('frame = "left_sole_link"', 'frame = "left_hand"'):
            r"map.toml: \[\[contacts\]\] entry 1: frame 'left_hand' is not a contact frame of robot 'talos'",
        toml.replace('column = "foot0.fz"\n', ''): r"map.toml: \[\[contacts\]\] entry 1 \(frame 'left_sole_link'\)"
                                                    r": a table log needs column",
        toml.replace("threshold = 50.0", 'threshold = "high"', 1): r"entry 1: threshold must be a number",
    }
    for text, message in cases.items():
        (tmp_path / "map.toml").write_text(text)
        with pytest.raises(InputError, match=message) as info:
            read_log(log, talos, tmp_path / "map.toml")
        assert "\n" not in str(info.value)


@pytest.mark.parametrize("rows", [[1234], "all"], ids=["sporadic", "all"])
@pytest.mark.parametrize("threshold", [True, False], ids=["force", "flag"])
def test_a_non_finite_contact_column_is_refused_with_its_file_column_and_row(talos, walk_log, tmp_path, rows,
                                                                            threshold):
    """A NaN (or inf) force is not "no contact" (issue 37: an all-NaN column made 1845 double-support rows
    swing samples), nor a NaN flag "contact": read whole or in blocks, the first bad row of the file is named."""
    table = pq.read_table(walk_log)
    mapped, toml = mapped_copy(table, talos.contact_frames)
    if not threshold:  # the column a 0/1 flag
        toml = toml.replace("threshold = 50.0\n", "")
        mapped = mapped.set_column(mapped.column_names.index("foot1.fz"), "foot1.fz",
                                   pa.array((np.abs(mapped.column("foot1.fz").to_numpy()) > 50).astype(float)))
    values = mapped.column("foot1.fz").to_numpy().copy()
    bad = np.arange(len(values)) if rows == "all" else np.array(rows)
    values[bad] = np.nan if rows == "all" else np.inf
    log = tmp_path / "mapped.parquet"
    pq.write_table(mapped.set_column(mapped.column_names.index("foot1.fz"), "foot1.fz", pa.array(values)), log)
    (tmp_path / "map.toml").write_text(toml)
    for read in (lambda: read_log(log, talos, tmp_path / "map.toml"),
                 lambda: list(open_log(log, tmp_path / "map.toml", talos).blocks(700))):
        with pytest.raises(ColumnError) as info:
            read()
        e = info.value
        assert (e.source, e.column, e.row) == (str(log), "foot1.fz", int(bad[0]))
        assert str(e).startswith(f"{log}: column 'foot1.fz' has a non-finite value (NaN or inf) at row {bad[0]}")
        assert "right_sole_link" in str(e) and "map.toml" in str(e) and "\n" not in str(e)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(values=arrays(float, st.integers(1, 120), elements=st.one_of(st.floats(-500, 500), st.just(np.nan),
                                                                    st.just(np.inf), st.just(-np.inf))),
       threshold=st.one_of(st.none(), st.floats(0, 400)), block_rows=st.integers(1, 50))
def test_a_contact_column_gives_its_flags_or_its_first_non_finite_row(tmp_path_factory, values, threshold,
                                                                       block_rows):
    """Any column, read in any blocks: ``|f| > threshold`` (a flag: ``f != 0``) where every value is finite,
    else a ColumnError at the file's first non-finite row."""
    folder = tmp_path_factory.mktemp("column")
    pq.write_table(pa.table({"time": np.arange(len(values)) * 1e-3, "f": values}), folder / "log.parquet")
    (folder / "map.toml").write_text('[[contacts]]\nframe = "foot"\ncolumn = "f"\n'
                                     + ("" if threshold is None else f"threshold = {threshold!r}\n"))
    source = open_log(folder / "log.parquet", folder / "map.toml")
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        with pytest.raises(ColumnError) as info:
            list(source.blocks(block_rows))
        assert (info.value.column, info.value.row) == ("f", int(bad[0]))
    else:
        flags = pa.concat_tables(source.blocks(block_rows)).column("contact.foot").to_numpy()
        expected = np.abs(values) > threshold if threshold is not None else values != 0
        np.testing.assert_array_equal(flags, expected.astype(np.int8))
