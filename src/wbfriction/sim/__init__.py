"""Simulators that write logs in the project's format: the ideal one (thesis 6.1), the realistic one on
MuJoCo (thesis 6.2), a fixed-base arm tracking an excitation trajectory (:mod:`.arm`), and sensor models."""

from wbfriction.sim.arm import ArmOptions, ExcitationOptions, simulate_arm
from wbfriction.sim.common import Pull, SimulationResult
from wbfriction.sim.control import feedforward, pd_gains
from wbfriction.sim.ideal import INTEGRATORS, IdealOptions, simulate_ideal
from wbfriction.sim.mujoco_sim import MujocoOptions, simulate_mujoco
from wbfriction.sim.sensors import SensorNoise, apply_sensor_noise

__all__ = ["feedforward", "pd_gains", "INTEGRATORS", "IdealOptions", "Pull", "SimulationResult", "simulate_ideal",
           "MujocoOptions", "simulate_mujoco", "SensorNoise", "apply_sensor_noise",
           "ArmOptions", "ExcitationOptions", "simulate_arm"]
