"""Static friction models (thesis chapter 3), vectorised over samples and joints.

Sign convention (the one used everywhere in wbfriction):

* ``tau_f`` is the torque friction exerts **on the joint**. It enters the equation of
  motion as ``M qdd + h = S^T (tau + tau_f) + J^T lambda``, so a dissipative friction
  has ``qd * tau_f <= 0`` (thesis eq. 7.9).
* The models below return the thesis's friction characteristic ``f(qd)``, which points
  along the velocity: ``tau_f = -f(qd)``. Fitted parameters are therefore positive for
  dissipative friction (F_c, F_v > 0), as in the thesis's Tables 6.1 and 6.2.

All functions broadcast: ``qd`` may be (N,), (N, n_joints), ...; parameters are scalars
or arrays broadcastable to ``qd`` (e.g. shape (n_joints,)).

Units: qd [rad/s]; F_c, F_s, tau_os [N·m]; F_v [N·m·s/rad]; v_s [rad/s]; a [s/rad];
S and delta_s dimensionless.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass, fields
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.exceptions import InputError

PARAM_NAMES = ("F_v", "F_c", "S", "v_s", "tau_os", "a")
"""Names of the fitted parameters of model (3.5), in the order used by the fit."""

ParamLike = float | np.ndarray
"""A model parameter: one value, or an array of them broadcastable to ``qd`` (e.g. one per joint)."""


def coulomb(qd: ArrayLike, F_c: ArrayLike) -> np.ndarray:
    """Coulomb friction, eq. (3.1): ``f = F_c sgn(qd)`` (zero at rest)."""
    return np.asarray(F_c) * np.sign(qd)


def viscous(qd: ArrayLike, F_v: ArrayLike) -> np.ndarray:
    """Viscous friction, eq. (3.2): ``f = F_v qd``."""
    return np.asarray(F_v) * np.asarray(qd)


def stribeck(qd: ArrayLike, F_c: ParamLike, F_s: ParamLike, v_s: ParamLike,
             delta_s: ParamLike = 2.0) -> np.ndarray:
    """Coulomb friction with the Stribeck effect, eq. (3.3).

    ``f = sgn(qd) (F_c + (F_s - F_c) exp(-|qd / v_s|^delta_s))``, with static friction
    F_s, Stribeck velocity v_s and exponent delta_s (2: Gaussian, the thesis's choice).
    """
    qd = np.asarray(qd, dtype=float)
    return np.sign(qd) * (F_c + (np.asarray(F_s) - F_c) * np.exp(-np.abs(qd / v_s) ** delta_s))


def coulomb_viscous_stribeck(qd: ArrayLike, F_v: ParamLike, F_c: ParamLike, S: ParamLike, v_s: ParamLike,
           tau_os: ParamLike, a: ParamLike, delta_s: ParamLike = 2.0) -> np.ndarray:
    """Smooth Coulomb-viscous-Stribeck model with offset, eq. (3.5).

    ``f = F_v qd + F_c tanh(a qd) (1 + S exp(-|qd / v_s|^delta_s)) + tau_os``

    It is eq. (3.4) with the static friction written ``F_s = (1 + S) F_c``; ``tanh(a qd)``
    replaces ``sgn(qd)`` so that the model is continuous at rest (slope set by ``a``).
    """
    qd = np.asarray(qd, dtype=float)
    return (F_v * qd + F_c * np.tanh(np.asarray(a) * qd) * (1.0 + S * np.exp(-np.abs(qd / v_s) ** delta_s))
            + tau_os)


@dataclass(frozen=True)
class FrictionParams:
    """Parameters of model (3.5) for one joint (units in the module docstring)."""

    F_v: float = 0.0
    F_c: float = 0.0
    S: float = 0.0
    v_s: float = 0.1
    tau_os: float = 0.0
    a: float = 40.0
    delta_s: float = 2.0

    def f(self, qd: ArrayLike) -> np.ndarray:
        """Friction characteristic f(qd) of eq. (3.5) [N·m]."""
        return coulomb_viscous_stribeck(qd, self.F_v, self.F_c, self.S, self.v_s, self.tau_os, self.a, self.delta_s)

    def torque(self, qd: ArrayLike) -> np.ndarray:
        """Torque friction exerts on the joint, ``tau_f = -f(qd)`` [N·m]."""
        return -self.f(qd)

    def as_vector(self) -> np.ndarray:
        """The six fitted parameters in :data:`PARAM_NAMES` order."""
        return np.array([getattr(self, n) for n in PARAM_NAMES])

    @classmethod
    def from_vector(cls, x: Iterable[float], delta_s: float = 2.0) -> FrictionParams:
        """Parameters from the six fitted values in :data:`PARAM_NAMES` order."""
        # the six positional fields (PARAM_NAMES): delta_s is given by keyword
        six = cast(tuple[float, float, float, float, float, float], tuple(map(float, x)))
        return cls(*six, delta_s=delta_s)

    def to_dict(self) -> dict[str, float]:
        """Every parameter by name (the inverse of :meth:`from_dict`)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> FrictionParams:
        """Parameters from a mapping of their names (missing ones take the defaults).

        Raises:
            InputError: an unknown name, or a value that is not a number.
        """
        names = {f.name for f in fields(cls)}
        unknown = set(d) - names
        if unknown:
            raise InputError(f"unknown friction parameter(s): {', '.join(sorted(unknown))}")
        try:
            return cls(**{k: float(v) for k, v in d.items()})
        except (TypeError, ValueError) as exc:
            raise InputError(str(exc)) from None


def friction_torque(qd: np.ndarray, params: list[FrictionParams]) -> np.ndarray:
    """Friction torques ``tau_f = -f(qd)`` for several joints at once.

    Args:
        qd: joint velocities (N, n_joints) [rad/s].
        params: one :class:`FrictionParams` per column of ``qd``.

    Returns:
        tau_f, (N, n_joints) [N·m], in the sign convention of this module.
    """
    return -coulomb_viscous_stribeck(qd, **stack_params(params))


def stack_params(params: list[FrictionParams]) -> dict[str, ParamLike]:
    """Keyword arguments of :func:`coulomb_viscous_stribeck` for several joints: each parameter as an (n_joints,)
    array, or as a float when every joint has the same value (cheaper to broadcast)."""
    out: dict[str, ParamLike] = {}
    for name in PARAM_NAMES + ("delta_s",):
        values = np.array([getattr(p, name) for p in params], dtype=float)
        out[name] = float(values[0]) if values.size and np.all(values == values[0]) else values
    return out
