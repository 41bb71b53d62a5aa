"""HDF5 logs: both layouts read back as the same log; malformed files are input errors."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from wbfriction.exceptions import InputError
from wbfriction.logs.log import log_from_table, write_log
from wbfriction.logs.source import read_log


@pytest.fixture(scope="module")
def log(talos, combined_walk):
    return log_from_table(combined_walk.log.to_table(talos).slice(0, 300), talos, "walk")


def test_one_dataset_per_column_round_trip(talos, log, tmp_path):
    write_log(log, talos, tmp_path / "log.h5")
    back = read_log(tmp_path / "log.h5", talos)
    for name in ("time", "q", "tau", "contact", "base", "tau_f_true"):
        np.testing.assert_array_equal(getattr(back, name), getattr(log, name), err_msg=name)
    assert back.metadata == log.metadata
    # the same log written twice gives the same bytes (no HDF5 timestamps)
    write_log(log, talos, tmp_path / "again.h5")
    assert (tmp_path / "log.h5").read_bytes() == (tmp_path / "again.h5").read_bytes()


def test_metadata_as_fixed_length_bytes_or_as_an_attribute(talos, log, tmp_path):
    """The metadata is written where a damaged file cannot make HDF5 loop (a fixed-length string, no
    global heap); a file that carries it as a variable-length attribute (older files) still gives it."""
    write_log(log, talos, tmp_path / "log.h5")
    with h5py.File(tmp_path / "log.h5", "r") as f:
        assert "wbfriction" not in f.attrs
        stored = f["wbfriction"]
        assert stored.ndim == 0 and h5py.check_string_dtype(stored.dtype).length is not None
    with h5py.File(tmp_path / "log.h5", "a") as f:  # as older files have it
        text = f["wbfriction"][()].decode()
        del f["wbfriction"]
        f.attrs["wbfriction"] = text
    assert read_log(tmp_path / "log.h5", talos).metadata == log.metadata


def test_groups_and_a_two_dimensional_dataset(talos, log, tmp_path):
    table = log.to_table(talos)
    names = table.column_names
    data = np.column_stack([table.column(n).to_numpy().astype(float) for n in names])
    with h5py.File(tmp_path / "matrix.h5", "w") as f:
        ds = f.create_dataset("log", data=data)
        ds.attrs["names"] = names
    with h5py.File(tmp_path / "groups.h5", "w") as f:  # q/<joint>, tau/<joint>, ...
        for n in names:
            f.create_dataset(n.replace(".", "/", 1), data=table.column(n).to_numpy())
    for file in ("matrix.h5", "groups.h5"):
        back = read_log(tmp_path / file, talos)
        np.testing.assert_array_equal(back.q, log.q)
        np.testing.assert_array_equal(back.contact, log.contact)


def test_malformed_hdf5_files(talos, log, tmp_path):
    with h5py.File(tmp_path / "names.h5", "w") as f:
        f.create_dataset("log", data=np.zeros((10, 3))).attrs["names"] = ["time", "q.x"]
    with pytest.raises(InputError, match="has 3 columns but its names attribute lists 2"):
        read_log(tmp_path / "names.h5", talos)
    with h5py.File(tmp_path / "lengths.h5", "w") as f:
        f.create_dataset("time", data=np.arange(10.0))
        f.create_dataset("q.leg_left_1_joint", data=np.zeros(9))
    with pytest.raises(InputError, match=r"lengths.h5: column 'time' has 10 rows, column 'q.leg_left_1_joint' 9"):
        read_log(tmp_path / "lengths.h5", talos)
    with h5py.File(tmp_path / "empty.h5", "w") as f:
        f.create_group("nothing")
    with pytest.raises(InputError, match="no 1-D numeric dataset"):
        read_log(tmp_path / "empty.h5", talos)
    (tmp_path / "junk.h5").write_bytes(b"\x89HDF\r\n\x1a\nnot really")
    with pytest.raises(InputError, match="not a readable HDF5 log"):
        read_log(tmp_path / "junk.h5", talos)
    write_log(log, talos, tmp_path / "nokne.h5")
    with h5py.File(tmp_path / "nokne.h5", "a") as f:
        del f["q.leg_left_4_joint"]
    with pytest.raises(InputError, match="missing column 'q.leg_left_4_joint'"):
        read_log(tmp_path / "nokne.h5", talos)
