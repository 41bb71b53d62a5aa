"""PD-driven actuators identified from their logs: armature, friction, encoder offsets and the drivers' delay, each
with its standard error, Cramér-Rao bound and status (issue 55; :mod:`wbfriction.actuator.identification`)."""

from wbfriction.actuator.identification import (
    ActuatorIdentification,
    Identified,
    JointActuator,
    identify_actuators,
)
from wbfriction.actuator.options import ActuatorOptions

__all__ = ["ActuatorIdentification", "ActuatorOptions", "Identified", "JointActuator", "identify_actuators"]
