"""What a motion will let the identification report, before the robot moves: each parameter's standard error and
status, predicted by the identification itself on the motion simulated under the prior.

A standard error a PD-driven robot's identification reports (:func:`~wbfriction.actuator.identify_actuators`) is
never below its Cramér-Rao bound, and holds what the sensors' noise leaves and what the model does not hold (the
sandwich on the balance's residual, the Coulomb nuisance's slope, the delay's form). The two parts are predicted
apart, each by the identification's own code:

* the **model error**: the identification of the motion simulated without sensor noise (the robot's drivers, its
  delay and friction as the prior has them): what it reports there is the model error alone;
* the **noise**: the Cramér-Rao bound of the same identification on the motion simulated with the drivers' noise
  (:class:`~wbfriction.sim.pd_options.DriverNoise`);

and the prediction is their sum in quadrature. On a hung Go2 (30 s of chirps, ramps, or both; a real driver's noise;
two seeds), the standard errors reported were within 1.5 times the prediction for 276 of 288 parameters (median
ratio 0.98-1.02); those off were far below their status's limit.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from wbfriction.actuator.identification import ActuatorIdentification, identify_actuators
from wbfriction.actuator.options import ActuatorOptions
from wbfriction.friction.models import ModelParams
from wbfriction.logs.log import log_from_table
from wbfriction.model.robot import Robot
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.pd_options import DriverNoise, HungOptions


@dataclass(frozen=True)
class Predicted:
    """One parameter's prediction.

    Attributes:
        value: the prior's (what the noise-free identification finds).
        model_error: the standard error the noise-free identification reports [the parameter's unit].
        bound: its Cramér-Rao bound with the drivers' noise.
        se: ``hypot(model_error, bound)``: what the identification is predicted to report.
        status, reason: the noise-free identification's verdict (a delay's form it cannot tell, a joint it does
            not excite: the motion's, whatever the noise).
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
    """

    joints: dict[str, dict[str, Predicted]]
    delay: Predicted

    def worst(self, limits: Mapping[str, float], weak: float) -> tuple[str, str, float]:
        """The parameter whose predicted standard error comes to the largest share of its status's limit:
        ``limits[name]`` [its unit] where given (an offset's), else ``weak`` times its value; (joint, name,
        share)."""
        shares = [(j, n, p.se / (limits[n] if n in limits else weak * abs(p.value)))
                  for j, params in self.joints.items() for n, p in params.items()]
        return max(shares, key=lambda x: x[2])


def predict_pd(robot: Robot, options: HungOptions, friction: Mapping[str, ModelParams] | None = None,
               reference: tuple[np.ndarray, np.ndarray] | None = None,
               identification: ActuatorOptions = ActuatorOptions()) -> ActuatorPrediction:
    """:class:`ActuatorPrediction` (module docstring) for the hung PD-driven ``robot``'s motion: ``options``'
    set-points, or ``reference`` (:func:`~wbfriction.sim.hung.simulate_hung`), its drivers' noise
    :attr:`HungOptions.noise`, the ``friction`` prior (None: the simulator's default).

    Raises:
        InputError: what :func:`~wbfriction.sim.hung.simulate_hung` and the identification raise.
    """
    def identified(noise: DriverNoise) -> ActuatorIdentification:
        sim = simulate_hung(robot, dataclasses.replace(options, noise=noise), friction, reference=reference)
        return identify_actuators(robot, log_from_table(sim.table, robot, "excite"), identification)

    clean, noisy = identified(DriverNoise()), identified(options.noise)
    joints = {}
    for jc, jn in zip(clean.joints, noisy.joints):
        noisy_params = jn.parameters()
        joints[jc.joint] = {name: _predicted(c, noisy_params[name].crb) for name, c in jc.parameters().items()}
    return ActuatorPrediction(joints, _predicted(clean.delay, noisy.delay.crb))


def _predicted(clean, bound: float) -> Predicted:
    model_error = float(clean.se) if np.isfinite(clean.se) else np.inf
    return Predicted(float(clean.value), model_error, float(bound), float(np.hypot(model_error, bound)),
                     str(clean.status), str(clean.reason))
