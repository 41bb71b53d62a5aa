"""The robot: a URDF with a free-flyer root, its joint roles and contact frames (:mod:`.robot`,
:mod:`.loading`), the trees re-rooted at a stance sole (:mod:`.stance`), the constrained
floating-base dynamics (:mod:`.dynamics`, thesis 4.4-5.12), and the built-in robots (``robots/``)."""

from wbfriction.model.dynamics import ConstrainedDynamics, constrained_dynamics
from wbfriction.model.layout import JointLayout
from wbfriction.model.loading import BUILTIN_ROBOTS, build_robot, load_robot
from wbfriction.model.robot import Robot
from wbfriction.model.stance import StanceModel, stance_frame_pose, stance_model

__all__ = ["BUILTIN_ROBOTS", "ConstrainedDynamics", "JointLayout", "Robot", "StanceModel", "build_robot",
           "constrained_dynamics", "load_robot", "stance_frame_pose", "stance_model"]
