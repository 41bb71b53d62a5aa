"""Simulators that write logs in the project's format: the ideal one (thesis 6.1), the realistic one on
MuJoCo (thesis 6.2), and sensor models."""

from .control import feedforward, pd_gains
from .common import Pull, SimulationResult
from .ideal import INTEGRATORS, IdealOptions, simulate_ideal
from .mujoco_sim import MujocoOptions, simulate_mujoco
from .sensors import SensorNoise, apply_sensor_noise

__all__ = ["feedforward", "pd_gains", "INTEGRATORS", "IdealOptions", "Pull", "SimulationResult", "simulate_ideal",
           "MujocoOptions", "simulate_mujoco", "SensorNoise", "apply_sensor_noise"]
