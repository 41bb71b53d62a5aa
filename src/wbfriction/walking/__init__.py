"""Walking reference for a biped: footsteps, ZMP and LIPM centre of mass, swing feet, whole-body IK."""

from wbfriction.walking.footsteps import GAITS, FootstepPlan, GaitOptions, Step, plan_footsteps
from wbfriction.walking.reference import WalkingReference, standing_configuration, walking_reference

__all__ = ["GAITS", "FootstepPlan", "GaitOptions", "Step", "plan_footsteps", "WalkingReference",
           "standing_configuration", "walking_reference"]
