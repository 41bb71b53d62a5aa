"""Options that do not apply to the robot or the mode a command runs in are refused, not ignored (issue 65,
class 6): one line naming the option, the mode and what it takes, exit 2, before the work, nothing written.
``simulate``'s modes (a robot on point feet, a hung PD-driven robot, an arm, a walk ideal or on MuJoCo) and
``identify``'s (the inertia model, ``--actuator pd``) each read the options of their table (each rig's
:attr:`~wbfriction.rigs.base.Rig.simulation` fields and its engine's, :data:`wbfriction.cli.identify.MODES`);
the refusal is :func:`wbfriction.cli.common.refuse_options`. Also the misleading lines of class 5 in these commands."""

from __future__ import annotations

import json

import pytest
import typer.main

from helpers import run_cli, said
from wbfriction.cli import actuator as actuator_cli
from wbfriction.cli import app
from wbfriction.cli import identify as identify_cli
from wbfriction.cli import rigs as rigs_cli
from wbfriction.cli import simulate as simulate_cli
from wbfriction.cli.common import option_flag
from wbfriction.exceptions import InputError
from wbfriction.options import option_names
from wbfriction.rigs.registry import RIGS
from wbfriction.sim.engines import engine_of

COMMANDS = typer.main.get_command(app).commands  # type: ignore[attr-defined]


MODES = {"quadruped": ("quadruped", "ideal"), "hung": ("hung", None), "arm": ("arm", None), "ideal": ("biped", "ideal"),
         "mujoco": ("biped", "mujoco")}
"""Each mode of ``simulate``: the rig and the engine it runs in."""


def simulator_options() -> dict[str, tuple[str, ...]]:
    """The options each mode reads beyond ``simulate``'s shared ones: its rig's and its engine's, ``--simulator``
    where it runs in one."""
    found = {}
    for mode, (rig_name, engine_name) in MODES.items():
        rig, engine = RIGS.get(rig_name), None if engine_name is None else engine_of(engine_name)
        found[mode] = (*option_names(rig.simulation), *option_names(rig.engine_options(engine)),
                       *(("simulator",) if engine is not None else ()))
    return found

HUNG = ("robot 'go2' is a hung PD-driven robot (fixed base, [pd]): it takes --friction, --substeps, "
        "--mujoco-friction, --position-noise, --encoder-bits, --noise-seed, --delay, --friction-timeconst, "
        "--duration, --excitation-seed, --setpoints, --driver-noise, --velocity-noise, --play")
QUADRUPED = ("robot 'go2_walking' stands on point feet (a walking quadruped), simulated in ideal: it takes --gait, "
             "--friction, --simulator, --substeps, --sensors, --position-noise, --encoder-bits, --torque-noise, "
             "--noise-seed, --duration, --excitation-seed, --speed, --foot-forces, --play, --sensor-noise, --logger, "
             "--logger-period, --imu-period, --angles, --kt-error, --foot-counts/--no-foot-counts, --contacts")
ARM = ("robot 'panda' is a fixed-base arm (torque-driven, an excitation trajectory): it takes --friction, "
       "--position-noise, --encoder-bits, --torque-noise, --noise-seed, --duration, --excitation-seed, --play")
PD = ("--actuator pd identifies a hung PD-driven robot's actuators (the URDF kept): it takes --json, --holdout, "
      "--time-unit, --config-output, --wide, --max-delay, --delay, --window, --offset-bound, --velocity, --delayed")

ISSUE_SIMULATE = [
    (("--robot", "go2", "--gait", "trot"), f"--gait: {HUNG}; not --gait"),
    (("--robot", "go2", "--foot-forces", "3d"), f"--foot-forces: {HUNG}; not --foot-forces"),
    (("--robot", "go2", "--speed", "0.3"), f"--speed: {HUNG}; not --speed"),
    (("--robot", "go2", "--simulator", "ideal"), f"--simulator: {HUNG}; not --simulator"),
    (("--robot", "go2_walking", "--lift-height", "-0.05"), f"--lift-height: {QUADRUPED}; not --lift-height"),
    (("--robot", "go2_walking", "--steps", "3"), f"--steps: {QUADRUPED}; not --steps"),
    (("--robot", "panda", "--gait", "trot"), f"--gait: {ARM}; not --gait"),
]


@pytest.mark.parametrize(("args", "line"), ISSUE_SIMULATE, ids=[" ".join(a) for a, _ in ISSUE_SIMULATE])
def test_the_issues_simulate_options_are_refused(capsys, tmp_path, args, line):
    """The issue's examples (each with a short --duration, which every one of these modes takes, so that the
    former code, which ran them, ran briefly): one line, exit 2, no log."""
    out = tmp_path / "log.parquet"
    code, err = run_cli(capsys, "simulate", *args, "--duration", "0.2", "-o", out)
    assert (code, err.strip()) == (2, f"error: {line}")
    assert not out.exists()


ISSUE_IDENTIFY = [
    (("-o", "x.urdf"), f"-o/--output: {PD}; not -o/--output"),
    (("--stride", "2"), f"--stride: {PD}; not --stride"),
    (("--armature", "identify"), f"--armature: {PD}; not --armature"),
    (("--route", "momentum"), f"--route: {PD}; not --route"),
]


@pytest.fixture(scope="module")
def hung_log(tmp_path_factory):
    """2 s of the hung Go2, noise-free, as ``simulate --robot go2`` writes it, and the same without its drivers'
    velocities (``qd.*``)."""
    from wbfriction.logs.tables import write_table
    from wbfriction.model.loading import load_robot
    from wbfriction.sim.hung import simulate_hung
    from wbfriction.sim.pd_options import HungOptions

    folder = tmp_path_factory.mktemp("hung")
    table = simulate_hung(load_robot("go2"), HungOptions(duration=2.0)).table
    write_table(table, folder / "hung.parquet")
    write_table(table.drop([c for c in table.column_names if c.startswith("qd.")]), folder / "no_qd.parquet")
    return folder


@pytest.mark.parametrize(("args", "line"), ISSUE_IDENTIFY, ids=[" ".join(a) for a, _ in ISSUE_IDENTIFY])
def test_the_issues_identify_options_are_refused(capsys, tmp_path, hung_log, args, line):
    """On a log ``--actuator pd`` identifies (the former code did, dropping the option): one line, exit 2, nothing
    written."""
    code, err = run_cli(capsys, "identify", hung_log / "hung.parquet", "--robot", "go2", "--actuator", "pd",
                        *[str(tmp_path / a) if a.endswith(".urdf") else a for a in args], "--json", tmp_path / "a.json")
    assert (code, err.strip()) == (2, f"error: {line}")
    assert list(tmp_path.iterdir()) == []


def test_a_logged_velocity_the_log_has_not_is_refused(capsys, tmp_path, hung_log):
    """``identify --actuator pd --velocity logged`` on a log without ``qd.*`` columns: refused in one line, no JSON
    (its "used: logged" was the positions' velocity); on the log with them, taken and said so."""
    log = hung_log / "no_qd.parquet"
    code, err = run_cli(capsys, "identify", log, "--robot", "go2", "--actuator", "pd", "--velocity", "logged",
                        "--json", tmp_path / "a.json")
    assert (code, err.strip()) == (2, f"error: {log}: --velocity logged needs the drivers' velocities, the columns "
                                      "qd.<joint> (none in this log): give --velocity positions or auto")
    assert not (tmp_path / "a.json").exists()
    code, err = run_cli(capsys, "identify", hung_log / "hung.parquet", "--robot", "go2", "--actuator", "pd",
                        "--velocity", "logged", "--json", tmp_path / "a.json")
    assert code == 0, err
    assert json.loads((tmp_path / "a.json").read_text())["velocity"]["used"] == "logged"


def test_a_stride_out_of_reach_names_the_speed(capsys, tmp_path):
    """``simulate --robot go2_walking --speed 5``: the error names what the command line can change (--speed), not
    fields it has no option for."""
    out = tmp_path / "fast.parquet"
    code, err = run_cli(capsys, "simulate", "--robot", "go2_walking", "--speed", "5", "--duration", "1", "-o", out)
    assert (code, err.strip()) == (2, "error: the gait puts a foot of robot 'go2_walking' out of its leg's reach at "
                                      "sample 193: lower --speed (5 m/s)")
    assert not out.exists()


# every option of the two commands with a valid value: what the tables are checked with
VALUES = {
    "gait": ["--gait", "trot"], "steps": ["--steps", "3"], "step_length": ["--step-length", "0.2"],
    "step_width": ["--step-width", "0.1"], "turn_angle": ["--turn-angle", "0.2"],
    "lift_height": ["--lift-height", "0.05"], "friction": ["--friction", "FILE"], "simulator": ["--simulator", "ideal"],
    "substeps": ["--substeps", "2"], "integrator": ["--integrator", "explicit"],
    "mujoco_friction": ["--mujoco-friction", "mujoco"], "sensors": ["--sensors", "FILE"],
    "position_noise": ["--position-noise", "1e-4"], "encoder_bits": ["--encoder-bits", "16"],
    "torque_noise": ["--torque-noise", "0.01"], "noise_seed": ["--noise-seed", "1"], "delay": ["--delay", "0.01"],
    "log_base": ["--no-log-base"], "force_torque": ["--force-torque"], "sole_timeconst": ["--sole-timeconst", "0.03"],
    "friction_timeconst": ["--friction-timeconst", "0.01"], "torque_drift": ["--torque-drift", "0.1"],
    "ft_offset": ["--ft-offset", "1", "0.1"], "duration": ["--duration", "1"],
    "excitation_seed": ["--excitation-seed", "2"], "setpoints": ["--setpoints", "chirps"],
    "driver_noise": ["--driver-noise", "none"], "velocity_noise": ["--velocity-noise", "0.01"],
    "speed": ["--speed", "0.1"], "foot_forces": ["--foot-forces", "3d"], "play": ["--play", "FILE"],
    "sensor_noise": ["--sensor-noise", "unitree"], "logger": ["--logger", "raw"],
    "logger_period": ["--logger-period", "1"], "imu_period": ["--imu-period", "4"],
    "angles": ["--angles", "cos-sin"], "kt_error": ["--kt-error", "0.02"],
    "foot_counts": ["--foot-counts"], "contacts": ["--contacts", "firm"],
    # identify's
    "output": ["-o", "OUT.urdf"], "json_output": ["--json", "OUT.json"],
    "stribeck_velocity": ["--stribeck-velocity", "0.1"],
    "passes": ["--passes", "1"], "holdout": ["--holdout", "0.3"], "stride": ["--stride", "2"],
    "prior": ["--prior", "10"], "armature": ["--armature", "identify"], "link_margin": ["--link-margin", "0.1"],
    "prior_tolerance": ["--prior-tolerance", "0.1"], "noise_target": ["--noise-target", "10"],
    "tanh_slope": ["--tanh-slope", "50"], "diff": ["--diff", "central"], "mask": ["--mask", "single"],
    "route": ["--route", "momentum"], "base_motion": ["--base-motion", "logged"], "workers": ["--workers", "1"],
    "time_unit": ["--time-unit", "ms"], "config_output": ["--config-output", "OUT.toml"], "wide": ["--wide"],
    "max_delay": ["--max-delay", "0.03"], "window": ["--window", "0.05"], "offset_bound": ["--offset-bound", "0.1"],
    "velocity": ["--velocity", "positions"], "delayed": ["--delayed", "torque"],
}
SIMULATE_MODES = {  # the mode's command line, and the values its own options take there where VALUES' do not fit
    "quadruped": (["--robot", "go2_walking"], {}),
    "hung": (["--robot", "go2"], {}),
    "arm": (["--robot", "panda"], {}),
    "ideal": (["--robot", "talos"], {"gait": ["--gait", "forward"]}),
    "mujoco": (["--robot", "talos", "--simulator", "mujoco"], {"gait": ["--gait", "forward"],
                                                               "simulator": ["--simulator", "mujoco"]}),
}
IDENTIFY_MODES = {"none": ["-o", "OUT.urdf"], "pd": ["--actuator", "pd"]}


def _options(command: str, shared: tuple[str, ...]) -> list[str]:
    return [p.name for p in COMMANDS[command].params if p.name not in shared and p.name != "ctx"]


def _argv(fragment: list[str], tmp_path) -> list[str]:
    (tmp_path / "FILE").touch()
    return [str(tmp_path / a) if a == "FILE" or a.startswith("OUT") else a for a in fragment]


class Accepted(InputError):
    """Raised where the work would start, right after the refusal: the options were accepted."""


def _sorted(capsys, command: str, argv: list[str], options: list[str], values: dict, tmp_path) -> dict[str, str]:
    """Each option alone on ``argv``: ``accepted`` or the refusal's one line."""
    found = {}
    for name in options:
        code, err = run_cli(capsys, command, *argv, *_argv(values.get(name, VALUES[name]), tmp_path))
        lines = said(err)
        assert code == 2 and len(lines) == 1, (name, err)
        found[name] = "accepted" if lines[0] == "error: accepted" else lines[0]
    return found


@pytest.fixture
def stop_after_the_refusal(monkeypatch):
    """The commands stopped where their work starts (the numbers' ranges for ``simulate``, the paths for
    ``identify``), its robots loaded once."""
    def accepted(*args, **kwargs):
        raise Accepted("accepted")

    robots: dict = {}
    robot_of = simulate_cli.robot_of
    monkeypatch.setattr(simulate_cli, "robot_of", lambda *a: robots.get(a) or robots.setdefault(a, robot_of(*a)))
    monkeypatch.setattr(rigs_cli, "read_options", accepted)
    monkeypatch.setattr(identify_cli, "check_paths", accepted)
    monkeypatch.setattr(actuator_cli, "check_paths", accepted)


@pytest.mark.parametrize("mode", list(SIMULATE_MODES))
def test_simulate_takes_its_modes_options_and_refuses_the_others(capsys, tmp_path, stop_after_the_refusal, mode):
    argv, values = SIMULATE_MODES[mode]
    argv = [*argv, "-o", str(tmp_path / "log.parquet")]
    found = _sorted(capsys, "simulate", argv, _options("simulate", simulate_cli.SHARED), values, tmp_path)
    takes = simulator_options()[mode]
    wrong = {name: line for name, line in found.items() if (line == "accepted") != (name in takes)}
    assert not wrong, wrong
    for name, line in found.items():
        flag = option_flag(next(p for p in COMMANDS["simulate"].params if p.name == name))
        assert line == "accepted" or (line.startswith(f"error: {flag}: robot '{argv[1]}' ")
                                      and line.endswith(f"; not {flag}")), line
    assert not (tmp_path / "log.parquet").exists()


@pytest.mark.parametrize("mode", list(IDENTIFY_MODES))
def test_identify_takes_its_modes_options_and_refuses_the_others(capsys, tmp_path, stop_after_the_refusal, mode):
    argv = ["LOG", "--robot", "go2", *_argv(IDENTIFY_MODES[mode], tmp_path)]
    found = _sorted(capsys, "identify", argv, _options("identify", identify_cli.SHARED), {}, tmp_path)
    what, takes = identify_cli.MODES[mode]  # type: ignore[index]
    wrong = {name: line for name, line in found.items() if (line == "accepted") != (name in takes)}
    assert not wrong, wrong
    assert all(line == "accepted" or f": {what}: it takes " in line for line in found.values())


@pytest.mark.parametrize(("command", "shared", "tables"), [
    ("simulate", simulate_cli.SHARED, list(simulator_options().values())),
    ("identify", identify_cli.SHARED, [takes for _, takes in identify_cli.MODES.values()])])
def test_the_tables_name_the_commands_options(command, shared, tables):
    """Every name in a mode's table is an option of the command, and every option is read by some mode (none
    ignored by all); the test's values cover them all."""
    options = set(_options(command, ()))
    named = set(shared).union(*tables)
    assert named <= options, named - options
    assert options <= named, options - named
    assert set(_options(command, shared)) <= set(VALUES)


ESTIMATE_CONTACT_VALUES = {"mask": "single", "lift_off": "0.1", "touch_down": "0.1", "ds_weight": "2",
                           "ds_regularization": "0.1", "base_motion": "logged", "wrenches": None}


@pytest.mark.parametrize("name", list(ESTIMATE_CONTACT_VALUES))
def test_estimate_on_a_fixed_base_refuses_the_contacts_options(capsys, tmp_path, name):
    """A fixed-base robot's estimate reads no contact switch, double support or base motion: each of those options,
    given, is one line naming it and what the robot is, exit 2, before the log is read, nothing written."""
    from wbfriction.cli.estimate import CONTACT_OPTIONS

    assert set(ESTIMATE_CONTACT_VALUES) == set(CONTACT_OPTIONS)
    param = next(p for p in COMMANDS["estimate"].params if p.name == name)
    value = ESTIMATE_CONTACT_VALUES[name]
    given = [param.opts[0]] if value is None else [param.opts[0], value]
    log = tmp_path / "log.parquet"
    log.write_bytes(b"not read")
    code, err = run_cli(capsys, "estimate", log, "--robot", "panda", *given, "-o", tmp_path / "f.parquet")
    assert code == 2 and len(said(err)) == 1, err
    message = f"error: {option_flag(param)}: robot 'panda' has a fixed base: it takes no contact or base option"
    assert err.strip() == message and len(message) <= 100, err
    assert not (tmp_path / "f.parquet").exists()
