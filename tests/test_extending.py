"""A new kind of thing is one file and one registry entry (issues 54, 65): a toy friction family
(``toys/toy_family.py``), a toy export target (``toys/toy_target.py``), a toy log format (``toys/toy_format.py``) and
a toy torque source (``toys/toy_torque.py``), each registered with one call, reach every command (run in this
process, as ``docs/extending.md`` says registration reaches) and public function that takes their kind.

* The family: ``simulate --friction`` (its ``model`` key) injects it and logs its own characteristic; ``fit --model``
  recovers it; ``predict`` and ``report`` read its fits; ``export`` writes them (a built-in MJCF and the toy target);
  ``batch --model`` fits it; the rollout (:func:`~wbfriction.replay.rollout.rollout`) replays it as the (3.5) it equals.
  Every simulator's injection: ``tests/sim/test_injected_families.py``.
* The target: ``export -o FILE.csv`` (:func:`~wbfriction.pipeline.export_step.export_files`).
* The format: ``simulate -o`` writes it; ``estimate``, ``convert``, ``spectrum``, ``sensitivity``, ``identify``,
  ``rollout``, ``refine`` and ``batch`` (a folder's scan) read it.
* The torque source: a log written through it (:func:`~wbfriction.logs.log.write_log`: its own columns), then
  ``convert``, ``spectrum``, ``estimate`` (which says it) and ``fit`` read it.
"""

from __future__ import annotations

import csv
import json
from datetime import UTC, datetime

import numpy as np
import pyarrow as pa
import pytest

from helpers import run_cli_printed
from toys.toy_family import NAME, A, FixedSlope, FixedSlopeParams
from toys.toy_format import Feather
from toys.toy_target import FrictionCsv
from toys.toy_torque import SCALE, Effort
from wbfriction.export.registry import register_target, unregister_target
from wbfriction.friction.families.registry import register_family, unregister_family
from wbfriction.friction.models import FrictionParams
from wbfriction.logs import (
    read_log,
    register_format,
    register_torque_source,
    unregister_format,
    unregister_torque_source,
)
from wbfriction.logs.log import write_log
from wbfriction.logs.tables import read_metadata, read_table, write_table
from wbfriction.model.loading import load_robot
from wbfriction.sim.arm import default_arm_friction


@pytest.fixture
def toys(monkeypatch):
    """The three toys registered (one call each), and forgotten after the test."""
    family, fmt, target = register_family(FixedSlope()), register_format(Feather()), register_target(FrictionCsv())
    yield family, fmt, target
    unregister_family(family.name)
    unregister_format(fmt.name)
    unregister_target(target.name)


@pytest.fixture
def effort():
    """The toy torque source registered (one call), and forgotten after the test."""
    kind = register_torque_source(Effort())
    yield kind
    unregister_torque_source(kind.name)


def friction_toml(path, params: dict[str, FixedSlopeParams]):
    """``simulate --friction``'s TOML: the toy family (its ``model`` key) on each joint of ``params``."""
    path.write_text("".join(f'[friction.{j}]\nmodel = "{NAME}"\nF_v = {p.F_v!r}\nF_c = {p.F_c!r}\n'
                            f"tau_os = {p.tau_os!r}\n" for j, p in params.items()))
    return path


def test_a_toy_family_target_and_format_run_from_a_simulation_to_an_export(toys, tmp_path, cli):
    """The Panda simulated with the toy family (the thesis's defaults with S = 0, the toy's slope) into the toy
    format; its log estimated, fitted with the toy family, predicted and exported by the toy target: the friction
    injected comes out of the other end."""
    robot = load_robot("panda")
    truth = {j: FixedSlopeParams(F_v=p.F_v, F_c=p.F_c, tau_os=p.tau_os) for j, p in default_arm_friction(robot).items()}
    log = tmp_path / "arm.feather"
    cli("simulate", "--robot", "panda", "--friction", friction_toml(tmp_path / "toy.toml", truth), "--duration", "6",
        "--torque-noise", "0.01", "--noise-seed", "3", "-o", log)
    assert log.read_bytes()[:6] == b"ARROW1"  # written through the toy format: it claims the name
    table = read_table(log)
    for joint, p in truth.items():  # the toy's own characteristic injected and logged
        assert read_metadata(table)["friction_true"][joint]["model"] == NAME
        np.testing.assert_allclose(table[f"tau_f_true.{joint}"].to_numpy(),
                                   p.torque(table[f"qd_true.{joint}"].to_numpy()), rtol=1e-12, atol=1e-12)

    cli("estimate", log, "--robot", "panda", "-o", tmp_path / "friction.parquet")
    cli("fit", tmp_path / "friction.parquet", "--model", NAME, "--terms", "none", "-o", tmp_path / "params.json")
    predicted = cli("predict", tmp_path / "friction.parquet", "--params", tmp_path / "params.json")
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
    everyone = next(line.split() for line in predicted.splitlines() if line.strip().startswith("all joints"))
    rigid, with_friction = float(everyone[3]), float(everyone[4])  # the RMS without and with the toy's fits
    assert with_friction < 0.1 * rigid  # what is left is the 0.01 N·m torque noise, not the friction of ~1 N·m


def test_a_toy_torque_source_runs_from_a_log_to_the_fitted_friction(toys, effort, tmp_path, cli, capsys):
    """The Panda simulated with the toy family (its currents logged), its log written through the toy torque source
    (``effort.<joint>`` in mN·m, no current), then converted, read, estimated and fitted: the friction injected comes
    out of the other end, and the outputs say where the torque came from."""
    robot = load_robot("panda")
    truth = {j: FixedSlopeParams(F_v=p.F_v, F_c=p.F_c, tau_os=p.tau_os) for j, p in default_arm_friction(robot).items()}
    cli("simulate", "--robot", "panda", "--friction", friction_toml(tmp_path / "toy.toml", truth), "--duration", "6",
        "--torque-noise", "0.01", "--noise-seed", "3", "-o", tmp_path / "arm.parquet")
    simulated = read_log(tmp_path / "arm.parquet", robot)
    assert simulated.torque_source == "current"
    simulated.torque_source = effort.name
    write_log(simulated, robot, tmp_path / "effort.parquet")
    table = read_table(tmp_path / "effort.parquet")
    assert not [c for c in table.column_names if c.partition(".")[0] in ("tau", "tau_est", "current", "q_des")]
    for i, joint in enumerate(robot.torque_controlled):  # its own columns, in its own unit
        np.testing.assert_allclose(table[f"effort.{joint}"].to_numpy(), simulated.tau[:, i] / SCALE, rtol=1e-15)

    log = tmp_path / "converted.parquet"
    cli("convert", tmp_path / "effort.parquet", "--robot", "panda", "-o", log)
    back = read_log(log, robot)
    assert back.torque_source == effort.name
    np.testing.assert_allclose(back.tau, simulated.tau, rtol=1e-15, atol=0)
    cli("spectrum", log, "--robot", "panda", "--joints", "panda_joint1", "-o", tmp_path / "spectrum.png")
    assert (tmp_path / "spectrum.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, _, said = run_cli_printed(capsys, "estimate", log, "--robot", "panda", "-o", tmp_path / "friction.parquet")
    assert code == 0, said
    assert f"torque: {Effort.what}\n" in said  # the text output says it, as it says a built-in's
    assert read_metadata(read_table(tmp_path / "friction.parquet"))["torque_source"] == {
        "source": effort.name, "what": Effort.what}
    cli("fit", tmp_path / "friction.parquet", "--model", NAME, "--terms", "none", "-o", tmp_path / "params.json")
    fits = json.loads((tmp_path / "params.json").read_text())["joints"]
    assert set(fits) == set(truth)
    for joint, p in truth.items():
        for name in ("F_c", "F_v"):
            assert fits[joint]["params"][name] == pytest.approx(getattr(p, name), rel=0.05), (joint, name)


def test_a_torque_source_is_refused_a_name_or_precedence_taken(effort):
    """One source per name and per place in the order: the toy registered twice, or at the currents' precedence, is
    refused, naming what holds it; the order is the precedence's, whatever the order of registration."""
    from wbfriction.logs import torque_sources

    with pytest.raises(ValueError, match="'effort' is registered already"):
        register_torque_source(Effort())
    tied = type("Tied", (Effort,), {"name": "tied", "precedence": 30})
    with pytest.raises(ValueError, match="precedence 30 of 'current'"):
        register_torque_source(tied())
    assert [k.name for k in torque_sources()] == ["sensor", "driver", "effort", "current", "pd"]


@pytest.mark.slow
def test_the_toys_reach_every_other_command_that_takes_their_kind(toys, tmp_path, cli):
    """The toy format read by every other command that reads a log, on a Panda log (``convert``, ``spectrum``,
    ``sensitivity``, ``batch``'s folder scan) and a hung Go2's (``identify --actuator pd``, ``rollout``,
    ``refine``); the toy family fitted by ``batch --model``, read by ``report``, exported as a built-in MJCF that
    ``rollout`` replays, and replayed by the rollout function as the (3.5) it equals (about 30 s)."""
    panda = load_robot("panda")
    truth = {j: FixedSlopeParams(F_v=p.F_v, F_c=p.F_c, tau_os=p.tau_os) for j, p in default_arm_friction(panda).items()}
    arm = tmp_path / "arm.feather"
    cli("simulate", "--robot", "panda", "--friction", friction_toml(tmp_path / "toy.toml", truth), "--duration", "3",
        "-o", arm)
    cli("convert", arm, "--robot", "panda", "-o", tmp_path / "arm.parquet")
    assert read_table(tmp_path / "arm.parquet").select(read_table(arm).column_names).equals(read_table(arm))
    cli("spectrum", arm, "--robot", "panda", "--joints", "panda_joint1", "-o", tmp_path / "spectrum.png")
    cli("sensitivity", arm, "--robot", "panda", "--factors", "1.1", "--joints", "panda_joint1",
        "-o", tmp_path / "sensitivity.png")
    for path in (tmp_path / "spectrum.png", tmp_path / "sensitivity.png"):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    # batch: a folder of one robot, its log in the toy format (its time as dates), the toy family fitted
    dated = read_table(arm)
    start = datetime(2026, 3, 1, 8, tzinfo=UTC).timestamp()
    dated = dated.set_column(0, "time", pa.array(((start + dated["time"].to_numpy()) * 1e9).astype("int64"),
                                                 pa.timestamp("ns", tz="UTC")))
    (tmp_path / "fleet" / "arm-1").mkdir(parents=True)
    write_table(dated, tmp_path / "fleet" / "arm-1" / "run.feather")
    cli("batch", tmp_path / "fleet", "--robot", "panda", "--model", NAME, "--terms", "none", "--serial",
        "-o", tmp_path / "results")
    from wbfriction.fleet.results import read_results
    results = read_results(tmp_path / "results").table
    assert set(results["model"].to_pylist()) == {NAME} and results.num_rows == len(truth)
    cli("estimate", arm, "--robot", "panda", "-o", tmp_path / "friction.parquet")
    cli("fit", tmp_path / "friction.parquet", "--model", NAME, "--terms", "none", "-o", tmp_path / "params.json")
    cli("report", tmp_path / "friction.parquet", "--params", tmp_path / "params.json", "-o", tmp_path / "report.html")
    assert NAME in (tmp_path / "report.html").read_text()

    # the hung Go2, its log in the toy format: the actuators identified, the toy family's fit exported and replayed
    hung = tmp_path / "hung.feather"
    cli("simulate", "--robot", "go2", "--actuator", "pd", "--duration", "4", "-o", hung)
    cli("identify", hung, "--robot", "go2", "--actuator", "pd", "--json", tmp_path / "actuator.json")
    cli("estimate", hung, "--robot", "go2", "-o", tmp_path / "hung_friction.parquet")
    cli("fit", tmp_path / "hung_friction.parquet", "--model", NAME, "--terms", "none",
        "-o", tmp_path / "hung_params.json")
    cli("export", tmp_path / "hung_params.json", "--robot", "go2", "--include", "weak,at-bound",
        "-o", tmp_path / "go2.xml")
    cli("rollout", hung, tmp_path / "go2.xml", "--robot", "go2", "-o", tmp_path / "rollout.parquet")
    tracking = read_table(tmp_path / "rollout.parquet")["rms_windows"].to_numpy()
    assert (tracking < 0.01).all(), tracking  # the exported fit tracks the log (measured: 1-4 mrad)
    cli("refine", hung, tmp_path / "go2.xml", "--robot", "go2", "--to", "1.5", "-o", tmp_path / "refined.xml")
    assert (tmp_path / "refined.xml").read_text().lstrip().startswith(("<", "<!--"))

    from wbfriction.replay.rollout import ActuatorParams, rollout
    go2 = load_robot("go2")
    toy = {j: FixedSlopeParams(F_v=0.2, F_c=0.4, tau_os=0.05) for j in go2.actuated}
    thesis = {j: FrictionParams(F_v=0.2, F_c=0.4, S=0.0, v_s=0.05, tau_os=0.05, a=A) for j in go2.actuated}
    ours, same = (rollout(go2, hung, ActuatorParams(friction=f), times=(0.0, 2.0)) for f in (toy, thesis))
    assert ours.no_friction == () and ours.joints == same.joints
    np.testing.assert_allclose(ours.q_sim, same.q_sim, rtol=0, atol=1e-12)  # the toy is (3.5) with S = 0, a = A


def test_the_help_lists_the_registered_targets_and_formats(tmp_path):
    """Registered before the command line is loaded (as an installed package's entry point or the package itself
    registers them), the toy target and format are in the help that lists the targets and formats: the help reads the
    catalogs the registries keep, no list of its own (issue 65, class 7)."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    script = (f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
              "from toys.toy_format import Feather\nfrom toys.toy_target import FrictionCsv\n"
              "from wbfriction.export.registry import register_target\nfrom wbfriction.logs import register_format\n"
              "register_target(FrictionCsv()); register_format(Feather())\n"
              "from wbfriction.entry import main\nmain()\n")
    env = {**os.environ, "COLUMNS": "200"}
    export = subprocess.run([sys.executable, "-c", script, "export", "--help"], capture_output=True, text=True, env=env)
    simulate = subprocess.run([sys.executable, "-c", script, "simulate", "--help"], capture_output=True, text=True,
                              env=env)
    assert export.returncode == 0 and simulate.returncode == 0, (export.stderr, simulate.stderr)
    assert f"{FrictionCsv.suffixes[0]} ({FrictionCsv.description})" in " ".join(export.stdout.split())
    assert Feather.suffixes[0] in simulate.stdout


def effort_table(robot, extra: dict[str, pa.Array]) -> pa.Table:
    """A still log of ``robot`` whose torque is the toy source's (``effort.<joint>`` [mN·m]), with ``extra`` columns
    (a column of the same name replaced)."""
    n = 50
    columns = {"time": pa.array(np.arange(n) * 1e-3)}
    columns |= {f"q.{j}": pa.array(np.zeros(n)) for j in robot.actuated}
    columns |= {f"effort.{j}": pa.array(np.full(n, 100.0)) for j in robot.torque_controlled}
    return pa.table(columns | extra)


def test_the_schema_checks_a_registered_torque_source_s_columns_as_a_built_in_s(effort, tmp_path):
    """The guide's torque source registered (``docs/extending.md``: ``effort.<joint>``): a column of it naming no
    joint of the robot is refused, naming it, as ``tau.<joint>`` would be; one holding text (numbers written as text)
    is refused, naming it, not read as numbers; the same log with its own columns only is read (issue 81)."""
    from wbfriction.exceptions import ColumnError

    robot = load_robot("panda")
    joint = robot.torque_controlled[0]
    good = tmp_path / "effort.parquet"
    write_table(effort_table(robot, {}), good)
    assert read_log(good, robot).torque_source == effort.name
    for name, extra, said in (
            ("unknown", {"effort.no_such_joint": pa.array(np.zeros(50))},
             "column 'effort.no_such_joint' names an unknown joint 'no_such_joint'"),
            ("text", {f"effort.{joint}": pa.array(["100.0"] * 50)},
             f"column 'effort.{joint}' holds string values, not numbers")):
        path = tmp_path / f"{name}.parquet"
        write_table(effort_table(robot, extra), path)
        with pytest.raises(ColumnError, match=said) as caught:
            read_log(path, robot)
        assert caught.value.column == next(iter(extra))
    # the built-in sources' columns are asked the same way: the sensors' tau of an unknown joint is refused
    write_table(effort_table(robot, {"tau.no_such_joint": pa.array(np.zeros(50))}), path := tmp_path / "tau.parquet")
    with pytest.raises(ColumnError, match="column 'tau.no_such_joint' names an unknown joint"):
        read_log(path, robot)
