"""wbfriction: whole-body joint friction estimation for torque-controlled legged robots.

Data flow: log (:mod:`~wbfriction.log`) -> measured kinematics
(:mod:`~wbfriction.kinematics`, zero-phase filters in :mod:`~wbfriction.filters`) -> constrained dynamics (:mod:`~wbfriction.dynamics`,
:mod:`~wbfriction.stance`) -> friction estimate (:mod:`~wbfriction.estimate`) ->
identification (:mod:`~wbfriction.identify`). Beside it, :mod:`~wbfriction.walking`
plans walks and :mod:`~wbfriction.sim` simulates them, writing logs in the same format;
:mod:`~wbfriction.study` runs the thesis's simulation study (chapter 6) and
:mod:`~wbfriction.filter_study` its filter study (chapter 7).

Sign convention: ``tau_f`` is the torque friction exerts on the joint,
``M qdd + h = S^T (tau + tau_f) + J^T lambda``; the model ``f(qd)`` of thesis eq. (3.5) is
fitted to ``-tau_f``.
"""

__version__ = "0.1.0"

from .estimate import EstimateOptions, FrictionEstimate, estimate_friction, estimate_log  # noqa: E402
from .exceptions import InputError, ModelError, WbfrictionError  # noqa: E402
from .friction import FrictionParams  # noqa: E402
from .identify import FitResult, fit_estimate, fit_friction  # noqa: E402
from .kinematics import FilterOptions, MeasuredKinematics, measure  # noqa: E402
from .log import Log, read_log, write_log  # noqa: E402
from .robot import Robot, load_robot  # noqa: E402

__all__ = [
    "EstimateOptions", "FilterOptions", "FitResult", "FrictionEstimate", "FrictionParams", "InputError",
    "Log", "MeasuredKinematics", "ModelError", "Robot", "WbfrictionError", "estimate_friction", "estimate_log",
    "fit_estimate", "fit_friction", "load_robot", "measure", "read_log", "write_log",
]
