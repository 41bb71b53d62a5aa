"""Names of :mod:`wbfriction.walking`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .footsteps import FootstepPlan as FootstepPlan
from .footsteps import Step as Step
from .footsteps import plan_footsteps as plan_footsteps
from .options import GAITS as GAITS
from .options import GaitOptions as GaitOptions
from .reference import WalkingReference as WalkingReference
from .reference import standing_configuration as standing_configuration
from .reference import walking_reference as walking_reference
