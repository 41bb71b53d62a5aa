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
