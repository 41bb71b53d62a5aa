"""Names of :mod:`wbfriction.actuator`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .identification import ActuatorIdentification as ActuatorIdentification
from .identification import Identified as Identified
from .identification import JointActuator as JointActuator
from .identification import identify_actuators as identify_actuators
from .options import ActuatorOptions as ActuatorOptions
