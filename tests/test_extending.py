"""A new kind of thing is one file and one registry entry (issue 54): a toy friction family
(``toys/toy_family.py``), a toy export target (``toys/toy_target.py``) and a toy log format (``toys/toy_format.py``),
each registered with one call, carry a simulated arm's log from its file through ``estimate``, ``fit`` and
``export`` on the command line, and the friction injected comes out of the other end."""

from __future__ import annotations

import csv
import dataclasses
import json

import numpy as np
import pytest

from helpers import run_cli_printed
from toys.toy_family import NAME, A, FixedSlope
from toys.toy_format import Feather
from toys.toy_target import FrictionCsv
from wbfriction.export import registry
from wbfriction.export.registry import register_target
from wbfriction.friction.families.registry import register_family, unregister_family
from wbfriction.logs import register_format, unregister_format
from wbfriction.logs.tables import write_table
from wbfriction.model.loading import load_robot
from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm


@pytest.fixture
def toys(monkeypatch):
    """The three toys registered (one call each), and forgotten after the test."""
    monkeypatch.setattr(registry, "TARGETS", dict(registry.TARGETS))  # the export targets as they were, after
    family, fmt, target = register_family(FixedSlope()), register_format(Feather()), register_target(FrictionCsv())
    yield family, fmt, target
    unregister_family(family.name)
    unregister_format(fmt.name)


def test_a_toy_family_target_and_format_run_from_a_log_to_an_export(toys, tmp_path, capsys):
    robot = load_robot("panda")
    truth = {j: dataclasses.replace(p, S=0.0, a=A) for j, p in default_arm_friction(robot).items()}  # the toy's
    sim = simulate_arm(robot, truth, options=ArmOptions(duration=6.0, seed=3, torque_std=0.01))
    log = tmp_path / "arm.feather"
    write_table(sim.table, log)  # through the toy format: it claims the name
    assert log.read_bytes()[:6] == b"ARROW1"

    def cli(*args):
        code, out, err = run_cli_printed(capsys, *args)
        assert code == 0, err
        return out

    cli("estimate", log, "--robot", "panda", "-o", tmp_path / "friction.parquet")
    cli("fit", tmp_path / "friction.parquet", "--model", NAME, "--terms", "none", "-o", tmp_path / "params.json")
    cli("export", tmp_path / "params.json", "--robot", "panda", "--include", "weak", "-o", tmp_path / "friction.csv")

    fits = json.loads((tmp_path / "params.json").read_text())["joints"]
    rows = {r["joint"]: r for r in csv.DictReader((tmp_path / "friction.csv").open())}
    assert set(rows) == set(truth)
    for joint, p in truth.items():
        fit = fits[joint]
        assert fit["model"] == NAME
        for name in ("F_c", "F_v"):
            assert fit["params"][name] == pytest.approx(getattr(p, name), rel=0.05), (joint, name)
            assert float(rows[joint][name]) == fit["params"][name]  # exported as fitted, to the bit
    assert np.isfinite([f["stderr"]["F_c"] for f in fits.values()]).all()
