"""Fuzzing the readers: malformed Parquet, CSV, HDF5 and ROS 2 bags, for a bounded budget.

Every input is a valid file with random damage (bytes flipped, cut, inserted, or text
replaced). Reading it must either give a log or raise the project's InputError: any other
exception is a failure. The budget is hypothesis's example count (a few seconds per format).
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.log import Log, read_log, write_log

from test_bags import bag_map, write_bag

BUDGET = settings(max_examples=150, deadline=None, derandomize=True,
                  suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


@pytest.fixture(scope="module")
def seeds(talos, tmp_path_factory):
    """One small valid log in every format."""
    out = tmp_path_factory.mktemp("seeds")
    n = 40
    rng = np.random.default_rng(0)
    contact = np.zeros((n, 2), dtype=bool)
    contact[: n // 2, 0] = True
    contact[n // 2:, 1] = True
    base = np.tile([0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], (n, 1))
    log = Log(time=np.arange(n) * 1e-3, q=np.clip(rng.normal(0, 0.1, (n, talos.n_act)), *talos.angle_limits),
              tau=rng.normal(0, 1, (n, len(talos.torque_controlled))), contact=contact, base=base)
    for name in ("log.parquet", "log.csv", "log.h5"):
        write_log(log, talos, out / name)
    write_bag(out / "bag", log, talos, "mcap", odom_every=1)
    return out


damage = st.lists(st.tuples(st.sampled_from(["flip", "cut", "insert", "zero"]), st.floats(0, 1),
                            st.binary(min_size=1, max_size=16)), min_size=1, max_size=4)


def _damaged(data: bytes, edits) -> bytes:
    buf = bytearray(data)
    for kind, where, blob in edits:
        k = int(where * max(len(buf) - 1, 0))
        if kind == "flip" and buf:
            buf[k] ^= blob[0] or 0xFF
        elif kind == "cut":
            del buf[k:]
        elif kind == "insert":
            buf[k:k] = blob
        elif kind == "zero":
            buf[k:k + len(blob)] = bytes(len(buf[k:k + len(blob)]))
    return bytes(buf)


def _read_or_refuse(path, talos, **kw) -> None:
    try:
        read_log(path, talos, **kw)
    except InputError:
        pass


@pytest.mark.parametrize("name", ["log.parquet", "log.csv", "log.h5"])
def test_damaged_files_are_read_or_refused(talos, seeds, tmp_path, name):
    original = (seeds / name).read_bytes()

    @BUDGET
    @given(edits=damage)
    def check(edits):
        path = tmp_path / name
        path.write_bytes(_damaged(original, edits))
        _read_or_refuse(path, talos)

    check()


def test_csv_with_random_text_is_read_or_refused(talos, seeds, tmp_path):
    lines = (seeds / "log.csv").read_text().splitlines()

    @BUDGET
    @given(row=st.integers(0, len(lines) - 1), text=st.text(max_size=40))
    def check(row, text):
        path = tmp_path / "log.csv"
        edited = list(lines)
        edited[row] = text
        path.write_text("\n".join(edited))
        _read_or_refuse(path, talos)

    check()


@pytest.mark.parametrize("part", ["data", "metadata.yaml"])
def test_damaged_bags_are_read_or_refused(talos, seeds, tmp_path, part):
    files = {p.name: p.read_bytes() for p in (seeds / "bag").iterdir()}
    target = next(n for n in files if n.endswith(".mcap")) if part == "data" else part

    @BUDGET
    @given(edits=damage)
    def check(edits):
        bag = tmp_path / "bag"
        shutil.rmtree(bag, ignore_errors=True)
        bag.mkdir()
        for n, data in files.items():
            (bag / n).write_bytes(_damaged(data, edits) if n == target else data)
        _read_or_refuse(bag, talos, bag_map=bag_map(talos))

    check()
