"""wbfriction: whole-body joint friction estimation for torque-controlled legged robots.

The package follows the data flow, one subpackage per stage, each importing only those before it:

* :mod:`wbfriction.model`: the robot (URDF, joint roles, contact frames), its stance-rooted
  trees and constrained dynamics;
* :mod:`wbfriction.logs`: logs as files (Parquet, CSV, HDF5, ROS 2 bags), validated;
* :mod:`wbfriction.signals`: log -> signals: differentiation, zero-phase filters, support phases, spectra;
* :mod:`wbfriction.friction`: the friction models (thesis ch. 3), the estimate (5.10-5.13, 6.1),
  the fit (6.4), the energy check (7.9) and their documents;
* :mod:`wbfriction.inertia`: the inertia model identified from the same logs, sensitivity, URDF writing;
* :mod:`wbfriction.pipeline`: files in, files out (long logs in chunks, provenance);
* :mod:`wbfriction.report`: figures and the HTML report.

Beside them, :mod:`wbfriction.walking` plans walks and :mod:`wbfriction.sim` simulates them,
writing logs in the same format; :mod:`wbfriction.studies` reproduces the thesis's studies;
:mod:`wbfriction.cli` is the command line.

Sign convention: ``tau_f`` is the torque friction exerts on the joint,
``M qdd + h = S^T (tau + tau_f) + J^T lambda``; the model ``f(qd)`` of thesis eq. (3.5) is
fitted to ``-tau_f``.
"""

from importlib import import_module
from typing import TYPE_CHECKING

from wbfriction.version import __version__

if TYPE_CHECKING:
    from wbfriction.exceptions import ColumnError, InputError, ModelError, SimulationError, WbfrictionError
    from wbfriction.friction.estimate import EstimateOptions, FrictionEstimate, estimate_friction, estimate_log
    from wbfriction.friction.fit import FitResult, fit_estimate, fit_friction, fit_joints
    from wbfriction.friction.io import friction_table, read_friction_file, read_params, write_params
    from wbfriction.friction.models import FrictionParams
    from wbfriction.friction.status import FitVerdict
    from wbfriction.logs.log import Log, write_log
    from wbfriction.logs.source import open_log, read_log
    from wbfriction.model.loading import load_robot
    from wbfriction.model.robot import Robot
    from wbfriction.signals.kinematics import FilterOptions, MeasuredKinematics, measure
    from wbfriction.sim.ideal import IdealOptions, simulate_ideal
    from wbfriction.sim.mujoco_sim import MujocoOptions, simulate_mujoco
    from wbfriction.walking.footsteps import GaitOptions
    from wbfriction.walking.reference import walking_reference

__all__ = [
    "ColumnError", "EstimateOptions", "FilterOptions", "FitResult", "FitVerdict", "FrictionEstimate",
    "FrictionParams", "GaitOptions", "IdealOptions", "InputError", "Log", "MeasuredKinematics", "ModelError",
    "MujocoOptions", "Robot", "SimulationError", "WbfrictionError", "__version__", "estimate_friction",
    "estimate_log", "fit_estimate", "fit_friction", "fit_joints", "friction_table", "load_robot", "measure",
    "open_log", "read_friction_file", "read_log", "read_params", "simulate_ideal", "simulate_mujoco",
    "walking_reference", "write_log", "write_params",
]


_HOMES = {
    **dict.fromkeys(("ColumnError", "InputError", "ModelError", "SimulationError", "WbfrictionError"),
                    "wbfriction.exceptions"),
    **dict.fromkeys(("EstimateOptions", "FrictionEstimate", "estimate_friction", "estimate_log"),
                    "wbfriction.friction.estimate"),
    **dict.fromkeys(("FitResult", "fit_estimate", "fit_friction", "fit_joints"), "wbfriction.friction.fit"),
    **dict.fromkeys(("friction_table", "read_friction_file", "read_params", "write_params"), "wbfriction.friction.io"),
    "FrictionParams": "wbfriction.friction.models",
    **dict.fromkeys(("Log", "write_log"), "wbfriction.logs.log"),
    **dict.fromkeys(("open_log", "read_log"), "wbfriction.logs.source"),
    "load_robot": "wbfriction.model.loading",
    "Robot": "wbfriction.model.robot",
    **dict.fromkeys(("FilterOptions", "MeasuredKinematics", "measure"), "wbfriction.signals.kinematics"),
    "FitVerdict": "wbfriction.friction.status",
    **dict.fromkeys(("IdealOptions", "simulate_ideal"), "wbfriction.sim.ideal"),
    **dict.fromkeys(("MujocoOptions", "simulate_mujoco"), "wbfriction.sim.mujoco_sim"),
    "GaitOptions": "wbfriction.walking.footsteps",
    "walking_reference": "wbfriction.walking.reference",
}
"""Where each public name lives: imported on first use (PEP 562), so that ``import wbfriction``
(and the command's entry point, :mod:`wbfriction.entry`) loads no NumPy, Pinocchio or SciPy."""


def __getattr__(name: str) -> object:
    if name not in _HOMES:
        raise AttributeError(f"module 'wbfriction' has no attribute {name!r}")
    value = getattr(import_module(_HOMES[name]), name)
    globals()[name] = value
    return value
