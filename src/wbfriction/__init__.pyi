"""Names of :mod:`wbfriction`, imported on first use (:func:`lazy_loader.attach_stub`), so that
``import wbfriction`` (and the command's entry point, :mod:`wbfriction.entry`) loads no NumPy, Pinocchio or
SciPy."""

from .exceptions import ClusterError as ClusterError
from .exceptions import ColumnError as ColumnError
from .exceptions import InputError as InputError
from .exceptions import ModelError as ModelError
from .exceptions import OptionError as OptionError
from .exceptions import OutputError as OutputError
from .exceptions import SimulationError as SimulationError
from .exceptions import WbfrictionError as WbfrictionError
from .fit.joints import fit_estimate as fit_estimate
from .fit.joints import fit_joints as fit_joints
from .fit.options import FitOptions as FitOptions
from .fit.params_file import read_params as read_params
from .fit.params_file import write_params as write_params
from .fit.result import FitResult as FitResult
from .fit.selection import fit_friction as fit_friction
from .fit.status import FitVerdict as FitVerdict
from .friction.estimate import FrictionEstimate as FrictionEstimate
from .friction.estimate import estimate_friction as estimate_friction
from .friction.estimate import estimate_log as estimate_log
from .friction.io import friction_table as friction_table
from .friction.io import read_friction_file as read_friction_file
from .friction.models import FrictionParams as FrictionParams
from .friction.options import EstimateOptions as EstimateOptions
from .logs.log import Log as Log
from .logs.log import write_log as write_log
from .logs.source import open_log as open_log
from .logs.source import read_log as read_log
from .model.loading import load_robot as load_robot
from .model.robot import Robot as Robot
from .signals.kinematics import MeasuredKinematics as MeasuredKinematics
from .signals.kinematics import measure as measure
from .signals.options import FilterOptions as FilterOptions
from .sim.ideal import simulate_ideal as simulate_ideal
from .sim.mujoco_sim import simulate_mujoco as simulate_mujoco
from .sim.options import IdealOptions as IdealOptions
from .sim.options import MujocoOptions as MujocoOptions
from .version import __version__ as __version__
from .walking.options import GaitOptions as GaitOptions
from .walking.reference import walking_reference as walking_reference
