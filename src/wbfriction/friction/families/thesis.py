"""The thesis's family: the smooth Coulomb-viscous-Stribeck model with offset, eq. (3.5), the one the thesis
simulates and fits,

.. math:: f(\\dot q) = F_v \\dot q + F_c \\tanh(a \\dot q)\\,(1 + S e^{-|\\dot q / v_s|^{\\delta_s}}) + \\tau_{os}.

It is eq. (3.4) with the static friction written ``F_s = (1 + S) F_c``; ``tanh(a qd)`` replaces ``sgn(qd)`` so that
the model is continuous at rest (slope set by ``a``). Units: F_v [N·m·s/rad]; F_c, tau_os [N·m]; v_s [rad/s];
a [s/rad]; S and delta_s dimensionless. Sign convention: :mod:`wbfriction.friction.models`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import ClassVar, cast

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.friction.families.base import FrictionFamily
from wbfriction.friction.families.gaussian import (
    central_differences,
    hermite_mean,
    tanh_decay,
    tanh_decay_mean,
    tanh_mean,
    tanh_terms,
)
from wbfriction.friction.families.params import ModelParamsBase, ParamLike
from wbfriction.friction.families.registry import register_family

PARAM_NAMES = ("F_v", "F_c", "S", "v_s", "tau_os", "a")
"""Names of the fitted parameters of model (3.5), in the order used by the fit."""

LOWER = np.array([0.0, 0.0, 0.0, 1e-4, -np.inf, 1e-2])
"""Lower bounds of (F_v, F_c, S, v_s, tau_os, a) of model (3.5) (:data:`UPPER`)."""

UPPER = np.array([np.inf, np.inf, 50.0, 100.0, np.inf, 1e4])
"""Bounds of (F_v, F_c, S, v_s, tau_os, a) of model (3.5): dissipative viscous and Coulomb parts, static
friction at least the Coulomb level (S >= 0: the Stribeck effect is a drop from static to
Coulomb friction), positive Stribeck velocity and tanh slope. The fit further bounds ``v_s``
by the largest speed in the data: a Stribeck velocity beyond it is not identifiable, and
the Stribeck term would otherwise mimic viscous friction (S < 0, v_s large)."""


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
class FrictionParams(ModelParamsBase):
    """Parameters of model (3.5) for one joint (units in the module docstring)."""

    model: ClassVar[str] = "thesis"
    names: ClassVar[tuple[str, ...]] = PARAM_NAMES

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

    def quantities(self) -> dict[str, float]:
        """:meth:`ModelParamsBase.quantities`: the static friction ``F_s = (1 + S) F_c``; the smoothing
        ``tanh(a qd)`` has no counterpart in the other models."""
        return {"F_v": self.F_v, "F_c": self.F_c, "F_s": (1.0 + self.S) * self.F_c, "S": self.S,
                "v_s": self.v_s, "tau_os": self.tau_os, "a": self.a}


class Thesis(FrictionFamily):
    """The thesis's family (module docstring): bounds :data:`LOWER`, :data:`UPPER` (v_s at most the data's speed;
    ``a``'s upper bound a step). Its design columns are ``qd``, ``tanh(a qd)``, ``tanh(a qd) e``, 1 (times F_v,
    F_c, F_c S, tau_os), ``e = exp(-|qd / v_s|^delta_s)``. Under a velocity noise: ``tanh`` as a sum of error
    functions (:data:`~wbfriction.friction.families.gaussian.TANH_ERF`) for ``delta_s = 2``; otherwise the jump's
    expectation less that of its continuous rest by Gauss-Hermite (and the Jacobian by central differences)."""

    name = "thesis"
    equation = "3.5"
    params_class = FrictionParams
    units = {"F_v": "N·m·s/rad", "F_c": "N·m", "S": "1", "v_s": "rad/s", "tau_os": "N·m", "a": "s/rad"}
    lower = LOWER
    upper = UPPER
    speed_bounded = ("v_s",)
    step_slopes = ("a",)
    constant_columns = ("F_v", "tau_os")
    column_factors = (("F_v",), ("F_c",), ("F_c", "S"), ("tau_os",))
    nonlinear = ("v_s", "a")
    jump_column = 1
    jump_params = ("a",)
    varying_columns = (2,)


    def transitions(self, params: ModelParamsBase) -> dict[str, float]:
        """``v_s`` where the Stribeck effect is there (``S > 0``) and ``1 / a``, the speed at which ``tanh(a qd)``
        reaches 0.76, unless ``a`` is at its upper bound (a step: Coulomb friction, no transition to resolve)
        (:meth:`FrictionFamily.transitions`)."""
        p = cast(FrictionParams, params)
        out = {"v_s": float(p.v_s)} if p.S > 1e-6 and p.F_c > 0 else {}
        if p.a < (1.0 - 1e-3) * UPPER[5]:
            out["a"] = 1.0 / float(p.a)
        return out

    def coulomb_shape(self, params: ModelParamsBase, qd: np.ndarray) -> np.ndarray:
        """``tanh(a qd)`` (:meth:`FrictionFamily.coulomb_shape`)."""
        return np.tanh(cast(FrictionParams, params).a * qd)

    def coulomb_sign(self, params: ModelParamsBase, qd: float) -> float:
        """``tanh(a qd)`` of one velocity (:meth:`FrictionFamily.coulomb_sign`)."""
        return math.tanh(cast(FrictionParams, params).a * qd)

    def velocity_basis(self, params: ModelParamsBase,
                       qd: np.ndarray) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
        """``F_v, F_c, F_cS, tau_os`` on ``[qd, tanh(a qd), tanh(a qd) e, 1]`` with ``F_cS = F_c S`` and
        ``e = exp(-|qd / v_s|^delta_s)`` (:meth:`FrictionFamily.velocity_basis`)."""
        p = cast(FrictionParams, params)
        qd = np.asarray(qd, dtype=float)
        e = np.exp(-np.abs(qd / p.v_s) ** p.delta_s)
        th = np.tanh(p.a * qd)
        return ("F_v", "F_c", "F_cS", "tau_os"), np.column_stack([qd, th, th * e, np.ones_like(qd)]), \
            np.array([p.F_v, p.F_c, p.F_c * p.S, p.tau_os])

    def with_coefficients(self, params: ModelParamsBase, c: np.ndarray) -> ModelParamsBase:
        """``F_v, F_c, tau_os`` and ``S = F_cS / F_c`` (0 where F_c is) (:meth:`FrictionFamily.with_coefficients`)."""
        S = float(c[2] / c[1]) if c[1] != 0 else 0.0
        return replace(cast(FrictionParams, params), F_v=float(c[0]), F_c=float(c[1]), S=S, tau_os=float(c[3]))

    def values(self, x: np.ndarray, qd: np.ndarray, delta_s: ParamLike) -> np.ndarray:
        return coulomb_viscous_stribeck(qd, x[0], x[1], x[2], x[3], x[4], x[5], delta_s)

    def jacobian(self, x: np.ndarray, qd: np.ndarray, delta_s: float) -> np.ndarray:
        J = np.empty((qd.size, len(self.names)))
        J[:, 0] = qd  # F_v
        J[:, 4] = 1.0  # tau_os
        u = np.abs(qd / x[3])  # |qd / v_s|
        ud = u**delta_s
        e = np.exp(-ud)
        _, F_c, S, v_s, _, a = x
        th = np.tanh(a * qd)
        J[:, 1] = th * (1.0 + S * e)
        J[:, 2] = F_c * th * e
        # d/dv_s of exp(-(|qd|/v_s)^d) = e * d * u^d / v_s
        J[:, 3] = F_c * th * S * e * delta_s * ud / v_s
        J[:, 5] = F_c * (1.0 - th**2) * qd * (1.0 + S * e)
        return J

    def columns(self, qd: np.ndarray, delta_s: float, z: np.ndarray, jump: np.ndarray | None = None) -> np.ndarray:
        qd = np.asarray(qd, dtype=float)
        one = np.ones_like(qd)
        e = np.exp(-np.abs(qd / z[self.index("v_s")]) ** delta_s)
        if jump is None:
            jump = np.tanh(z[self.index("a")] * qd)
        return np.column_stack([qd, jump, jump * e, one])

    def jump(self, qd: np.ndarray, z: np.ndarray) -> np.ndarray:
        return np.tanh(z[self.index("a")] * qd)

    def other_exponent(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        """:meth:`mean_values` for ``delta_s != 2`` (class docstring)."""
        F_v, F_c, S, v_s, tau_os, a = x
        rest = hermite_mean(lambda u: np.tanh(a * u) * (1.0 - np.exp(-np.abs(u / v_s) ** delta_s)), qd, sigma)
        return F_v * qd + F_c * ((1.0 + S) * tanh_mean(qd, sigma, a) - S * rest) + tau_os

    def mean_values(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        if delta_s != 2.0:
            return self.other_exponent(x, qd, sigma, delta_s)
        F_v, F_c, S, v_s, tau_os, a = x
        return F_v * qd + F_c * (tanh_mean(qd, sigma, a) + S * tanh_decay_mean(qd, sigma, a, v_s)) + tau_os

    def mean_jacobian(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        if delta_s != 2.0:
            return central_differences(lambda p: self.other_exponent(p, qd, sigma, delta_s), x, qd.size)
        J = np.empty((qd.size, len(x)))
        J[:, 0] = qd
        F_v, F_c, S, v_s, tau_os, a = x
        th, th_a, _, _ = tanh_terms(qd, sigma**2, a)
        decay, decay_a, decay_vs = tanh_decay(qd, sigma, a, v_s)
        J[:, 1] = th + S * decay
        J[:, 2] = F_c * decay
        J[:, 3] = F_c * S * decay_vs
        J[:, 4] = 1.0
        J[:, 5] = F_c * (th_a + S * decay_a)
        return J

    def mean_columns(self, qd: np.ndarray, sigma: float, delta_s: float, z: np.ndarray,
                     jump: np.ndarray | None = None) -> np.ndarray:
        one = np.ones_like(qd)
        v_s, a = z[self.index("v_s")], z[self.index("a")]
        if jump is None:
            jump = self.mean_jump(qd, sigma, z)
        if delta_s == 2.0:
            decay = tanh_decay_mean(qd, sigma, a, v_s)
        else:  # the jump's expectation less that of its continuous rest
            decay = jump - hermite_mean(lambda u: np.tanh(a * u) * (1.0 - np.exp(-np.abs(u / v_s) ** delta_s)), qd,
                                        sigma)
        return np.column_stack([qd, jump, decay, one])

    def mean_jump(self, qd: np.ndarray, sigma: float, z: np.ndarray) -> np.ndarray:
        return tanh_mean(qd, sigma, z[self.index("a")])


THESIS = register_family(Thesis())
"""The thesis's family, registered."""
