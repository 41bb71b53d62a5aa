"""Friction: the models (:mod:`.models`, thesis 3.1-3.5) and their parameters per joint
(:mod:`.targets`), the estimate from measured kinematics (:mod:`.estimate`, 5.10-5.13, 6.1),
the fit of model (3.5) with standard errors (:mod:`.fit`, 6.4), the energy check
(:mod:`.energy`, 7.9), and the friction table and parameters JSON (:mod:`.io`)."""

from wbfriction.friction.energy import JointEnergy, energy_consistency
from wbfriction.friction.estimate import EstimateOptions, FrictionEstimate, estimate_friction, estimate_log
from wbfriction.friction.fit import FitResult, fit_estimate, fit_friction, fit_joints
from wbfriction.friction.io import friction_table, read_friction_file, read_friction_table, read_params, write_params
from wbfriction.friction.models import PARAM_NAMES, FrictionParams, coulomb_viscous_stribeck

__all__ = ["PARAM_NAMES", "EstimateOptions", "FitResult", "FrictionEstimate", "FrictionParams", "JointEnergy",
           "coulomb_viscous_stribeck", "energy_consistency", "estimate_friction", "estimate_log", "fit_estimate",
           "fit_friction", "fit_joints", "friction_table", "read_friction_file", "read_friction_table",
           "read_params", "write_params"]
