"""What a motion will let the identification report, before the robot moves: each parameter's standard error and
status, predicted by the identification itself on the motion simulated under the prior.

A standard error a PD-driven robot's identification reports (:func:`~wbfriction.actuator.identify_actuators`) is
never below its Cramér-Rao bound, and holds what the sensors' noise leaves and what the model does not hold (the
sandwich on the balance's residual, the Coulomb nuisance's slope, the delay's form). The two parts are predicted
apart, each by the identification's own code:

* the **model error**: the identification of the motion simulated without sensor noise (the robot's drivers, its
  delay and friction as the prior has them), under the delay's form the noisy run finds (on data without noise the
  form's test has no noise to weigh the two forms' difference against): what it reports there is the model error
  alone;
* the **noise**: the Cramér-Rao bound of the same identification on the motion simulated with the drivers' noise
  (:class:`~wbfriction.sim.pd_options.DriverNoise`);

and the prediction is their sum in quadrature. On a hung Go2 (30 s of chirps, ramps, or both; a real driver's noise;
two seeds), the standard errors reported were within 1.5 times the prediction for 276 of 288 parameters (median
ratio 0.98-1.02); those off were far below their status's limit.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from wbfriction.actuator.identification import (
    STRUCTURE_SPREAD,
    ActuatorIdentification,
    Identified,
    identify_actuators,
    parameter_status,
)
from wbfriction.actuator.options import ActuatorOptions
from wbfriction.friction.models import ModelParams
from wbfriction.logs.log import log_from_table
from wbfriction.model.robot import Robot
from wbfriction.sim.hung import HungSimulation, simulate_hung
from wbfriction.sim.pd_options import DriverNoise, HungOptions


@dataclass(frozen=True)
class Predicted:
    """One parameter's prediction.

    Attributes:
        value: the prior's (what the noise-free identification finds).
        model_error: the standard error the noise-free identification reports [the parameter's unit].
        bound: its Cramér-Rao bound with the drivers' noise.
        se: ``hypot(model_error, bound)``: what the identification is predicted to report.
        status, reason: the predicted verdict (:func:`_predicted`).
    """

    value: float
    model_error: float
    bound: float
    se: float
    status: str
    reason: str


@dataclass(frozen=True)
class ActuatorPrediction:
    """What the identification of a PD-driven robot's motion is predicted to report.

    Attributes:
        joints: per joint, each parameter's :class:`Predicted` (``armature``, ``F_v``, ``F_c``, ``offset``).
        delay: the drivers' delay's.
        delayed_known: whether the identification is predicted to tell what the delay holds back (the set-points
            or the whole torque; :attr:`~wbfriction.actuator.identification.ActuatorIdentification.delayed_known`).
        motion: the motion simulated without noise (its set-points, angles and the drivers' torque: what the
            motion asks of the robot).
    """

    joints: dict[str, dict[str, Predicted]]
    delay: Predicted
    delayed_known: bool = True
    motion: HungSimulation | None = field(default=None, repr=False, compare=False)

    def worst(self, limits: Mapping[str, float], weak: float) -> tuple[str, str, float]:
        """The parameter predicted worst (:func:`worst_share`)."""
        return worst_share(self.joints, limits, weak)


def worst_share(joints: Mapping[str, Mapping[str, Any]], limits: Mapping[str, float], weak: float
                ) -> tuple[str, str, float]:
    """The parameter whose standard error (``.se``, of a :class:`Predicted` or of what the identification reports)
    comes to the largest share of its status's limit: ``limits[name]`` [its unit] where given (an offset's), else
    ``weak`` times its value (inf where that is 0); (joint, name, share)."""
    def share(name: str, p: Any) -> float:
        limit = limits[name] if name in limits else weak * abs(p.value)
        return float(p.se / limit) if limit > 0 else np.inf

    shares = [(j, n, share(n, p)) for j, params in joints.items() for n, p in params.items()]
    if not shares:
        raise ValueError("no parameter to share out")
    return max(shares, key=lambda x: x[2])


def predict_pd(robot: Robot, options: HungOptions, friction: Mapping[str, ModelParams] | None = None,
               reference: tuple[np.ndarray, np.ndarray] | None = None,
               identification: ActuatorOptions = ActuatorOptions(),
               motion: HungSimulation | None = None) -> ActuatorPrediction:
    """:class:`ActuatorPrediction` (module docstring) for the hung PD-driven ``robot``'s motion: ``options``'
    set-points, or ``reference`` (:func:`~wbfriction.sim.hung.simulate_hung`), its drivers' noise
    :attr:`HungOptions.noise`, the ``friction`` prior (None: the simulator's default); ``motion``: the same motion
    simulated without noise already (None: simulated here).

    Raises:
        InputError: what :func:`~wbfriction.sim.hung.simulate_hung` and the identification raise (a
            :class:`~wbfriction.exceptions.ColumnError`: the log's checks refuse a simulated log).
    """
    def simulated(noise: DriverNoise) -> HungSimulation:
        return simulate_hung(robot, dataclasses.replace(options, noise=noise), friction, reference=reference)

    def identified(sim: HungSimulation, held: ActuatorOptions) -> ActuatorIdentification:
        return identify_actuators(robot, log_from_table(sim.table, robot, "excite"), held)

    noisy = identified(simulated(options.noise), identification)
    motion = simulated(DriverNoise()) if motion is None else motion
    clean = identified(motion, dataclasses.replace(identification, delayed=noisy.options.delayed))
    joints = {}
    for jc, jn in zip(clean.joints, noisy.joints):
        theirs = jn.parameters()
        joints[jc.joint] = {name: _predicted(name, c, theirs[name], spread=not noisy.delayed_known
                                             and name in STRUCTURE_SPREAD) for name, c in jc.parameters().items()}
    return ActuatorPrediction(joints, _predicted("delay", clean.delay, noisy.delay, spread=False),
                              noisy.delayed_known, motion)


def _predicted(kind: str, clean: Identified, noisy: Identified, spread: bool) -> Predicted:
    """What the identification is predicted to report of one parameter: the model error (``clean``'s standard error)
    and the noise's bound (``noisy``'s) in quadrature; where the log does not tell the delay's form (``spread``), no
    less than the noisy run's, which carries the distance between the two forms' values (:func:`~wbfriction.actuator.
    identification.structure_widened`). Its status: the noisy run's where the motion leaves it undetermined or at a
    bound, else the rule's (:func:`~wbfriction.actuator.identification.parameter_status`) on the prediction."""
    model_error = float(clean.se) if np.isfinite(clean.se) else np.inf
    bound = float(noisy.crb)
    se = float(np.hypot(model_error, bound))
    if spread:
        se = max(se, float(noisy.se))
    status: str = noisy.status
    reason = noisy.reason
    if status not in ("not excited", "at bound"):
        status, reason = parameter_status(kind, float(clean.value), se, bound, False)
    return Predicted(float(clean.value), model_error, bound, se, status, reason)
