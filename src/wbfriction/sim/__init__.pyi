"""Names of :mod:`wbfriction.sim`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .arm import ArmOptions as ArmOptions
from .arm import ExcitationOptions as ExcitationOptions
from .arm import simulate_arm as simulate_arm
from .common import Pull as Pull
from .common import SimulationResult as SimulationResult
from .control import feedforward as feedforward
from .control import pd_gains as pd_gains
from .hung import HungSimulation as HungSimulation
from .hung import simulate_hung as simulate_hung
from .ideal import simulate_ideal as simulate_ideal
from .mujoco_sim import simulate_mujoco as simulate_mujoco
from .options import INTEGRATORS as INTEGRATORS
from .options import IdealOptions as IdealOptions
from .options import MujocoOptions as MujocoOptions
from .options import SensorNoise as SensorNoise
from .pd_options import REAL_DRIVER as REAL_DRIVER
from .pd_options import DriverNoise as DriverNoise
from .pd_options import HungOptions as HungOptions
from .pd_options import SetpointOptions as SetpointOptions
from .pd_robot import PdMujocoRobot as PdMujocoRobot
from .pd_robot import build_pd_robot as build_pd_robot
from .sensors import apply_sensor_noise as apply_sensor_noise
