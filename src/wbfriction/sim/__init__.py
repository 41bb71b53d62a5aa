"""Simulators that write logs in the project's format: the ideal one (thesis 6.1)."""

from .control import feedforward, pd_gains
from .ideal import INTEGRATORS, IdealOptions, Pull, SimulationResult, simulate_ideal

__all__ = ["feedforward", "pd_gains", "INTEGRATORS", "IdealOptions", "Pull", "SimulationResult", "simulate_ideal"]
