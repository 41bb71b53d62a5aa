"""A walking robot's raw log made the project's log (wbfriction.pipeline.raw_log), against the simulated twin's truth:
the repeats found exactly, the contacts inferred as the simulator's, the rows not confident left out of the friction,
and ``estimate`` run on the raw log as a user runs it."""

from __future__ import annotations

import re
import subprocess
import sys
from importlib import resources
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from wbfriction.logs.options import ReadOptions
from wbfriction.model.loading import RobotSpec

TOML = Path(str(resources.files("wbfriction.model.robots").joinpath("go2_logged.toml")))  # the built-in twin's
RATE = 1 / 1.22e-3


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "wbfriction", *args], cwd=cwd, capture_output=True, text=True)


@pytest.fixture(scope="module")
def raw(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("raw")
    done = _cli("simulate", "--robot", str(TOML), "--simulator", "mujoco", "--gait", "trot", "--duration", "8",
                "--logger", "raw", "-o", "trot_raw.parquet", cwd=folder)
    assert done.returncode == 0, done.stderr
    return folder / "trot_raw.parquet"


@pytest.fixture(scope="module")
def prepared(raw):
    from wbfriction.pipeline.raw_log import prepare_raw

    robot = RobotSpec.given(str(TOML)).load()
    return robot, pq.read_table(raw), prepare_raw(pq.read_table(raw), robot, str(raw), ReadOptions(rate=RATE))


@pytest.mark.slow
def test_the_raw_log_is_recognised_and_a_full_log_is_not(prepared):
    from wbfriction.pipeline.raw_log import is_raw

    robot, table, done = prepared
    assert is_raw(robot, table.column_names)
    assert not is_raw(robot, done.table.column_names)  # contacts and base pose written: read as any log


@pytest.mark.slow
def test_repeats_found_exactly_and_contacts_as_the_simulators(prepared):
    robot, table, done = prepared
    out = done.table
    sample, raw_sample = np.asarray(out.column("sample_true")), np.asarray(table.column("sample_true"))
    np.testing.assert_array_equal(sample, raw_sample[np.r_[True, np.diff(raw_sample) != 0]])
    truth = np.column_stack([np.asarray(out.column(f"contact_true.{f}")) for f in robot.contact_frames]) > 0
    flags = np.column_stack([np.asarray(out.column(f"contact.{f}")) for f in robot.contact_frames]) > 0
    assert np.mean(flags == truth) >= 0.97  # the target
    unsure = np.asarray(out.column("unsure")) > 0
    np.testing.assert_array_equal(unsure, done.contacts.unconfident_rows())
    assert not any(c.startswith("imu.") for c in out.column_names)  # in base.* now


@pytest.mark.slow
def test_estimate_reads_the_raw_log_and_leaves_the_unsure_rows_out(raw, prepared, tmp_path):
    _, _, done = prepared
    out = tmp_path / "f.parquet"
    run = _cli("estimate", str(raw), "--robot", str(TOML), "--rate", repr(RATE), "--route", "acceleration",
               "-o", str(out), cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    said = run.stdout + run.stderr
    assert "contacts inferred from" in said and "base velocity from the stance legs" in said
    est = pq.read_table(out)
    unsure = done.contacts.unconfident_rows()
    assert est.num_rows == unsure.size and unsure.any()
    valid = np.column_stack([np.asarray(est.column(c)) for c in est.column_names if c.startswith("valid.")])
    assert valid.any() and not valid[unsure].any()


def test_a_robot_without_imu_is_refused_in_one_line(tmp_path):
    from wbfriction.exceptions import InputError
    from wbfriction.pipeline.raw_log import prepare_raw

    robot = RobotSpec.given("go2_walking").load()
    table = pa.table({"q.FL_hip_joint": np.zeros(3)})
    if robot.imu is not None:  # the built-in has one: drop it from a copy of the TOML
        import dataclasses

        robot = dataclasses.replace(robot, imu=None)
    with pytest.raises(InputError, match="has no \\[imu\\]"):
        prepare_raw(table, robot, "log.parquet")


@pytest.mark.slow
def test_a_standing_robot_and_too_few_samples_are_refused_in_one_line(tmp_path):
    """A robot that stands (no foot ever unloaded and lifted) and a log whose repeats leave fewer distinct samples
    than the contact inference needs: each one line, exit 2, nothing written."""
    done = _cli("simulate", "--robot", str(TOML), "--simulator", "mujoco", "--gait", "stand", "--duration", "2",
                "--logger", "raw", "-o", "stand.parquet", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    run = _cli("estimate", "stand.parquet", "--robot", str(TOML), "--rate", repr(RATE), "-o", "f.parquet",
               cwd=tmp_path)
    assert run.returncode == 2 and "no foot ever leaves the ground" in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and not (tmp_path / "f.parquet").exists()
    pq.write_table(pq.read_table(tmp_path / "stand.parquet").slice(0, 150), tmp_path / "short.parquet")
    run = _cli("estimate", "short.parquet", "--robot", str(TOML), "--rate", repr(RATE), "-o", "f.parquet",
               cwd=tmp_path)
    assert run.returncode == 2 and "distinct samples" in run.stderr, run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and not (tmp_path / "f.parquet").exists()


@pytest.mark.slow
def test_a_standing_robot_with_noisy_sensors_is_refused(tmp_path):
    """The twin standing 8 s with a Unitree's noise (its IMU's orientation too): near the end a front foot's load falls
    to a few per cent of the weight and a few isolated samples are lifted and unloaded (the longest run 6 samples,
    measured). Before, they passed the standing check and each foot was called off the ground on 39-44 % of the
    samples; now a swing needs a run that noise alone does not make: one line saying what was found, exit 2."""
    done = _cli("simulate", "--robot", str(TOML), "--simulator", "mujoco", "--gait", "stand", "--duration", "8",
                "--sensor-noise", "unitree", "--logger", "raw", "-o", "stand.parquet", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    run = _cli("estimate", "stand.parquet", "--robot", str(TOML), "--rate", repr(RATE), "-o", "f.parquet",
               cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    found = re.search(r"no foot ever leaves the ground \(a standing log\): the longest run of samples with a foot "
                      r"lifted and unloaded is (\d+) \(\d+ ms, \w+_foot\), against the (\d+) \(\d+ ms\) a swing needs "
                      r"among the log's \d+ runs", run.stderr)
    assert found and int(found[1]) < int(found[2]), run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and not (tmp_path / "f.parquet").exists()


@pytest.mark.slow
def test_the_stance_check_tells_the_true_friction_from_none_and_from_a_wrong_one(raw, prepared):
    """The self-consistency check (wbfriction.fit.stance_check) on the twin's stances: the true friction leaves the
    base's balance a smaller residual than no friction, and than twice the true friction; one leg's true friction
    alone (the others none, in both residuals) leaves less than none on the same samples."""
    import json

    from wbfriction.fit.stance_check import log_stance_check, log_stance_checks
    from wbfriction.friction.models import target_from_dict
    from wbfriction.logs.log import log_from_table

    robot, _, done = prepared
    truth = json.loads(pq.read_schema(raw).metadata[b"wbfriction"])["friction_true"]
    log = log_from_table(done.table, robot, "prepared")
    true = log_stance_check(robot, log, {j: target_from_dict(p) for j, p in truth.items()})
    doubled = log_stance_check(robot, log, {j: target_from_dict({**p, "F_c": 2 * p["F_c"], "F_v": 2 * p["F_v"]})
                                            for j, p in truth.items()})
    assert true.samples > 1000 and true.samples == doubled.samples
    assert true.moment_with < 0.6 * true.moment_without and true.force_with < true.force_without
    assert true.moment_with < 0.6 * doubled.moment_with
    leg = [j for j in robot.actuated if j.startswith("FL_")]  # some joints' friction only, as a user's ok fits
    part = log_stance_check(robot, log, {j: target_from_dict(truth[j]) for j in leg})
    assert part.samples == true.samples and part.joints == tuple(leg) and len(true.joints) == 12
    assert part.moment_without == true.moment_without and part.moment_with < part.moment_without
    together = log_stance_checks(robot, log, [{j: target_from_dict(p) for j, p in truth.items()},
                                              {j: target_from_dict(truth[j]) for j in leg}])
    assert together == [true, part]  # the log measured and each row's dynamics computed once: the same numbers


def test_the_stance_check_refuses_a_robot_not_on_point_feet():
    from wbfriction.exceptions import InputError
    from wbfriction.fit.stance_check import stance_check

    with pytest.raises(InputError, match="point feet"):
        stance_check(RobotSpec.given("panda").load(), None, {})  # type: ignore[arg-type]
