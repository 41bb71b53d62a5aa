"""Fixtures of the arm's identification tests: the Panda (its built-in configuration), its friction,
and logs of the arm simulator (1 kHz, 19-bit encoders, motor currents with noise)."""

from __future__ import annotations

from importlib import resources

import pytest

from wbfriction.friction.models import FrictionParams
from wbfriction.logs.log import Log, log_from_table
from wbfriction.model.loading import example_robot_data_dir, load_robot
from wbfriction.model.robot import Robot
from wbfriction.model.robots import BUILTIN_ROBOTS
from wbfriction.sim.arm import ArmOptions, ExcitationOptions, simulate_arm


@pytest.fixture(scope="session")
def panda() -> Robot:
    """The built-in Panda: its armature (the TOML's) is the one the simulator injects by default."""
    if "panda" in BUILTIN_ROBOTS:
        return load_robot("panda")
    config = resources.files("wbfriction.model.robots").joinpath("panda.toml")
    return load_robot(urdf=example_robot_data_dir() / "panda_description/urdf/panda.urdf", config=str(config))


@pytest.fixture(scope="session")
def panda_friction(panda) -> dict[str, FrictionParams]:
    """Friction (3.5) with a Stribeck term on every joint, larger on the proximal ones."""
    return {j: FrictionParams(F_v=0.5 - 0.05 * i, F_c=1.0 - 0.1 * i, S=0.3, v_s=0.05, tau_os=0.1,
                              a=40.0) for i, j in enumerate(panda.actuated)}


def _log(robot: Robot, friction, duration: float, excited: tuple[str, ...] | None = None) -> Log:
    options = ArmOptions(duration=duration, torque_std=0.05, excitation=ExcitationOptions(period=duration,
                                                                                          excited=excited))
    return log_from_table(simulate_arm(robot, friction, options=options).table, robot, "panda-sim")


@pytest.fixture(scope="session")
def panda_log(panda, panda_friction) -> Log:
    """8 s of every joint excited."""
    return _log(panda, panda_friction, 8.0)


@pytest.fixture(scope="session")
def panda_still_wrist_log(panda, panda_friction) -> Log:
    """6 s of the first four joints excited, the wrist (joints 5 to 7) held still."""
    return _log(panda, panda_friction, 6.0, panda.actuated[:4])
