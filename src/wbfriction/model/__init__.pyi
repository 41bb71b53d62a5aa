"""Names of :mod:`wbfriction.model`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .contacts import ContactModel as ContactModel
from .contacts import contact_model_of as contact_model_of
from .contacts import contact_models as contact_models
from .contacts import register_contact_model as register_contact_model
from .contacts import unregister_contact_model as unregister_contact_model
from .dynamics import ConstrainedDynamics as ConstrainedDynamics
from .dynamics import constrained_dynamics as constrained_dynamics
from .layout import JointLayout as JointLayout
from .loading import RobotSpec as RobotSpec
from .loading import build_robot as build_robot
from .loading import load_robot as load_robot
from .rerooted import StanceModel as StanceModel
from .rerooted import stance_frame_pose as stance_frame_pose
from .rerooted import stance_model as stance_model
from .robot import Robot as Robot
from .robots import BUILTIN_ROBOTS as BUILTIN_ROBOTS
