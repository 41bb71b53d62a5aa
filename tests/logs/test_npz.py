"""FloBaRoID's ``.npz`` recordings read as a log table (:func:`wbfriction.logs.read_npz_recordings`): the arrays'
values as they are, and bad recordings refused in one line naming the file and the array."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import KUKA, needs_kuka
from wbfriction.exceptions import InputError
from wbfriction.logs import read_npz_recordings

JOINTS = ("a", "b", "c")


def recording(path, n: int = 5, t0: float = 100.0, joints: int = 3, **change):
    """A small recording with every array FloBaRoID writes (``change``: arrays replaced, or dropped when None)."""
    rng = np.random.default_rng(len(str(path)))
    arrays = {"times": t0 + 0.005 * np.arange(n), "positions": rng.normal(size=(n, joints)),
              "velocities": rng.normal(size=(n, joints)), "torques": rng.normal(size=(n, joints)),
              "accelerations": rng.normal(size=(n, joints)), "target_positions": rng.normal(size=(n, joints))}
    arrays.update(change)
    np.savez(path, **{k: v for k, v in arrays.items() if v is not None})
    return path


def refused(paths, joints=JOINTS) -> str:
    with pytest.raises(InputError) as info:
        read_npz_recordings(paths, joints)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_the_columns_are_the_arrays_as_recorded(tmp_path):
    first, second = recording(tmp_path / "1.npz"), recording(tmp_path / "2.npz", n=4, t0=200.0)
    table = read_npz_recordings([first, second], JOINTS)
    assert table.column_names == ["time", "q.a", "q.b", "q.c", "tau.a", "tau.b", "tau.c", "qd.a", "qd.b", "qd.c"]
    with np.load(first) as x, np.load(second) as y:
        np.testing.assert_array_equal(table["time"].to_numpy(), np.concatenate([x["times"], y["times"]]))
        for prefix, key in (("q", "positions"), ("tau", "torques"), ("qd", "velocities")):
            both = np.concatenate([x[key], y[key]])
            for i, joint in enumerate(JOINTS):
                np.testing.assert_array_equal(table[f"{prefix}.{joint}"].to_numpy(), both[:, i])


def test_integer_stamps_are_read_as_numbers(tmp_path):
    path = recording(tmp_path / "r.npz", times=np.arange(5, dtype=np.int64))
    assert read_npz_recordings([path], JOINTS)["time"].to_pylist() == [0.0, 1.0, 2.0, 3.0, 4.0]


@needs_kuka
def test_the_kuka_recordings_as_numpy_reads_them():
    runs = [KUKA / "measurements_1.npz", KUKA / "measurements_2.npz"]
    joints = [f"lwr_{i}_joint" for i in range(7)]
    table = read_npz_recordings(runs, joints)
    assert table.num_rows == 2 * 5027
    loaded = []
    for path in runs:
        with np.load(path) as archive:
            loaded.append({key: archive[key] for key in ("times", "positions", "torques", "velocities")})
    np.testing.assert_array_equal(table["time"].to_numpy(), np.concatenate([r["times"] for r in loaded]))
    for prefix, key in (("q", "positions"), ("tau", "torques"), ("qd", "velocities")):
        values = np.concatenate([r[key] for r in loaded])
        assert values.shape == (2 * 5027, 7)
        np.testing.assert_array_equal(np.column_stack([table[f"{prefix}.{j}"].to_numpy() for j in joints]), values)


def test_a_missing_array_is_named(tmp_path):
    path = recording(tmp_path / "r.npz", torques=None)
    message = refused([path])
    assert message.startswith(f"{path}: no array 'torques'")


@pytest.mark.parametrize(("key", "value", "expected"), [
    ("torques", np.zeros((5, 2)), "'torques' has shape (5, 2), expected (5, 3)"),
    ("positions", np.zeros(5), "'positions' has shape (5,), expected (5, 3)"),
    ("velocities", np.zeros((4, 3)), "'velocities' has shape (4, 3), expected (5, 3)"),
    ("times", np.zeros((5, 1)), "'times' has shape (5, 1), expected (N,)"),
    ("times", np.zeros(0), "'times' has shape (0,), expected (N,)"),
    ("torques", np.full((5, 3), "x"), "'torques' holds <U1 values, not numbers"),
])
def test_a_wrong_array_is_named(tmp_path, key, value, expected):
    path = recording(tmp_path / "r.npz", **{key: value})
    message = refused([path])
    assert message.startswith(f"{path}: ") and expected in message


def test_recordings_out_of_order_are_refused(tmp_path):
    later, earlier = recording(tmp_path / "later.npz", t0=200.0), recording(tmp_path / "earlier.npz", t0=100.0)
    message = refused([later, earlier])
    assert message.startswith(f"{earlier}: 'times' starts at 100.0 s") and str(later) in message
    touching = recording(tmp_path / "touching.npz", t0=100.02)  # its first stamp is the first one's last
    assert refused([earlier, touching]).startswith(f"{touching}: ")


def test_what_is_not_a_recording_is_refused(tmp_path):
    missing = tmp_path / "missing.npz"
    assert refused([missing]) == f"{missing}: file not found"
    text = tmp_path / "notes.npz"
    text.write_text("not an archive\n")
    assert refused([text]).startswith(f"{text}: not a readable .npz archive")
    single = tmp_path / "single.npy"
    np.save(single, np.zeros(3))
    assert refused([single]).startswith(f"{single}: a single array")


def test_a_damaged_archive_is_refused(tmp_path):
    path = recording(tmp_path / "r.npz", n=200)
    data = bytearray(path.read_bytes())
    at = data.index(b"torques.npy") + 400  # inside the torques' stored bytes, past their local header
    data[at] ^= 0xFF
    path.write_bytes(bytes(data))
    message = refused([path])
    assert message.startswith(f"{path}: not a readable .npz archive") and "torques" in message


def test_no_recording_or_joints_named_twice_are_refused(tmp_path):
    assert refused([]) == "no .npz recording given"
    path = recording(tmp_path / "r.npz")
    assert "named once each" in refused([path], ("a", "a", "c"))
    assert "named once each" in refused([path], ())
