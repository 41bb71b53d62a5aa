"""Contact flags from the measured forces: the hysteresis, and a log without contact columns read and
estimated (whole and in chunks) with flags from its force-torque sensors."""

from __future__ import annotations

import numpy as np
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.contacts import default_thresholds, hysteresis, normal_forces
from wbfriction.logs.log import write_log
from wbfriction.logs.source import read_log
from wbfriction.pipeline.chunks import Chunking
from wbfriction.pipeline.estimate_step import RobotSpec, estimate_file
from wbfriction.sim import IdealOptions, simulate_ideal
from wbfriction.walking import GaitOptions, walking_reference


def _loop(x, on, off):
    """The hysteresis written as the obvious loop (the reference)."""
    state, out = x[0] > 0.5 * (on + off), []
    for v in x:
        state = True if v > on else False if v < off else state
        out.append(state)
    return np.array(out)


@settings(max_examples=200, deadline=None)
@given(x=arrays(float, st.integers(1, 60), elements=st.floats(-50, 150)),
       on=st.floats(0, 100), gap=st.floats(0, 50))
def test_the_hysteresis_is_the_loop_it_stands_for(x, on, gap):
    np.testing.assert_array_equal(hysteresis(x, on, on - gap), _loop(x, on, on - gap))


def test_a_force_that_hovers_between_the_thresholds_does_not_chatter():
    x = np.r_[np.zeros(5), 100 * np.ones(5), 60 + 5 * np.sin(np.arange(40)), np.zeros(5)]
    flags = hysteresis(x, 80, 40)
    assert np.count_nonzero(np.diff(flags.astype(int))) == 2  # on once, off once


@pytest.fixture(scope="module")
def no_flags(talos, tmp_path_factory):
    """A forward walk with its force-torque sensors logged and its contact columns dropped."""
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=3))
    log = simulate_ideal(talos, ref, None, IdealOptions(substeps=10, force_torque=True)).log
    d = tmp_path_factory.mktemp("flags")
    write_log(log, talos, d / "walk.parquet")
    table = pq.read_table(d / "walk.parquet")
    pq.write_table(table.drop([c for c in table.column_names if c.startswith("contact.")]), d / "noflags.parquet")
    return log, d


def test_a_log_without_contact_columns_takes_its_flags_from_the_forces(talos, no_flags):
    log, d = no_flags
    back = read_log(d / "noflags.parquet", talos)
    on, off = default_thresholds(talos)
    normal = normal_forces(talos, log.wrench)
    assert normal[log.contact].max() > 5 * on and normal[~log.contact].max() < off  # the sensors see the stance
    np.testing.assert_array_equal(back.contact, hysteresis(normal, on, off))
    # the planned flags say "in contact" a little longer than the forces do: the unloading foot
    assert np.all(back.contact <= log.contact) and 0 < np.mean(back.contact != log.contact) < 0.05


def test_flags_from_forces_are_the_same_whole_and_in_chunks(talos, no_flags):
    _, d = no_flags
    for rows in (100_000, 1_000):
        estimate_file(RobotSpec("talos"), d / "noflags.parquet", d / f"f{rows}.parquet", EstimateOptions(diff="true"),
                      chunking=Chunking(rows=rows, workers=1))
    whole, chunked = pq.read_table(d / "f100000.parquet"), pq.read_table(d / "f1000.parquet")
    assert whole.column_names == chunked.column_names
    for name in whole.column_names:
        a, b = whole.column(name).to_numpy(zero_copy_only=False), chunked.column(name).to_numpy(zero_copy_only=False)
        if a.dtype.kind == "f":  # the Savitzky-Golay velocity convolves by FFT, whose rounding follows the length
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9, err_msg=name)
        else:
            assert np.array_equal(a, b), name


def test_a_nan_wrench_is_refused_where_the_flags_come_from_the_forces(talos, no_flags, tmp_path):
    """The force-torque route: a NaN in a sensor's force (the flags' only source) is refused with the file,
    the column and the first row, whole (read_log) and before the chunks (estimate_file's plan), never held
    as the last flag by the hysteresis."""
    import pyarrow as pa

    from wbfriction.exceptions import ColumnError

    _, d = no_flags
    table = pq.read_table(d / "noflags.parquet")
    column = talos.ft_sensors[1].columns()[2]  # a force: fz of the second sensor
    values = table.column(column).to_numpy().copy()
    values[[901, 1700]] = np.nan
    log = tmp_path / "nan.parquet"
    pq.write_table(table.set_column(table.column_names.index(column), column, pa.array(values)), log)
    for read in (lambda: read_log(log, talos),
                 lambda: estimate_file(RobotSpec("talos"), log, tmp_path / "f.parquet", EstimateOptions(diff="true"),
                                       chunking=Chunking(rows=1_000, workers=1))):
        with pytest.raises(ColumnError) as info:
            read()
        assert (info.value.source, info.value.column, info.value.row) == (str(log), column, 901)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["nan.parquet"]
