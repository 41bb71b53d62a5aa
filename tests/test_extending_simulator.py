"""A new simulator is one file and one registry entry (issue 65, class 7): a toy simulator
(``toys/toy_simulator.py``: a fixed-base arm under a known Coulomb-viscous friction, ``--simulator toy-arm``),
registered with one call, runs in ``wbfriction simulate`` (in this process), and its log is estimated and fitted
back to the friction it injected; ``simulate`` refuses an option it does not read, and ``--simulator`` takes the
registered names. The built-in simulators are chosen as before (:mod:`wbfriction.sim.simulators`)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from helpers import run_cli_printed
from toys.toy_simulator import NAME, ToyArm, toy_friction
from wbfriction.exceptions import InputError
from wbfriction.model.loading import load_robot
from wbfriction.sim.simulators import (
    SimulationOutput,
    register_simulator,
    simulator_for,
    simulator_names,
    simulators,
    unregister_simulator,
)


@pytest.fixture
def toy():
    """The toy simulator registered (one call), and forgotten after the test."""
    kind = register_simulator(ToyArm())
    yield kind
    unregister_simulator(kind.name)


@pytest.fixture(scope="module")
def robots():
    return {name: load_robot(name) for name in ("panda", "go2", "go2_walking", "talos")}


def test_a_toy_simulator_runs_from_simulate_to_the_fitted_friction(toy, tmp_path, capsys):
    """``simulate --robot panda --simulator toy-arm`` writes the toy's log; ``estimate`` and ``fit`` recover the
    friction it injected, F_c and F_v within 3 %."""
    log = tmp_path / "toy.parquet"
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--simulator", NAME, "--duration", "8",
                                   "-o", log)
    assert (code, err.strip().splitlines()[-1]) == (0, f"wrote {log} (8000 samples, 8 s, {NAME})")
    for args in (("estimate", log, "--robot", "panda", "-o", tmp_path / "friction.parquet"),
                 ("fit", tmp_path / "friction.parquet", "--model", "coulomb-viscous", "--terms", "none", "-o",
                  tmp_path / "params.json")):
        code, _, err = run_cli_printed(capsys, *args)
        assert code == 0, (args[0], err)
    fits = json.loads((tmp_path / "params.json").read_text())["joints"]
    truth = toy_friction(load_robot("panda"))
    assert set(fits) == set(truth)
    for joint, p in truth.items():
        assert fits[joint]["model"] == "coulomb-viscous"
        for name in ("F_c", "F_v"):
            assert fits[joint]["params"][name] == pytest.approx(getattr(p, name), rel=0.03), (joint, name)


def test_an_option_the_toy_does_not_read_is_refused(toy, tmp_path, capsys):
    """An option of another simulator (``--gait``, ``--friction``) is refused in one line naming what the toy
    reads, exit 2, before the work: no log."""
    out = tmp_path / "toy.parquet"
    (tmp_path / "f.toml").write_text("")
    takes = f"robot 'panda' runs in the toy arm simulator (--simulator {NAME}): it takes --simulator, --duration, " \
            "--excitation-seed"
    for args, flag in ((("--gait", "trot"), "--gait"), (("--friction", tmp_path / "f.toml"), "--friction"),
                       (("--torque-noise", "0.01"), "--torque-noise")):
        code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--simulator", NAME, *args, "-o", out)
        assert (code, err.strip()) == (2, f"error: {flag}: {takes}; not {flag}")
    assert not out.exists()


def test_an_unknown_simulator_is_one_line_listing_the_registered_ones(toy, tmp_path, capsys):
    """``--simulator`` takes the registered simulators' names (the toy's too): another is one line listing them,
    exit 2, before the robot is loaded; after the toy is unregistered, its name is refused as well."""
    out = tmp_path / "log.parquet"
    code, _, err = run_cli_printed(capsys, "simulate", "--simulator", "bogus", "-o", out)
    assert (code, err.strip()) == (2, "error: --simulator must be one of toy-arm, ideal, mujoco, got 'bogus'")
    unregister_simulator(NAME)
    try:
        code, _, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "--simulator", NAME, "-o", out)
        assert (code, err.strip()) == (2, f"error: --simulator must be one of ideal, mujoco, got '{NAME}'")
    finally:
        register_simulator(toy)
    assert not out.exists()


def test_a_simulator_no_kind_claims_is_one_line(toy, tmp_path, capsys):
    """The toy claims fixed bases only: a walking robot with ``--simulator toy-arm`` is refused in one line."""
    code, _, err = run_cli_printed(capsys, "simulate", "--robot", "talos", "--simulator", NAME, "-o",
                                   tmp_path / "log.parquet")
    assert (code, err.strip()) == (2, f"error: --simulator {NAME}: no simulator runs robot 'talos' so (--simulator "
                                      "takes toy-arm, ideal, mujoco)")


DISPATCH = [  # robot, --actuator, --simulator -> the simulator that runs it
    ("panda", None, "ideal", "arm"), ("panda", None, "mujoco", "arm"), ("panda", "torque", "ideal", "arm"),
    ("panda", "pd", "ideal", "hung"), ("go2", None, "ideal", "hung"), ("go2", "pd", "mujoco", "hung"),
    ("go2_walking", None, "ideal", "quadruped"), ("go2_walking", "pd", "mujoco", "quadruped"),
    ("talos", None, "ideal", "ideal"), ("talos", None, "mujoco", "mujoco"), ("talos", "pd", "ideal", "hung"),
]


@pytest.mark.parametrize(("robot", "actuator", "simulator", "kind"), DISPATCH)
def test_the_builtin_simulators_are_chosen_as_before(robots, robot, actuator, simulator, kind):
    """Point feet: the quadruped; PD drivers (``--actuator pd``, or a robot with ``[pd]``): hung; a fixed base:
    the arm; the rest walks in the simulator ``--simulator`` names."""
    assert simulator_for(robots[robot], actuator, simulator).name == kind


def test_the_toy_is_chosen_by_its_name_on_a_fixed_base_only(toy, robots):
    """Registered, the toy runs a fixed base given its name, before the built-in arm; the rest is unchanged."""
    assert simulator_for(robots["panda"], None, NAME) is toy
    assert simulator_for(robots["panda"], None, "ideal").name == "arm"
    assert simulator_for(robots["go2"], None, NAME).name == "hung"
    with pytest.raises(InputError, match="no simulator runs robot 'go2_walking'"):
        simulator_for(robots["go2_walking"], None, NAME)


def test_the_registry_refuses_a_name_or_precedence_taken(toy):
    """Registration: a second simulator of a name or a precedence taken is refused; the registry's order and the
    names ``--simulator`` takes follow the precedence."""
    assert [k.name for k in simulators()] == ["quadruped", "hung", NAME, "arm", "ideal", "mujoco"]
    assert simulator_names() == (NAME, "ideal", "mujoco")
    with pytest.raises(ValueError, match=f"a simulator named '{NAME}' is registered already"):
        register_simulator(ToyArm())

    class Tied(ToyArm):
        name = "tied"

    with pytest.raises(ValueError, match="simulator 'tied' has the precedence 25 of 'toy-arm'"):
        register_simulator(Tied())
    with pytest.raises(ValueError, match="no simulator named 'tied'"):
        unregister_simulator("tied")
    with pytest.raises(ValueError, match="a log or a table"):
        SimulationOutput(summary="nothing")


def test_the_simulators_names_are_known_without_loading_them():
    """The registry and the built-in simulators import nothing heavy (the command line's help and ``--simulator``'s
    check read it as the command line is loaded); the help lists the names."""
    probe = ("import sys\nfrom wbfriction.sim.simulators import simulator_names\nprint(simulator_names())\n"
             "print(sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'pinocchio', 'pyarrow', 'scipy', "
             "'mujoco'}))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == ["('ideal', 'mujoco')", "[]"]
    from wbfriction.cli import simulate as simulate_cli
    assert "Registered: ideal, mujoco." in (simulate_cli.SimulatorOpt.help or "")
