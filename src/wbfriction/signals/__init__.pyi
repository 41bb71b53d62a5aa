"""Names of :mod:`wbfriction.signals`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .contact_inference import ContactOptions as ContactOptions
from .contact_inference import InferredContacts as InferredContacts
from .contact_inference import infer_contacts as infer_contacts
from .kinematics import MeasuredKinematics as MeasuredKinematics
from .kinematics import measure as measure
from .options import FilterOptions as FilterOptions
from .phases import Phases as Phases
from .phases import joint_mask as joint_mask
from .phases import segment as segment
from .spectrum import AccelerationSpectrum as AccelerationSpectrum
from .spectrum import acceleration_spectrum as acceleration_spectrum
