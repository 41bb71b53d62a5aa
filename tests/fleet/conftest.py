"""Small fleets of simulated Panda logs (a fixed-base arm: every sample estimated, a log in about a second)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from wbfriction.logs.tables import write_table
from wbfriction.model.loading import load_robot
from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm

DURATION = 3.0
"""Seconds per log: enough for every Panda joint's fit to be ``ok``."""


def arm_log(path: Path, seed: int, friction_scale: float = 1.0) -> dict:
    """Simulate one Panda log (its friction scaled by ``friction_scale``) into ``path``; its true friction."""
    robot = load_robot("panda")
    friction = {j: dataclasses.replace(p, F_c=p.F_c * friction_scale)
                for j, p in default_arm_friction(robot).items()}
    sim = simulate_arm(robot, friction, options=ArmOptions(duration=DURATION, seed=seed, torque_std=0.01))
    write_table(sim.table, path)
    return friction


@pytest.fixture(scope="session")
def arm_fleet(tmp_path_factory) -> tuple[Path, dict]:
    """A folder with three Panda logs (two of ``arm-1``, one of ``arm-2`` with 20 % more Coulomb friction), a
    manifest, and the true friction per log name."""
    folder = tmp_path_factory.mktemp("fleet")
    truth = {}
    for name, seed, scale in (("a1.parquet", 1, 1.0), ("a2.parquet", 2, 1.0), ("b1.parquet", 3, 1.2)):
        truth[name] = arm_log(folder / name, seed, scale)
    (folder / "manifest.csv").write_text(
        "log,robot_id,start_time,robot\n"
        "a1.parquet,arm-1,2026-03-01T08:00:00+00:00,panda\n"
        "a2.parquet,arm-1,2026-03-02T08:00:00+00:00,panda\n"
        "b1.parquet,arm-2,2026-03-01T09:30:00+01:00,panda\n")
    return folder, truth


@pytest.fixture
def synthetic_results():
    """:func:`write_synthetic_results`."""
    return write_synthetic_results


def write_synthetic_results(results: Path, logs: int, robot_id: str = "r1", joints: tuple[str, ...] = ("j0", "j1"),
                            F_c=lambda i: 1.0, temperature=lambda i: float("nan")) -> list[Path]:
    """A results folder of ``logs`` logs of one robot, one a day, written as a batch writes them
    (:func:`~wbfriction.fleet.results.write_part`), each joint's F_c (and friction at 0.3 rad/s) ``F_c(i)`` with a
    2 % standard error, its temperature ``temperature(i)`` [°C]; the files, in log order."""
    from datetime import UTC, datetime, timedelta

    import pyarrow as pa

    from wbfriction.fleet.results import write_part
    from wbfriction.fleet.schema import RESULT_SCHEMA

    paths = []
    for i in range(logs):
        rows: dict[str, list] = {name: [] for name in RESULT_SCHEMA.names}
        for joint in joints:
            row = {name: float("nan") for name in RESULT_SCHEMA.names}
            row.update(robot_id=robot_id, log=f"/logs/{robot_id}/{i}.parquet",
                       start_time=datetime(2026, 1, 1, tzinfo=UTC) + timedelta(days=i), key=f"{robot_id}-{i:04d}",
                       log_sha256=f"{robot_id}{i}", robot_sha256="", options_sha256="", joint=joint, model="thesis",
                       route="acceleration",
                       status="ok", n_samples=1000, version="test", F_c=F_c(i), F_c_se=0.02 * F_c(i),
                       temperature=temperature(i), **{"f_at_0.3": F_c(i), "f_at_0.3_se": 0.02 * F_c(i)})
            for name in RESULT_SCHEMA.names:
                rows[name].append(row[name])
        paths.append(write_part(results, pa.Table.from_pydict(rows, schema=RESULT_SCHEMA)))
    return paths
