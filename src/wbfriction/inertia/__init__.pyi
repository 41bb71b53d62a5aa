"""Names of :mod:`wbfriction.inertia`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .closed_loop import ClosedLoop as ClosedLoop
from .closed_loop import identify as identify
from .document import Identification as Identification
from .identification import InertialIdentification as InertialIdentification
from .identification import identify_inertia as identify_inertia
from .io import identification_of as identification_of
from .io import read_identification as read_identification
from .options import InertialOptions as InertialOptions
from .sensitivity import inertia_sensitivity as inertia_sensitivity
from .sensitivity import scaled_robot as scaled_robot
from .urdf import write_urdf as write_urdf
