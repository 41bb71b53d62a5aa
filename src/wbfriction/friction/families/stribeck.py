"""The Stribeck family: Coulomb friction with the Stribeck effect (3.3) plus viscous friction (3.2), with the offset
``tau_os`` of (3.4),

.. math:: f(\\dot q) = F_v \\dot q + \\operatorname{sgn}(\\dot q)\\,(F_c + (F_s - F_c)\\,
          e^{-|\\dot q / v_s|^{\\delta_s}}) + \\tau_{os},

F_s the static friction (the level at rest), F_c the Coulomb friction beyond the Stribeck velocity v_s, delta_s the
Stribeck exponent (held, the thesis's 2). The fit moves ``F_s - F_c`` (>= 0: the Stribeck effect a drop from static to
Coulomb friction) in place of F_s. Units: F_v [N·m·s/rad]; F_c, F_s, tau_os [N·m]; v_s [rad/s]. Sign convention:
:mod:`wbfriction.friction.models`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, cast

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.friction.families.base import FrictionFamily
from wbfriction.friction.families.coulomb_viscous import viscous
from wbfriction.friction.families.gaussian import (
    central_differences,
    hermite_mean,
    sign_decay,
    sign_decay_mean,
    sign_mean,
)
from wbfriction.friction.families.params import ModelParamsBase, ParamLike
from wbfriction.friction.families.registry import register_family

STRIBECK_NAMES = ("F_v", "F_c", "F_s", "v_s", "tau_os")
"""Names of the parameters of the Coulomb-Stribeck-viscous model, in the order used by the fit."""


def stribeck(qd: ArrayLike, F_c: ParamLike, F_s: ParamLike, v_s: ParamLike,
             delta_s: ParamLike = 2.0) -> np.ndarray:
    """Coulomb friction with the Stribeck effect, eq. (3.3).

    ``f = sgn(qd) (F_c + (F_s - F_c) exp(-|qd / v_s|^delta_s))``, with static friction
    F_s, Stribeck velocity v_s and exponent delta_s (2: Gaussian, the thesis's choice).
    """
    qd = np.asarray(qd, dtype=float)
    return np.sign(qd) * (F_c + (np.asarray(F_s) - F_c) * np.exp(-np.abs(qd / v_s) ** delta_s))


def stribeck_viscous(qd: ArrayLike, F_v: ParamLike, F_c: ParamLike, F_s: ParamLike, v_s: ParamLike,
                     tau_os: ParamLike, delta_s: ParamLike = 2.0) -> np.ndarray:
    """Coulomb friction with the Stribeck effect (3.3) plus viscous friction (3.2), with offset:
    ``f = F_v qd + sgn(qd) (F_c + (F_s - F_c) exp(-|qd / v_s|^delta_s)) + tau_os``."""
    return viscous(qd, F_v) + stribeck(qd, F_c, F_s, v_s, delta_s) + np.asarray(tau_os)


@dataclass(frozen=True)
class StribeckParams(ModelParamsBase):
    """Parameters of the Coulomb-Stribeck-viscous model with offset, (3.3) + (3.2), for one
    joint: static friction ``F_s`` (at rest), Coulomb friction ``F_c`` (beyond the Stribeck
    velocity ``v_s``), viscous ``F_v``, offset ``tau_os`` (units in the module docstring)."""

    model: ClassVar[str] = "stribeck"
    names: ClassVar[tuple[str, ...]] = STRIBECK_NAMES

    F_v: float = 0.0
    F_c: float = 0.0
    F_s: float = 0.0
    v_s: float = 0.1
    tau_os: float = 0.0
    delta_s: float = 2.0

    def f(self, qd: ArrayLike) -> np.ndarray:
        """Friction characteristic f(qd) of (3.3) + (3.2) with offset [N·m]."""
        return stribeck_viscous(qd, self.F_v, self.F_c, self.F_s, self.v_s, self.tau_os, self.delta_s)

    def quantities(self) -> dict[str, float]:
        """:meth:`ModelParamsBase.quantities`: ``S = F_s / F_c - 1``, a sign function."""
        S = self.F_s / self.F_c - 1.0 if self.F_c != 0 else float("nan")
        return {"F_v": self.F_v, "F_c": self.F_c, "F_s": self.F_s, "S": S, "v_s": self.v_s, "tau_os": self.tau_os,
                "a": float("inf")}


class Stribeck(FrictionFamily):
    """The Stribeck family (module docstring): F_v, F_c >= 0, ``F_s - F_c >= 0``, v_s in [1e-4, 100] rad/s and at
    most the data's speed. Its design columns are ``qd``, ``sgn(qd)``, ``sgn(qd) e``, 1 (times F_v, F_c, F_s - F_c,
    tau_os), ``e = exp(-|qd / v_s|^delta_s)``. Under a velocity noise: closed forms for ``delta_s = 2``; otherwise the
    jump's expectation less that of its continuous rest, ``E[sgn(u) (1 - e(u))]``, by Gauss-Hermite (and the
    Jacobian by central differences)."""

    name = "stribeck"
    equation = "3.3 + 3.2"
    params_class = StribeckParams
    units = {"F_v": "N·m·s/rad", "F_c": "N·m", "F_s": "N·m", "v_s": "rad/s", "tau_os": "N·m"}
    lower = np.array([0.0, 0.0, 0.0, 1e-4, -np.inf])
    upper = np.array([np.inf, np.inf, np.inf, 100.0, np.inf])
    speed_bounded = ("v_s",)
    constant_columns = ("F_v", "tau_os")
    column_factors = (("F_v",), ("F_c",), ("F_s",), ("tau_os",))  # F_s's coordinate: F_s - F_c
    nonlinear = ("v_s",)
    jump_column = 1
    varying_columns = (2,)
    held_with = (("F_s", "F_c"),)


    def transitions(self, params: ModelParamsBase) -> dict[str, float]:
        """``{"v_s": v_s}`` where the Stribeck effect is there (``F_s > F_c``), else none
        (:meth:`FrictionFamily.transitions`)."""
        p = cast(StribeckParams, params)
        return {"v_s": float(p.v_s)} if p.F_s - p.F_c > 1e-6 * max(abs(p.F_c), 1.0) else {}

    def velocity_basis(self, params: ModelParamsBase,
                       qd: np.ndarray) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
        """``F_v, F_c, F_s, tau_os`` on ``[qd, sgn(qd) (1 - e), sgn(qd) e, 1]``, ``e = exp(-|qd / v_s|^delta_s)``
        (:meth:`FrictionFamily.velocity_basis`)."""
        p = cast(StribeckParams, params)
        qd = np.asarray(qd, dtype=float)
        e = np.exp(-np.abs(qd / p.v_s) ** p.delta_s)
        s = np.sign(qd)
        return ("F_v", "F_c", "F_s", "tau_os"), np.column_stack([qd, s * (1 - e), s * e, np.ones_like(qd)]), \
            np.array([p.F_v, p.F_c, p.F_s, p.tau_os])

    def values(self, x: np.ndarray, qd: np.ndarray, delta_s: ParamLike) -> np.ndarray:
        return stribeck_viscous(qd, x[0], x[1], x[2], x[3], x[4], delta_s)

    def jacobian(self, x: np.ndarray, qd: np.ndarray, delta_s: float) -> np.ndarray:
        J = np.empty((qd.size, len(self.names)))
        J[:, 0] = qd  # F_v
        J[:, 4] = 1.0  # tau_os
        u = np.abs(qd / x[3])  # |qd / v_s|
        ud = u**delta_s
        e = np.exp(-ud)
        _, F_c, F_s, v_s, _ = x
        sgn = np.sign(qd)
        J[:, 1] = sgn * (1.0 - e)
        J[:, 2] = sgn * e
        J[:, 3] = sgn * (F_s - F_c) * e * delta_s * ud / v_s
        return J

    def columns(self, qd: np.ndarray, delta_s: float, z: np.ndarray, jump: np.ndarray | None = None) -> np.ndarray:
        qd = np.asarray(qd, dtype=float)
        one = np.ones_like(qd)
        e = np.exp(-np.abs(qd / z[self.index("v_s")]) ** delta_s)
        if jump is None:
            jump = np.sign(qd)
        return np.column_stack([qd, jump, jump * e, one])

    def jump(self, qd: np.ndarray, z: np.ndarray) -> np.ndarray:
        return np.sign(qd)

    def to_fit(self, x: np.ndarray) -> np.ndarray:
        s, c = self.index("F_s"), self.index("F_c")
        z = np.array(x, dtype=float)
        z[s] = x[s] - x[c]  # F_s - F_c
        return z

    def from_fit(self, z: np.ndarray) -> np.ndarray:
        s, c = self.index("F_s"), self.index("F_c")
        x = np.array(z, dtype=float)
        x[s] = z[c] + z[s]
        return x

    def fit_jacobian(self, jac: np.ndarray) -> np.ndarray:
        s, c = self.index("F_s"), self.index("F_c")
        jac = jac.copy()
        jac[:, c] += jac[:, s]  # F_c moves F_s too
        return jac

    def other_exponent(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        """:meth:`mean_values` for ``delta_s != 2`` (class docstring)."""
        F_v, F_c, F_s, v_s, tau_os = x
        rest = hermite_mean(lambda u: np.sign(u) * (1.0 - np.exp(-np.abs(u / v_s) ** delta_s)), qd, sigma)
        return F_v * qd + F_s * sign_mean(qd, sigma) - (F_s - F_c) * rest + tau_os

    def mean_values(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        if delta_s != 2.0:
            return self.other_exponent(x, qd, sigma, delta_s)
        F_v, F_c, F_s, v_s, tau_os = x
        return F_v * qd + F_c * sign_mean(qd, sigma) + (F_s - F_c) * sign_decay_mean(qd, sigma, v_s) + tau_os

    def mean_jacobian(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        if delta_s != 2.0:
            return central_differences(lambda p: self.other_exponent(p, qd, sigma, delta_s), x, qd.size)
        J = np.empty((qd.size, len(x)))
        J[:, 0] = qd
        F_v, F_c, F_s, v_s, tau_os = x
        sgn = sign_mean(qd, sigma)
        decay, d_vs = sign_decay(qd, sigma, v_s)
        J[:, 1] = sgn - decay
        J[:, 2] = decay
        J[:, 3] = (F_s - F_c) * d_vs
        J[:, 4] = 1.0
        return J

    def mean_columns(self, qd: np.ndarray, sigma: float, delta_s: float, z: np.ndarray,
                     jump: np.ndarray | None = None) -> np.ndarray:
        one = np.ones_like(qd)
        v_s = z[self.index("v_s")]
        if jump is None:
            jump = self.mean_jump(qd, sigma, z)
        if delta_s == 2.0:
            decay = sign_decay_mean(qd, sigma, v_s)
        else:  # the jump's expectation less that of its continuous rest
            decay = jump - hermite_mean(lambda u: np.sign(u) * (1.0 - np.exp(-np.abs(u / v_s) ** delta_s)), qd, sigma)
        return np.column_stack([qd, jump, decay, one])

    def mean_jump(self, qd: np.ndarray, sigma: float, z: np.ndarray) -> np.ndarray:
        return sign_mean(qd, sigma)


STRIBECK = register_family(Stribeck())
"""The Stribeck family, registered."""
