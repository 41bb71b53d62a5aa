"""The inertia model: identified together with the friction from the logs' torques (thesis 2.4, ch. 8;
:mod:`.regressor`, :mod:`.least_squares`, :mod:`.consistency`, :mod:`.identification`), the loop
that re-estimates the friction with it (:mod:`.closed_loop`), the sensitivity of the estimate to
inertia errors (:mod:`.sensitivity`, 7.2), the corrected URDF (:mod:`.urdf`) and the
identification JSON (:mod:`.io`); the identified limbs kept only where held-out torques are
predicted better (:mod:`.validation`); solvers' stopping messages in words (:mod:`.solver`)."""

from wbfriction.inertia.closed_loop import ClosedLoop, identify
from wbfriction.inertia.identification import InertialIdentification, InertialOptions, identify_inertia
from wbfriction.inertia.io import read_identification
from wbfriction.inertia.sensitivity import inertia_sensitivity, scaled_robot
from wbfriction.inertia.urdf import write_urdf

__all__ = ["ClosedLoop", "InertialIdentification", "InertialOptions", "identify", "identify_inertia",
           "inertia_sensitivity", "read_identification", "scaled_robot", "write_urdf"]
