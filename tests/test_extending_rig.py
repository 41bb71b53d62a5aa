"""A new rig is one file and one registry entry: a toy rig (``toys/toy_rig.py``: a fixed-base arm tracking sines
of its own option ``sine_share``) registered with one call runs ``simulate``, ``excite``, ``identify`` and ``demo``
(in this process), its own option given with ``--rig-option``, which the other rigs refuse; its log is estimated and
fitted back to the friction it injected. The built-in rigs are decided as before (:mod:`wbfriction.rigs`)."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pyarrow.parquet as pq
import pytest

from helpers import run_cli_printed
from toys.toy_rig import NAME, ToyArm, sines, toy_friction
from wbfriction.exceptions import InputError
from wbfriction.model.loading import load_robot
from wbfriction.rigs import SimulationOutput, register_rig, rig_for, rigs, unregister_rig


@pytest.fixture
def toy():
    """The toy rig registered (one call), and forgotten after the test."""
    rig = register_rig(ToyArm())
    try:
        yield rig
    finally:  # a test that failed leaves the built-in arm as it found it
        unregister_rig(rig.name)


@pytest.fixture(scope="module")
def robots():
    return {name: load_robot(name) for name in ("panda", "go2", "go2_walking", "talos")}


def test_a_toy_rig_runs_simulate_with_its_own_option_to_the_fitted_friction(toy, tmp_path, capsys):
    """``simulate --robot panda --rig-option sine_share=0.3`` writes the toy's log, its sines that share of each
    half range; ``estimate`` and ``fit`` recover the friction it injected, F_c and F_v within 3 %."""
    log = tmp_path / "toy.parquet"
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--rig-option", "sine_share=0.3",
                                   "--duration", "8", "-o", log)
    assert (code, err.strip().splitlines()[-1]) == (0, f"wrote {log} (8000 samples, 8 s, {NAME})")
    panda = load_robot("panda")
    q_ref = sines(panda, 0.3, 0, pq.read_table(log).column("time").to_numpy())[0]
    q = pq.read_table(log).column("q.panda_joint1").to_numpy()
    assert abs(q - q_ref[:, 0]).max() < 0.05 * (q_ref[:, 0].max() - q_ref[:, 0].min())
    for args in (("estimate", log, "--robot", "panda", "-o", tmp_path / "friction.parquet"),
                 ("fit", tmp_path / "friction.parquet", "--model", "coulomb-viscous", "--terms", "none", "-o",
                  tmp_path / "params.json")):
        code, _, err = run_cli_printed(capsys, *args)
        assert code == 0, (args[0], err)
    fits = json.loads((tmp_path / "params.json").read_text())["joints"]
    truth = toy_friction(panda)
    assert set(fits) == set(truth)
    for joint, p in truth.items():
        for name in ("F_c", "F_v"):
            assert fits[joint]["params"][name] == pytest.approx(getattr(p, name), rel=0.03), (joint, name)


def test_the_toys_excite_identify_and_demo_run(toy, tmp_path, capsys):
    """``excite`` writes the toy's set-points at its own option; ``identify`` takes the inertia model's route on its
    log (the toy does not identify PD drivers); ``demo`` prints each joint's fit against the friction injected."""
    code, out, err = run_cli_printed(capsys, "excite", "--robot", "panda", "--rig-option", "sine_share=0.2",
                                     "--duration", "4", "-o", tmp_path / "sp.parquet", "--json", tmp_path / "sp.json")
    assert code == 0, err
    assert json.loads((tmp_path / "sp.json").read_text())["sine_share"] == 0.2
    assert pq.read_table(tmp_path / "sp.parquet").num_rows == 4000 and "sines of 0.2 of each half range" in out
    code, _, err = run_cli_printed(capsys, "excite", "--robot", "panda", "--duration", "4", "-o",
                                   tmp_path / "x.parquet", "--figure", tmp_path / "x.png")
    assert (code, err.strip()) == (2, "error: --figure: robot 'panda' is on the toy arm rig: its design draws no "
                                      "figure")
    assert not (tmp_path / "x.parquet").exists()
    code, out, err = run_cli_printed(capsys, "demo", "--robot", "panda", "--rig-option", "duration=4", "-o",
                                     tmp_path / "demo")
    assert code == 0, err
    truth = toy_friction(load_robot("panda"))
    found = re.findall(r"(\S+): F_c (\S+) \(true \S+\), F_v (\S+) \(true \S+\), ok", out)
    assert len(found) == len(truth), out
    for joint, F_c, F_v in found:
        assert float(F_c) == pytest.approx(truth[joint].F_c, rel=0.05)
        assert float(F_v) == pytest.approx(truth[joint].F_v, rel=0.05)
    code, _, err = run_cli_printed(capsys, "identify", tmp_path / "demo" / "toy.parquet", "--robot", "panda", "-o",
                                   tmp_path / "toy.urdf")
    assert code == 0 and (tmp_path / "toy.urdf").exists(), err


@pytest.mark.parametrize(("command", "robot", "rig"), [
    ("simulate", "go2", "is a hung PD-driven robot"), ("simulate", "talos", "is a biped on soles"),
    ("simulate", "go2_walking", "stands on point feet"), ("excite", "talos", "is a biped on soles"),
    ("demo", "go2_walking", "stands on point feet")])
def test_the_other_rigs_refuse_the_toys_option(toy, tmp_path, capsys, command, robot, rig):
    """``--rig-option sine_share=...`` on a robot of another rig: one line naming the rig's options, exit 2, nothing
    written."""
    out = ("-o", tmp_path / ("d" if command == "demo" else "x.parquet"))
    code, _, err = run_cli_printed(capsys, command, "--robot", robot, "--rig-option", "sine_share=0.3", *out)
    assert code == 2 and err.strip().startswith("error: --rig-option sine_share: not an option here (the options: ")
    assert not out[1].exists()


def test_without_the_toy_the_arm_refuses_its_option(tmp_path, capsys):
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--rig-option", "sine_share=0.3", "-o",
                                   tmp_path / "x.parquet")
    assert code == 2 and "--rig-option sine_share: not an option here" in err


def test_a_rig_option_of_the_wrong_type_or_shape_is_one_line(tmp_path, capsys):
    for text, line in (("duration=long", "--rig-option duration=long: not a float"),
                       ("duration", "--rig-option 'duration': NAME=VALUE"),
                       ("duration=-3", "--duration must be a number in (0, 3600] s")):
        code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--rig-option", text, "-o",
                                       tmp_path / "x.parquet")
        assert code == 2 and line in err, (text, err)


DISPATCH = [  # robot, --actuator -> its rig
    ("panda", None, "arm"), ("panda", "torque", "arm"), ("panda", "pd", "hung"), ("go2", None, "hung"),
    ("go2", "pd", "hung"), ("go2_walking", None, "quadruped"), ("go2_walking", "pd", "quadruped"),
    ("talos", None, "biped"), ("talos", "pd", "hung"),
]


@pytest.mark.parametrize(("robot", "actuator", "rig"), DISPATCH)
def test_the_builtin_rigs_are_decided_as_before(robots, robot, actuator, rig):
    """Point feet: the quadruped; PD drivers (``--actuator pd``, or a robot with ``[pd]``): hung; a fixed base:
    the arm; soles: the biped."""
    assert rig_for(robots[robot], actuator).name == rig


def test_the_toy_comes_before_the_arm_on_a_torque_driven_fixed_base(toy, robots):
    assert rig_for(robots["panda"]) is toy
    assert rig_for(robots["panda"], "pd").name == "hung" and rig_for(robots["go2"]).name == "hung"
    assert rig_for(robots["talos"]).name == "biped"


def test_the_engines_a_rig_runs_on(robots):
    """The biped and the quadruped run in an engine (``--simulator``: ideal by default); the arm and the hung robot
    in their own simulator; an engine a rig does not run on is one line."""
    quadruped, biped, arm = (rig_for(robots[n]) for n in ("go2_walking", "talos", "panda"))
    assert [e.name for e in biped.engines()] == [e.name for e in quadruped.engines()] == ["ideal", "mujoco"]
    assert biped.engine(robots["talos"], None).name == "ideal" and arm.engine(robots["panda"], "mujoco") is None
    assert biped.engine_options(biped.engine(robots["talos"], "mujoco")).__name__ == "MujocoWalkOptions"
    assert quadruped.engine_options(quadruped.engine(robots["go2_walking"], "mujoco")) is None


def test_the_registry_refuses_a_name_or_precedence_taken(toy):
    assert [r.name for r in rigs()] == ["quadruped", "hung", NAME, "arm", "biped"]
    with pytest.raises(ValueError, match=f"a rig named '{NAME}' is registered already"):
        register_rig(ToyArm())

    class Tied(ToyArm):
        name = "tied"

    with pytest.raises(ValueError, match="rig 'tied' has the precedence 25 of 'toy-arm'"):
        register_rig(Tied())
    with pytest.raises(ValueError, match="no rig named 'tied'"):
        unregister_rig("tied")
    with pytest.raises(ValueError, match="a log or a table"):
        SimulationOutput(summary="nothing")


def test_a_robot_no_rig_claims_is_one_line(robots):
    """With the built-in biped unregistered, a robot on soles is on no rig: one line naming it and the rigs."""
    biped = unregister_rig("biped")
    try:
        with pytest.raises(InputError, match=r"robot 'talos' \(a floating base on soles\) is on no registered rig "
                                             r"\(quadruped, hung, arm\)"):
            rig_for(robots["talos"])
    finally:
        register_rig(biped)


def test_the_rigs_and_engines_are_known_without_loading_them():
    """The registries and the built-in rigs and engines import nothing heavy (the command line reads their options
    as it is loaded)."""
    probe = ("import sys\nfrom wbfriction.rigs import rigs\nfrom wbfriction.sim.engines import engine_names\n"
             "print([r.name for r in rigs()], engine_names())\n"
             "print(sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'pinocchio', 'pyarrow', 'scipy', "
             "'mujoco'}))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == ["['quadruped', 'hung', 'arm', 'biped'] ('ideal', 'mujoco')", "[]"]
