"""A path's format is decided once (open_log): the same log through Parquet, CSV, HDF5 and a ROS 2 bag."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import bag_map, write_bag
from wbfriction.exceptions import InputError
from wbfriction.logs.formats.hdf5 import write_hdf5
from wbfriction.logs.source import open_log, read_log
from wbfriction.logs.tables import TableFile, write_table


@pytest.fixture(scope="module")
def short_log(talos, combined_walk):
    return combined_walk.log.rows(0, 600)


@pytest.mark.parametrize(("suffix", "fmt"), [(".parquet", "parquet"), (".csv", "csv"), (".h5", "hdf5")])
def test_every_table_format_reads_back_as_the_same_log(talos, short_log, tmp_path, suffix, fmt):
    path = tmp_path / f"log{suffix}"
    table = short_log.to_table(talos)
    if fmt == "hdf5":
        write_hdf5(table, path)
    else:
        write_table(table, path)
    source = open_log(path)
    assert source.format.name == fmt and not source.is_mapped
    blocks = list(source.blocks(block_rows=250))
    assert [b.num_rows for b in blocks] == [250, 250, 100]
    log = read_log(path, talos)
    np.testing.assert_allclose(log.q, short_log.q, rtol=1e-15 if fmt != "csv" else 1e-12)
    np.testing.assert_array_equal(log.contact, short_log.contact)


def test_a_bag_needs_its_map_and_is_read_through_it(talos, short_log, tmp_path):
    write_bag(tmp_path / "bag", short_log, talos)
    with pytest.raises(InputError, match="a ROS 2 bag needs a topic map"):
        open_log(tmp_path / "bag")
    source = open_log(tmp_path / "bag", bag_map(talos))
    assert source.format.name == "bag" and source.is_mapped
    with pytest.raises(InputError, match="is not a table file"):
        TableFile(tmp_path / "bag")
    log = read_log(tmp_path / "bag", talos, bag_map(talos))
    # the samples where every topic has data (the odometry every 5th sample bounds both ends)
    first = int(np.flatnonzero((short_log.q == log.q[0]).all(axis=1))[0])
    assert first < 5 and len(log) > len(short_log) - 10
    np.testing.assert_array_equal(log.q, short_log.q[first:first + len(log)])
    np.testing.assert_array_equal(log.contact, short_log.contact[first:first + len(log)])


def test_unknown_and_missing_files_are_refused_at_once(tmp_path):
    (tmp_path / "log.txt").write_text("time\n0\n")
    with pytest.raises(InputError, match="unknown file type '.txt'"):
        open_log(tmp_path / "log.txt")
    with pytest.raises(InputError, match="file not found"):
        open_log(tmp_path / "missing.parquet")
