"""Names of :mod:`wbfriction.friction`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .estimate import estimate_friction as estimate_friction
from .estimate import estimate_log as estimate_log
from .estimated import FrictionEstimate as FrictionEstimate
from .io import friction_table as friction_table
from .io import read_friction_file as read_friction_file
from .io import read_friction_table as read_friction_table
from .models import PARAM_NAMES as PARAM_NAMES
from .models import FrictionParams as FrictionParams
from .models import coulomb_viscous_stribeck as coulomb_viscous_stribeck
from .momentum import momentum_estimate as momentum_estimate
from .options import EstimateOptions as EstimateOptions
from .options import MomentumOptions as MomentumOptions
from .route import RouteDecision as RouteDecision
from .route import resolve_route as resolve_route
