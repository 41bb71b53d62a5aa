"""What a motion will let a fixed-base arm's identification report (``estimate`` then ``fit``, as a user runs them),
before the arm moves: each joint's fitted parameters' standard errors and statuses, predicted by the identification
itself on the motion simulated under the prior (:func:`~wbfriction.sim.arm.simulate_arm` with the trajectory).

The route of a PD-driven robot (:mod:`.predict`) predicts a standard error as two parts in quadrature: the model
error (what the identification reports on the motion simulated without sensor noise) and the noise's Cramér-Rao
bound (on the motion simulated with it). On an arm that sum is no prediction: the standard error the fit reports is
a median 2.0 times it, from 0.2 to 16 times, within 1.5 times for a third of the parameters (Panda, 30 s, positions'
noise 1e-4 rad, 19-bit encoders, torque noise 0.05 N·m; a designed and a random motion), for two reasons:

* the estimate is not efficient where the joint's inertia is large: the positions' noise reaches the friction
  through the inertia and a second derivative, and what the route's filter leaves of it makes the sandwich standard
  error of F_c and F_v on the shoulder and elbow (Panda A1-A4) 3 to 5 times their bound (the wrist's: the bound);
* with ``model="auto"`` the standard error a user reads of F_c and F_v holds how far the other families put them
  (:attr:`~wbfriction.fit.result.FitResult.model_spread`), which the noise sets (the Stribeck and transition
  parameters it leaves loose), not the model: 2.4 to 22 times the bound.

So the prediction is the identification's own report on the motion simulated with the sensors' noise
(:attr:`ArmPrediction.joints`, ``se``; its statistical part without the family spread,
:attr:`ArmPrediction.statistical`), the model error and the bound kept beside it. (Not floored at their sum: where
the noise leads ``auto`` to a simpler family than the noise-free motion does, that family's misfit of the
noise-free motion is no error the noisy fit reports.) What the noise makes of a standard error differs from one
recording to another: on another noise's recording the statistical standard errors of F_c, F_v and ``tau_os`` came
within 0.84 to 1.25 times those predicted (42 of 42 over the two motions, medians 1.07 and 1.03), but the standard
errors read, every parameter's, within 1.5 times for 72 % and 56 % of them only (0.2 to 3.7 times: the Stribeck and
transition parameters S, v_s and a, and the family spread, a single draw of the families' disagreement).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
import pyarrow as pa

from wbfriction.excite.predict import Predicted, worst_share
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions, ModelChoice
from wbfriction.fit.result import FitResult
from wbfriction.fit.status import READ
from wbfriction.friction.estimate import FrictionEstimate, estimate_log
from wbfriction.friction.models import ModelParams
from wbfriction.friction.noise import NoiseModel, effective_inertia
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import log_from_table
from wbfriction.model.robot import Robot
from wbfriction.sim.arm import ArmOptions, Reference, simulate_arm

REAL_ARM = ArmOptions(duration=30.0, encoder_bits=19, position_std=1e-4, torque_std=0.05)
"""An arm's recording as :func:`predict_arm` takes it by default: 30 s at 1 kHz, a real arm's sensors (19-bit
encoders, white position noise of 1e-4 rad, torque noise of 0.05 N·m: the studies' Panda)."""


@dataclass(frozen=True)
class ArmPrediction:
    """What a fixed-base arm's identification of a motion is predicted to report (module docstring).

    Attributes:
        joints: per joint, each parameter of the model the fit chose on the noisy motion, a :class:`Predicted`:
            ``value`` the noise-free fit's, ``model_error`` the standard error the noise-free fit (of the same
            family) reports, ``bound`` the noisy fit's Cramér-Rao bound, ``se`` the standard error the noisy fit
            reports, the one a user will read (:meth:`~wbfriction.fit.result.FitResult.read_stderr`: with the family
            spread) [the parameter's unit], ``status`` and ``reason`` the noisy fit's verdict.
        statistical: per joint and parameter, the predicted standard error without the family spread (the noisy
            fit's :attr:`~wbfriction.fit.result.FitResult.stderr`) [the parameter's unit].
        models: per joint, the family the fit chose on the noisy motion.
    """

    joints: dict[str, dict[str, Predicted]]
    statistical: dict[str, dict[str, float]]
    models: dict[str, str]

    def worst(self, weak: float, names: Sequence[str] = READ) -> tuple[str, str, float]:
        """The parameter of ``names`` (default F_c and F_v) whose predicted standard error is the largest share of
        ``weak`` times its value (:data:`~wbfriction.fit.status.WEAK`, the ``weak`` status's
        limit; above 1: predicted ``weak``); (joint, name, share), the share infinite for a value at zero.

        Raises:
            ValueError: no joint has a parameter of ``names``.
        """
        return worst_share({j: {n: p for n, p in params.items() if n in names} for j, params in self.joints.items()},
                           {}, weak)


def sensor_noise(robot: Robot, options: ArmOptions = REAL_ARM) -> dict[str, NoiseModel]:
    """Each joint's friction noise as ``options``' sensors make it (white position noise and the encoder's rounding,
    the torque's noise), its inertia at the middle of the ranges: what :func:`~.design.design_excitation` designs
    against."""
    lower, upper = robot.angle_limits
    inertia = effective_inertia(robot, (0.5 * (lower + upper))[None, :])
    step = 2 * np.pi / 2 ** options.encoder_bits if options.encoder_bits else 0.0
    position = float(np.hypot(options.position_std, step / np.sqrt(12)))
    return {j: NoiseModel(options.torque_std, position, float(inertia[i]), 1.0 / options.rate)
            for i, j in enumerate(robot.actuated)}


def noise_free(options: ArmOptions) -> ArmOptions:
    """``options`` with exact sensors: no position or torque noise, no encoder rounding."""
    return dataclasses.replace(options, position_std=0.0, torque_std=0.0, encoder_bits=None)


def identify_arm(robot: Robot, friction: Mapping[str, ModelParams], trajectory: Reference,
                 options: ArmOptions = REAL_ARM, armature: dict[str, float] | None = None,
                 estimate: EstimateOptions = EstimateOptions(), fit: FitOptions = FitOptions(),
                 joints: Sequence[str] | None = None) -> tuple[FrictionEstimate, list[FitResult]]:
    """The arm's motion along ``trajectory`` simulated (:func:`~wbfriction.sim.arm.simulate_arm`: ``friction`` and
    ``armature`` injected, ``options``' sensors) and identified as ``wbfriction estimate`` and ``wbfriction fit``
    do (:func:`~wbfriction.friction.estimate.estimate_log`, :func:`~wbfriction.fit.joints.fit_estimate`): the
    friction estimate and the fit of each torque-controlled joint (of ``joints`` only where given: the joints a
    design moves).

    Raises:
        InputError: what the simulator, the estimate and the fit raise.
    """
    table = recorded(robot, friction, trajectory, options, armature)
    est = estimate_log(robot, log_from_table(table, robot, "excite"), estimate)
    return est, fit_estimate(est, fit, joints=joints)


def recorded(robot: Robot, friction: Mapping[str, ModelParams], trajectory: Reference, options: ArmOptions,
             armature: dict[str, float] | None = None) -> pa.Table:
    """The arm's motion along ``trajectory`` simulated (:func:`~wbfriction.sim.arm.simulate_arm`) and logged as the
    robot's own logs carry its torque: motor currents ``current.<joint>`` where its TOML gives every joint a torque
    constant, else the joints' torques ``tau.<joint>`` [N·m] (a log without a joint's constant can only carry its
    torque). The torque is the same either way: the constants are asked of no robot whose logs do not need them
    (issue 81: an arm without ``[torque_constants]`` was refused after its whole design).

    Raises:
        InputError: what :func:`~wbfriction.sim.arm.simulate_arm` raises.
    """
    if all(j in robot.torque_constants for j in robot.actuated):
        return simulate_arm(robot, friction, armature, options, trajectory=trajectory).table
    unit = dataclasses.replace(robot, torque_constants=dict.fromkeys(robot.actuated, 1.0), cache={})
    table = simulate_arm(unit, friction, armature, options, trajectory=trajectory).table  # current: N·m at 1 N·m/A
    return table.rename_columns([f"tau.{n.removeprefix('current.')}" if n.startswith("current.") else n
                                 for n in table.column_names])


def predict_arm(robot: Robot, friction: Mapping[str, ModelParams], trajectory: Reference,
                options: ArmOptions = REAL_ARM, armature: dict[str, float] | None = None,
                estimate: EstimateOptions = EstimateOptions(), fit: FitOptions = FitOptions(),
                joints: Sequence[str] | None = None) -> ArmPrediction:
    """:class:`ArmPrediction` (module docstring) of the fixed-base ``robot`` following ``trajectory`` (an
    ``excite`` design's :class:`~wbfriction.walking.fourier.FourierTrajectory`, or any reference) for
    :attr:`ArmOptions.duration`, its ``friction`` and ``armature`` (None: the robot's) as the prior has them, read by
    ``options``' sensors (their noise's seed :attr:`ArmOptions.seed`), identified with ``estimate`` and ``fit``
    (their defaults: the commands'); of ``joints`` only where given (a design's moving joints: a joint held still
    is not predicted).

    Where the noise-free fit chose another family than the noisy one, its joint is fitted again with the noisy
    one's, so that each parameter has its model error. A joint the noisy fit could not fit has no parameters.

    Raises:
        InputError: what :func:`~wbfriction.sim.arm.simulate_arm`, the estimate and the fit raise.
    """
    clean_est, clean_fits = identify_arm(robot, friction, trajectory, noise_free(options), armature, estimate, fit,
                                         joints)
    _, noisy_fits = identify_arm(robot, friction, trajectory, options, armature, estimate, fit, joints)
    clean = {f.joint: f for f in clean_fits}
    predicted: dict[str, dict[str, Predicted]] = {}
    statistical: dict[str, dict[str, float]] = {}
    models: dict[str, str] = {}
    for noisy in noisy_fits:
        if noisy.params is None:
            predicted[noisy.joint], statistical[noisy.joint] = {}, {}
            continue
        c = clean[noisy.joint]
        if c.model != noisy.model:
            again = dataclasses.replace(fit, model=cast(ModelChoice, noisy.model))
            c = fit_estimate(clean_est, again, joints=[noisy.joint])[0]
        predicted[noisy.joint], statistical[noisy.joint] = predicted_joint(c, noisy)
        models[noisy.joint] = noisy.model
    return ArmPrediction(predicted, statistical, models)


def predicted_joint(clean: FitResult, noisy: FitResult) -> tuple[dict[str, Predicted], dict[str, float]]:
    """One joint's :class:`Predicted` per parameter of ``noisy``'s model, and its statistical standard errors
    (:class:`ArmPrediction`), from the fits of the same motion without (``clean``, of the same family) and with the
    sensors' noise (``noisy``). A parameter the noise-free fit has no finite standard error for (or no parameters)
    has an infinite model error."""
    verdict = noisy.verdict()
    clean_read = clean.read_stderr() if clean.params is not None else {}
    out = {}
    for name, se in noisy.read_stderr().items():
        value = getattr(clean.params, name) if clean.params is not None else getattr(noisy.params, name)
        out[name] = Predicted(float(value), _finite_or_inf(clean_read.get(name, np.inf)),
                              float(noisy.crb.get(name, 0.0)), float(se), str(verdict.status), str(verdict.reason))
    return out, {name: float(se) for name, se in noisy.stderr.items()}


def _finite_or_inf(x: float) -> float:
    return float(x) if np.isfinite(x) else np.inf
