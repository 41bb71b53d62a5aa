"""What an estimate knows of its noise, joint by joint (issue 38): the record the fit's errors-in-variables
correction and Cramér-Rao bound read.

Per joint, measured once per log from its positions and model (:func:`noise_record`):

* ``position``: the positions' white noise ``sigma_q`` [rad] (the spectrum of their second difference,
  :func:`~wbfriction.signals.content.acceleration_content`; an encoder's quantisation is in it);
* ``inertia``: the joint's effective inertia ``M`` [kg·m²]: the median over the log of the norm of its row of the
  joint-space inertia matrix (every joint's position noise reaches its friction through that row). The whole
  robot's matrix, not the stance-rooted tree's: a bound, not a number the estimate uses;

and per route (each with its own filter):

* ``velocity``: the noise's share in the velocity the route gives the model as its argument [rad/s]:
  ``sigma_q`` times the velocity filter's gain;
* ``acceleration``: what the route leaves of it in the friction, per unit inertia [rad/s²]: ``sigma_q`` times
  the route's gain (:func:`~wbfriction.signals.choice.central_noise_gain`,
  :func:`~wbfriction.signals.choice.savgol_noise_gain`, :func:`~wbfriction.signals.choice.momentum_noise_gain`, ...).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.friction.options import ROUTES, EstimateOptions, Route
from wbfriction.model.robot import Robot
from wbfriction.signals.choice import (
    butterworth_noise_gain,
    butterworth_velocity_gain,
    central_noise_gain,
    momentum_noise_gain,
    savgol_noise_gain,
    velocity_noise_gain,
)
from wbfriction.signals.content import acceleration_content


@dataclass(frozen=True)
class NoiseModel:
    """The per-sample noise of one joint's friction estimate (module docstring).

    Attributes:
        torque: ``sigma_tau``, the torque's white noise [N·m].
        position: ``sigma_q``, the positions' white noise [rad].
        inertia: ``M``, the joint's effective inertia [kg·m²].
        dt: the sampling period [s].
    """

    torque: float
    position: float
    inertia: float
    dt: float

    def psd(self, freq: np.ndarray) -> np.ndarray:
        """``P(f)`` [N²·m²] at ``freq`` [Hz] (module docstring)."""
        gain = 4.0 * np.sin(np.pi * np.asarray(freq, dtype=float) * self.dt) ** 2 / self.dt**2
        return self.torque**2 + (self.inertia * self.position * gain) ** 2


@dataclass(frozen=True)
class JointNoise:
    """What an estimate knows of one joint's noise, before a fit (:func:`~wbfriction.friction.noise.joint_noise`).

    Attributes:
        position: ``sigma_q``, the positions' white noise [rad], measured from their spectrum.
        velocity: the white noise's share in the velocity the model takes as its argument [rad/s].
        acceleration: the route's acceleration noise per unit inertia [rad/s²] (what its filter leaves).
        inertia: ``M``, the joint's effective inertia [kg·m²].
        dt: the sampling period [s].
    """

    position: float
    velocity: float
    acceleration: float
    inertia: float
    dt: float

    def with_torque(self, torque: float) -> NoiseModel:
        """The whole :class:`NoiseModel`, with the torque's noise [N·m]."""
        return NoiseModel(torque, self.position, self.inertia, self.dt)


INERTIA_SAMPLES = 32
"""Configurations of the log the effective inertia is the median over."""


def route_gains(options: EstimateOptions, dt: float) -> dict[Route, tuple[float, float]]:
    """Each route's (velocity [1/s], acceleration [1/s²]) gain of a unit white position noise, for resolved options
    (a differentiation scheme, the momentum route's windows)."""
    diff, f = options.diff, options.filtering
    if diff in ("central", "backward"):
        acceleration = (1.0 / (math.sqrt(2.0) * dt) if diff == "central" else math.sqrt(2.0) / dt,
                        central_noise_gain(dt))
    elif diff == "savgol":
        acceleration = (velocity_noise_gain(f.window, dt, f.poly_order, f.weights),
                        savgol_noise_gain(f.window, f.poly_order, dt, f.weights))
    elif diff == "butterworth":
        acceleration = (butterworth_velocity_gain(f.cutoff, f.butter_order, dt),
                        butterworth_noise_gain(f.cutoff, f.butter_order, dt))
    else:  # the simulators' true derivatives, or not resolved
        acceleration = (0.0, 0.0)
    out: dict[Route, tuple[float, float]] = {"acceleration": acceleration}
    m = options.momentum
    if m.velocity_window is not None and m.window is not None:
        out["momentum"] = (velocity_noise_gain(m.velocity_window, dt), momentum_noise_gain(m.velocity_window,
                                                                                          m.window // 2, dt))
    return out


def effective_inertia(robot: Robot, q: np.ndarray) -> np.ndarray:
    """``M`` (n_tc,) [kg·m²] (module docstring) over at most :data:`INERTIA_SAMPLES` of the joint positions ``q``
    (N, n_act) [rad], evenly spaced."""
    finite = np.flatnonzero(np.all(np.isfinite(q), axis=1))
    rows = finite[np.linspace(0, finite.size - 1, min(INERTIA_SAMPLES, finite.size)).astype(int)] if finite.size \
        else np.zeros(0, dtype=int)
    data = robot.model.createData()
    tc, act = robot.act_v_index[robot.tc_index], robot.act_v_index
    norms = [np.linalg.norm(pin.crba(robot.model, data, robot.configuration(q[k]))[np.ix_(tc, act)], axis=1)
             for k in rows]
    return np.median(norms, axis=0) if norms else np.full(len(tc), np.nan)


def noise_record(robot: Robot, q: np.ndarray, dt: float, options: EstimateOptions,
                 changes: np.ndarray | None = None) -> dict[str, Any] | None:
    """The JSON-ready record of an estimate's noise (module docstring) from joint positions ``q`` (N, n_act) [rad]
    sampled every ``dt`` [s] (a stretch without gaps) and resolved ``options``; None for positions too few to
    measure their noise. ``changes`` (N,): the rows where a contact flag changes, whose impacts are not noise
    (:func:`~wbfriction.signals.content.white_position_noise`)."""
    try:
        content = acceleration_content(q, dt, changes=changes)
    except InputError:
        return None
    sigma = dict(zip(robot.actuated, map(float, content.position_noise)))
    inertia = effective_inertia(robot, q)
    gains = route_gains(options, dt)
    joints = {j: {"position": sigma[j], "inertia": float(inertia[i])} for i, j in enumerate(robot.torque_controlled)}
    routes = {route: {j: {"velocity": sigma[j] * v, "acceleration": sigma[j] * a} for j in robot.torque_controlled}
              for route, (v, a) in gains.items()}
    return {"dt": float(dt), "joints": joints, "routes": routes}


def joint_noises(record: Any, route: str) -> dict[str, JointNoise]:
    """The :class:`~wbfriction.friction.noise.JointNoise` of every joint of a :func:`noise_record` for ``route``;
    empty without a record (an older table) or the route's entry.

    Raises:
        InputError: a record that is not one (a metadata damaged or written by another tool).
    """
    if record is None:
        return {}
    try:
        dt, joints, per_route = float(record["dt"]), record["joints"], record["routes"].get(route)
        if per_route is None or route not in ROUTES:
            return {}
        return {j: JointNoise(float(v["position"]), float(per_route[j]["velocity"]),
                              float(per_route[j]["acceleration"]), float(v["inertia"]), dt)
                for j, v in joints.items() if j in per_route}
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise InputError(f"the metadata's noise record is not wbfriction's: {exc}") from None
