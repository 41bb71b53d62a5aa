"""Log -> signals: measured velocities and accelerations (:mod:`.kinematics`, thesis 6.1.2), the
zero-phase filters (:mod:`.filters`, 7.1), support phases and masks (:mod:`.phases`, 5.3, 6.2.1),
and spectra (:mod:`.spectrum`, Fig. 7.1)."""

from wbfriction.signals.kinematics import FilterOptions, MeasuredKinematics, measure
from wbfriction.signals.phases import Phases, joint_mask, segment
from wbfriction.signals.spectrum import AccelerationSpectrum, acceleration_spectrum

__all__ = ["AccelerationSpectrum", "FilterOptions", "MeasuredKinematics", "Phases", "acceleration_spectrum",
           "joint_mask", "measure", "segment"]
