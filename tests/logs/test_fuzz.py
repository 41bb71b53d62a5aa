"""Fuzzing the readers: malformed Parquet, CSV, HDF5 and ROS 2 bags, for a bounded budget.

Every input is a valid file with random damage (bytes flipped, cut, inserted, or text
replaced). Reading it must either give a log or raise the project's InputError: any other
exception is a failure. The budget is hypothesis's example count (a few seconds per format).
"""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers import bag_map, write_bag
from wbfriction.exceptions import InputError
from wbfriction.fit.energy import energy_consistency
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions
from wbfriction.fit.result import fitted_offsets
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.io import friction_table, read_friction_table
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import Log, write_log
from wbfriction.logs.source import read_log
from wbfriction.logs.tables import read_table, with_metadata, write_table
from wbfriction.signals.options import FilterOptions

BUDGET = settings(max_examples=150, deadline=None, derandomize=True,
                  suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
FIT_BUDGET = settings(BUDGET, max_examples=50)  # each example fits two joints

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
    _friction_seed(talos, out)
    return out


FITTED = ("leg_left_4_joint", "leg_right_3_joint")


def _friction_seed(talos, out) -> None:
    """A friction table as ``estimate`` writes it (two joints kept, Savitzky-Golay options and
    true-friction targets in its metadata), in every format ``fit`` and ``report`` read."""
    n = 80
    t = np.arange(n) * 1e-3
    contact = np.zeros((n, 2), dtype=bool)
    contact[: n // 2, 0] = True
    contact[n // 2:, 1] = True
    q = np.mean(talos.angle_limits, axis=0) + 0.1 * np.sin(2 * np.pi * 3 * t)[:, None]
    log = Log(time=t, q=q, tau=np.random.default_rng(1).normal(0, 1, (n, len(talos.torque_controlled))),
              contact=contact)
    options = EstimateOptions(diff="savgol", mask="single", lift_off_skip=0.0, touch_down_skip=0.0,
                              filtering=FilterOptions(window=11, poly_order=3))
    table = friction_table(estimate_log(talos, log, options, companion=True))
    per_joint = ("qd.", "tau_f.", "valid.", "qdd.", "delta_qdd.", "delta_qdd_companion.")
    table = table.select([c for c in table.column_names
                          if not c.startswith(per_joint) or c.endswith(FITTED)])
    meta = json.loads(table.schema.metadata[b"wbfriction"])
    meta["friction_true"] = {FITTED[0]: {"F_v": 0.2, "F_c": 1.0}}
    table = with_metadata(table, meta)
    for name in ("friction.parquet", "friction.csv", "friction.h5"):
        write_table(table, out / name)


def _fit_or_refuse(path) -> None:
    """What ``fit`` and ``report`` do with a friction table before plotting."""
    try:
        est = read_friction_table(read_table(path), str(path))
        fits = fit_estimate(est, FitOptions(min_samples=5))
        energy_consistency(est, fitted_offsets(fits))
    except InputError:
        pass


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


def test_the_friction_seed_is_fitted(seeds):
    """The control: the undamaged friction tables are read and both joints fitted."""
    for name in ("friction.parquet", "friction.csv", "friction.h5"):
        est = read_friction_table(read_table(seeds / name), name)
        assert est.joints == FITTED and est.valid.sum() > 40
        fits = fit_estimate(est, FitOptions(min_samples=5))
        assert all(f.params is not None for f in fits)
        if name != "friction.csv":  # CSV has no place for the metadata (filter options, targets)
            assert est.smoother is not None and fits[0].target.F_c == 1.0


@pytest.mark.parametrize("name", ["friction.parquet", "friction.csv", "friction.h5"])
def test_damaged_friction_tables_are_read_or_refused(seeds, tmp_path, name):
    original = (seeds / name).read_bytes()

    @FIT_BUDGET
    @given(edits=damage)
    def check(edits):
        path = tmp_path / name
        path.write_bytes(_damaged(original, edits))
        _fit_or_refuse(path)

    check()


json_values = st.recursive(st.none() | st.booleans() | st.integers(-10**6, 10**6) | st.floats() | st.text(max_size=8),
                           lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner,
                                                                                      max_size=3), max_leaves=8)


@pytest.mark.parametrize("key", ["estimate_options", "friction_true", "companion_diff"])
def test_friction_tables_with_odd_metadata_are_read_or_refused(seeds, tmp_path, key):
    """The metadata ``fit`` and ``report`` use (the filter to rebuild, the targets) replaced
    by random JSON, or with one of its entries replaced."""
    table = read_table(seeds / "friction.parquet")
    meta = json.loads(table.schema.metadata[b"wbfriction"])

    @FIT_BUDGET
    @given(value=json_values, inner=st.booleans())
    def check(value, inner):
        doc = json.loads(json.dumps(meta))
        if inner and isinstance(doc.get(key), dict) and doc[key]:
            doc[key][sorted(doc[key])[0]] = value
        else:
            doc[key] = value
        path = tmp_path / "friction.parquet"
        write_table(with_metadata(table, doc), path)
        _fit_or_refuse(path)

    check()
