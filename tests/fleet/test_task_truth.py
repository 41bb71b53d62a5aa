"""One log's task against independent computations (issue 37, mutation testing of ``fleet/task.py``): what a
result's key digests, a log's rows from hand-made fits (velocity range, percentiles, friction at the reference
speeds and its delta-method error written out), and what the task hands the estimate and the fit (the options,
where the chunks go, one BLAS thread), its faults as one line."""

from __future__ import annotations

import dataclasses
import hashlib
import json
from contextlib import contextmanager
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from threadpoolctl import threadpool_info

from wbfriction.exceptions import InputError
from wbfriction.fit.energy import JointEnergy
from wbfriction.fit.options import FitOptions
from wbfriction.fit.result import FitResult
from wbfriction.fleet.manifest import LogEntry
from wbfriction.fleet.options import BatchOptions
from wbfriction.fleet.schema import REFERENCE_SPEEDS, RESULT_SCHEMA, speed_column
from wbfriction.fleet.task import (
    ResultKey,
    options_sha256,
    process_log,
    reference_friction,
    result_key,
    result_rows,
    robot_sha256,
)
from wbfriction.friction.models import CoulombViscousParams, StribeckParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.pipeline.estimate_step import RobotSpec
from wbfriction.version import __version__

KEY = ResultKey("007", datetime(2026, 3, 1, 9, 30, 0, 123456, tzinfo=timezone(timedelta(hours=1))), "/logs/a.parquet",
                "a" * 64, "b" * 64, "c" * 64)


def test_a_key_digests_every_field_and_the_instant_not_its_zone():
    changed = [dataclasses.replace(KEY, robot_id="7"),
               dataclasses.replace(KEY, start_time=KEY.start_time + timedelta(microseconds=1)),
               dataclasses.replace(KEY, log="/logs/b.parquet"), dataclasses.replace(KEY, log_sha256="d" * 64),
               dataclasses.replace(KEY, robot_sha256="d" * 64), dataclasses.replace(KEY, options_sha256="d" * 64)]
    keys = {KEY.key, *(k.key for k in changed)}
    assert len(keys) == 7 and all(len(k) == 64 and int(k, 16) >= 0 for k in keys)
    assert dataclasses.replace(KEY, start_time=KEY.start_time.astimezone(UTC)).key == KEY.key
    # fields that trade places are another key (robot id "a", log "b" is not robot id "b", log "a")
    assert dataclasses.replace(KEY, robot_id="x", log="y").key != dataclasses.replace(KEY, robot_id="y", log="x").key


def test_options_digest_canonical_json():
    """SHA-256 of the options as canonical JSON (every field, nested ones too, sorted keys): equal options one
    digest, any field changed another."""
    options = BatchOptions()
    canonical = json.dumps(dataclasses.asdict(options), sort_keys=True, default=str)
    assert options_sha256(options) == hashlib.sha256(canonical.encode()).hexdigest()
    assert options_sha256(BatchOptions()) == options_sha256(options)
    others = [BatchOptions(fit=FitOptions(model="thesis")), BatchOptions(chunk_rows=9999),
              BatchOptions(fit=FitOptions(min_samples=21)), BatchOptions(estimate=EstimateOptions(diff="savgol")),
              BatchOptions(energy_threshold=0.3)]
    assert len({options_sha256(o) for o in [options, *others]}) == 6


def test_a_key_is_made_of_the_entry_and_what_it_is_computed_from():
    entry = LogEntry(Path("/logs/a.parquet"), "007", KEY.start_time, RobotSpec("panda"))
    options = BatchOptions(fit=FitOptions(model="coulomb-viscous"))
    key = result_key(entry, "a" * 64, "b" * 64, options)
    assert key == ResultKey("007", KEY.start_time, "/logs/a.parquet", "a" * 64, "b" * 64, options_sha256(options))


def test_a_robot_digest_covers_its_model_file_and_its_configuration(tmp_path):
    """The built-in robot's packaged TOML and the same bytes given as a configuration file digest alike; a byte
    changed in either file is another digest."""
    from importlib import resources

    urdf = tmp_path / "arm.urdf"
    urdf.write_text("<robot name='arm'/>\n")
    toml = resources.files("wbfriction.model.robots").joinpath("panda.toml").read_bytes()
    config = tmp_path / "panda.toml"
    config.write_bytes(toml)
    robot = SimpleNamespace(urdf=urdf, name="panda")
    built_in = robot_sha256(RobotSpec("panda"), robot)
    assert robot_sha256(RobotSpec(None, config=str(config)), robot) == built_in
    config.write_bytes(toml + b"\n")
    assert robot_sha256(RobotSpec(None, config=str(config)), robot) != built_in
    urdf.write_text("<robot name='arm2'/>\n")
    assert robot_sha256(RobotSpec("panda"), robot) != built_in
    expected = hashlib.sha256(hashlib.sha256(urdf.read_bytes()).hexdigest().encode())
    expected.update(hashlib.sha256(toml).hexdigest().encode())
    assert robot_sha256(RobotSpec("panda"), robot) == expected.hexdigest()


def percentile95(values: list[float]) -> float:
    """The 95th percentile by linear interpolation between order statistics, written out."""
    s = sorted(values)
    h = 0.95 * (len(s) - 1)
    lo = int(np.floor(h))
    return s[lo] + (h - lo) * (s[min(lo + 1, len(s) - 1)] - s[lo])


def fits_and_samples():
    """Two joints: ``a`` fitted (Coulomb-viscous, a covariance), moving up to exactly 0.3 rad/s on its valid
    samples (faster on invalid or non-finite ones); ``b`` not fitted, no valid sample."""
    cov = np.array([[4e-4, 1e-4, 0.0], [1e-4, 9e-4, 2e-5], [0.0, 2e-5, 1e-4]])  # F_v, F_c, tau_os
    a = FitResult("a", 120, CoulombViscousParams(F_v=0.2, F_c=1.5, tau_os=0.05),
                  stderr={"F_v": 0.02, "F_c": 0.03, "tau_os": 0.01}, rms_residual=0.125, success=True,
                  covariance=cov)
    b = FitResult("b", 0, message="no valid sample")
    qd = np.array([[0.1, 0.0], [-0.25, 1.0], [0.3, 2.0], [np.nan, 0.5], [5.0, 0.1], [-0.05, 0.2], [0.2, 0.3]])
    valid = np.array([[True, False], [True, False], [True, False], [True, False], [False, False],
                      [True, False], [True, False]])
    energy = [JointEnergy("a", 6, 0.25, 0.05, 3, None, 0.0, None, 0.2)]
    return [a, b], energy, qd, valid, cov


def test_a_logs_rows_from_its_fits():
    fits, energy, qd, valid, cov = fits_and_samples()
    rows = result_rows(KEY, fits, energy, qd, valid)
    assert rows.schema == RESULT_SCHEMA
    a, b = rows.to_pylist()
    expected_time = np.datetime64(KEY.start_time.astimezone(UTC).replace(tzinfo=None), "ns").astype(np.int64)
    assert rows.column("start_time").cast("int64").to_pylist() == [int(expected_time)] * 2
    for row, joint in ((a, "a"), (b, "b")):
        assert (row["robot_id"], row["log"], row["key"], row["log_sha256"], row["robot_sha256"],
                row["options_sha256"], row["joint"], row["version"]) == (
            "007", KEY.log, KEY.key, KEY.log_sha256, KEY.robot_sha256, KEY.options_sha256, joint, __version__)
    v = [0.1, -0.25, 0.3, -0.05, 0.2]  # a's valid, finite velocities
    assert (a["model"], a["status"], a["n_samples"]) == ("coulomb-viscous", "ok", 120)
    assert (a["qd_min"], a["qd_max"]) == (-0.25, 0.3)
    assert a["qd_p95"] == pytest.approx(percentile95([abs(x) for x in v]), rel=1e-12)
    assert (a["energy_share"], a["rms_residual"]) == (0.25, 0.125)
    assert (a["F_c"], a["F_v"], a["tau_os"], a["F_c_se"], a["F_v_se"], a["tau_os_se"]) == (
        1.5, 0.2, 0.05, 0.03, 0.02, 0.01)
    for s in REFERENCE_SPEEDS:  # reached: 0.1 and 0.3 (exactly its fastest valid sample); not 1
        f, se = a[speed_column(s)], a[speed_column(s) + "_se"]
        if s <= 0.3:
            assert f == pytest.approx(1.5 + 0.2 * s, rel=1e-12)
            assert se == pytest.approx(np.sqrt(s * s * cov[0, 0] + cov[1, 1] + 2 * s * cov[0, 1]), rel=1e-9)
        else:
            assert np.isnan(f) and np.isnan(se)
    assert (b["model"], b["status"], b["n_samples"]) == ("thesis", "not excited", 0)
    for name in ("qd_min", "qd_max", "qd_p95", "energy_share", "rms_residual", "F_c", "F_c_se", "tau_os",
                 *(speed_column(s) for s in REFERENCE_SPEEDS)):
        assert np.isnan(b[name]), name


def test_friction_at_a_speed_with_a_covariance_not_finite_or_not_positive():
    fit = FitResult("j", 10, CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.0), covariance=np.full((3, 3), np.inf))
    assert reference_friction(fit, 0.5) == (1.1, float("inf"))
    fit = FitResult("j", 10, CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.0), covariance=-np.eye(3))
    assert reference_friction(fit, 0.5) == (1.1, 0.0)  # a negative variance (rounding) is none


def test_the_stribeck_model_at_a_speed_matches_finite_differences():
    """Its delta-method gradient, with its own exponent delta_s, against central differences."""
    p = StribeckParams(F_v=0.3, F_c=0.8, F_s=1.2, v_s=0.2, tau_os=0.1, delta_s=1.3)
    x = p.as_vector()
    v = 0.15
    g = np.empty(x.size)
    for i in range(x.size):
        h = 1e-6 * max(1.0, abs(x[i]))
        values = []
        for y in (x + h * np.eye(x.size)[i], x - h * np.eye(x.size)[i]):
            q = StribeckParams(*y, delta_s=1.3)
            values.append(0.5 * float(np.subtract(*q.f(np.array([v, -v])))))
        g[i] = (values[0] - values[1]) / (2 * h)
    cov = np.diag(np.arange(1.0, 6.0)) * 1e-4
    value, se = reference_friction(FitResult("j", 1, p, covariance=cov), v)
    assert value == pytest.approx(0.5 * float(np.subtract(*p.f(np.array([v, -v])))), rel=1e-12)
    assert se == pytest.approx(np.sqrt(g @ cov @ g), rel=1e-6)


@pytest.fixture
def wiring(monkeypatch, tmp_path):
    """process_log with the estimate and the fit replaced by recorders (the rows are still made from the fit)."""
    calls: dict = {}
    robot = object()

    @contextmanager
    def prepared_log(path, robot, source, read, near):  # a log in the project's format: as it is
        calls["prepared"] = dict(path=path, robot=robot, source=source, near=Path(near))
        yield Path(path), None

    def estimate_file(spec, log, output, options, *, chunking, robot, executor, source):
        calls["estimate"] = dict(spec=spec, log=log, output=Path(output), options=options, chunking=chunking,
                                 robot=robot, executor=executor, source=source,
                                 threads={i["num_threads"] for i in threadpool_info()})
        if isinstance(calls.get("raise"), Exception):
            raise calls["raise"]

    def fit_table(friction, options, **kwargs):
        calls["fit"] = dict(friction=Path(friction), options=options,
                            threads={i["num_threads"] for i in threadpool_info()}, **kwargs)
        fits, energy, qd, valid, _ = fits_and_samples()
        return SimpleNamespace(fits=fits, energy=energy, est=SimpleNamespace(qd=qd, valid=valid, temperature=None,
                                                                          tau=None, tau_f=None))

    monkeypatch.setattr("wbfriction.fleet.task.worker_robot", lambda spec: robot)
    monkeypatch.setattr("wbfriction.fleet.task.prepared_log", prepared_log)
    monkeypatch.setattr("wbfriction.fleet.task.estimate_file", estimate_file)
    monkeypatch.setattr("wbfriction.fleet.task.fit_table", fit_table)
    entry = LogEntry(tmp_path / "a.parquet", "007", KEY.start_time, RobotSpec("panda"))
    return calls, robot, entry


def test_a_task_hands_its_options_to_the_estimate_and_the_fit(wiring, tmp_path):
    calls, robot, entry = wiring
    options = BatchOptions(estimate=EstimateOptions(diff="savgol", lift_off_skip=0.2),
                           fit=FitOptions(model="coulomb-viscous", selection_tolerance=0.05, min_samples=33),
                           energy_threshold=0.3, energy_tolerance=0.02, chunk_rows=777)
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    outcome = process_log(entry, KEY, options, scratch, chunk_workers=3)
    est, fit = calls["estimate"], calls["fit"]
    assert (est["spec"], est["log"], est["options"], est["robot"], est["executor"], est["source"]) == (
        entry.robot, entry.log, options.estimate, robot, None, str(entry.log))
    assert calls["prepared"] == dict(path=entry.log, robot=robot, source=str(entry.log), near=est["output"])
    assert (est["chunking"].rows, est["chunking"].workers) == (777, 1)  # no executor: chunks in this process
    assert est["output"].parent.parent == scratch and fit["friction"] == est["output"]
    assert {k: fit[k] for k in ("options", "threshold", "tolerance")} == dict(
        options=FitOptions(model="coulomb-viscous", selection_tolerance=0.05, min_samples=33), threshold=0.3,
        tolerance=0.02)
    assert est["threads"] == fit["threads"] == {1}  # one BLAS thread, whatever the engine
    assert not outcome.failed and outcome.rows.num_rows == 2 and outcome.table is None
    assert outcome.rows.column("key").to_pylist() == [KEY.key] * 2
    assert list(scratch.iterdir()) == []  # the scratch folder removed
    executor = object()
    table = tmp_path / "t.parquet"
    outcome = process_log(entry, KEY, options, scratch, table, executor=executor, chunk_workers=3)
    est = calls["estimate"]
    assert (est["chunking"].workers, est["executor"], est["output"]) == (3, executor, table)
    assert calls["fit"]["friction"] == table and outcome.table == table


def test_a_tasks_fault_is_one_line_and_no_rows(wiring, tmp_path):
    calls, _, entry = wiring
    calls["raise"] = InputError(f"{entry.log}: row 3, column 'q1': not a number")
    outcome = process_log(entry, KEY, BatchOptions(), tmp_path)
    assert outcome.failed and outcome.rows is None and outcome.key == KEY and outcome.entry == entry
    assert outcome.error == f"{entry.log}: row 3, column 'q1': not a number"
    calls["raise"] = ZeroDivisionError("float division by zero")
    outcome = process_log(entry, KEY, BatchOptions(), tmp_path)
    assert outcome.failed and outcome.error == f"{entry.log}: ZeroDivisionError: float division by zero"
