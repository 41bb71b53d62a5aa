"""Names of :mod:`wbfriction.fit`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .energy import JointEnergy as JointEnergy
from .energy import energy_consistency as energy_consistency
from .joints import fit_estimate as fit_estimate
from .joints import fit_joints as fit_joints
from .options import FitOptions as FitOptions
from .options import TermOptions as TermOptions
from .params_file import read_params as read_params
from .params_file import write_params as write_params
from .result import FitResult as FitResult
from .selection import fit_friction as fit_friction
from .status import FitVerdict as FitVerdict
