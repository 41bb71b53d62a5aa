"""A new engine is one file and one registry entry: a toy engine (``toys/toy_engine.py``: the ideal simulator with
finer physics steps by default) registered with one call runs in ``simulate`` (a biped's walk and a quadruped's
gait), ``demo`` and ``study-quadruped`` (in this process) as ``--simulator ideal-fine``; ``--simulator`` takes the
registered names, and a rig without an engine refuses it."""

from __future__ import annotations

import json

import pytest

from helpers import run_cli_printed
from toys.toy_engine import NAME, FineIdeal
from wbfriction.model.loading import load_robot
from wbfriction.rigs import rig_for
from wbfriction.sim.engines import engine_names, register_engine, unregister_engine


@pytest.fixture
def toy():
    engine = register_engine(FineIdeal())
    try:
        yield engine
    finally:
        unregister_engine(engine.name)


def test_the_toy_engine_runs_a_walk_finer_and_the_same(toy, tmp_path, capsys):
    """A biped's walk in the toy engine: the same samples as the ideal simulator's at 2 physics steps, which it
    takes by default (its log's joint angles within 1e-12 rad of ``--simulator ideal --substeps 2``)."""
    import pyarrow.parquet as pq

    logs = {}
    for name, args in (("fine", ("--simulator", NAME)), ("ideal", ("--simulator", "ideal", "--substeps", "2"))):
        logs[name] = tmp_path / f"{name}.parquet"
        code, _, err = run_cli_printed(capsys, "simulate", "--robot", "talos", "--steps", "1", *args, "-o", logs[name])
        assert code == 0, err
    fine, ideal = (pq.read_table(p) for p in logs.values())
    column = "q.leg_right_4_joint"
    assert fine.num_rows == ideal.num_rows
    assert abs(fine.column(column).to_numpy() - ideal.column(column).to_numpy()).max() < 1e-12


def test_the_toy_engine_runs_a_quadruped_in_simulate_demo_and_the_study(toy, tmp_path, capsys):
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "go2_walking", "--simulator", NAME, "--duration",
                                   "1", "-o", tmp_path / "trot.parquet")
    assert code == 0 and "500 samples, 1 s, trot" in err, err
    code, out, err = run_cli_printed(capsys, "demo", "--robot", "go2_walking", "--simulator", NAME, "--rig-option",
                                     "duration=2", "-o", tmp_path / "demo")
    assert code == 0 and "Fits" in out, err
    assert json.loads((tmp_path / "demo" / "quadruped.json").read_text())["case"]["simulator"] == NAME
    code, _, err = run_cli_printed(capsys, "study-quadruped", "--simulator", NAME, "--duration", "2", "-o",
                                   tmp_path / "study")
    assert code == 0, err


def test_simulator_takes_the_registered_engines(toy, tmp_path, capsys):
    """``--simulator`` takes the registered engines' names: another is one line listing them; a rig that runs in
    none (an arm) refuses ``--simulator``; an engine that does not simulate a rig's motion is refused by name."""
    assert engine_names() == ("ideal", NAME, "mujoco")
    out = tmp_path / "x.parquet"
    code, _, err = run_cli_printed(capsys, "simulate", "--simulator", "bogus", "-o", out)
    assert (code, err.strip()) == (2, f"error: --simulator must be one of ideal, {NAME}, mujoco, got 'bogus'")
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--simulator", NAME, "-o", out)
    assert code == 2 and err.strip().startswith("error: --simulator: robot 'panda' is a fixed-base arm"), err
    unregister_engine(NAME)
    try:
        code, _, err = run_cli_printed(capsys, "simulate", "--robot", "talos", "--simulator", NAME, "-o", out)
        assert (code, err.strip()) == (2, f"error: --simulator must be one of ideal, mujoco, got '{NAME}'")
    finally:
        register_engine(toy)
    assert not out.exists()


def test_an_engine_without_a_motion_is_not_offered_for_it():
    """An engine that simulates walks only is among a biped's engines, not a quadruped's; ``--simulator`` naming it
    for a quadruped is one line naming those that run it."""
    from wbfriction.exceptions import InputError
    from wbfriction.sim.engines import Engine

    class WalksOnly(Engine):
        name, precedence, what = "walks-only", 16, "walks only"

        def walk(self, robot, reference, friction, terms, settings, options, progress):
            raise NotImplementedError

    register_engine(WalksOnly())
    try:
        go2, talos = load_robot("go2_walking"), load_robot("talos")
        assert "walks-only" in [e.name for e in rig_for(talos).engines()]
        assert "walks-only" not in [e.name for e in rig_for(go2).engines()]
        with pytest.raises(InputError, match="--simulator walks-only: robot 'go2_walking' stands on point feet .*: "
                                             "it runs on ideal, mujoco"):
            rig_for(go2).engine(go2, "walks-only")
    finally:
        unregister_engine("walks-only")
