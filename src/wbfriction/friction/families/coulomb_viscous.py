"""The Coulomb-viscous family: Coulomb (3.1) plus viscous (3.2) friction with the offset ``tau_os`` of (3.4),

.. math:: f(\\dot q) = F_v \\dot q + F_c \\operatorname{sgn}(\\dot q) + \\tau_{os}

(``sgn(0) = 0``); linear in every parameter. Units: F_v [N·m·s/rad]; F_c, tau_os [N·m]. Sign convention:
:mod:`wbfriction.friction.models`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, cast

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.friction.families.base import FrictionFamily
from wbfriction.friction.families.gaussian import sign_mean
from wbfriction.friction.families.params import ModelParamsBase, ParamLike
from wbfriction.friction.families.registry import register_family

COULOMB_VISCOUS_NAMES = ("F_v", "F_c", "tau_os")
"""Names of the parameters of the Coulomb-viscous model, in the order used by the fit."""


def coulomb(qd: ArrayLike, F_c: ArrayLike) -> np.ndarray:
    """Coulomb friction, eq. (3.1): ``f = F_c sgn(qd)`` (zero at rest)."""
    return np.asarray(F_c) * np.sign(qd)


def viscous(qd: ArrayLike, F_v: ArrayLike) -> np.ndarray:
    """Viscous friction, eq. (3.2): ``f = F_v qd``."""
    return np.asarray(F_v) * np.asarray(qd)


def coulomb_viscous(qd: ArrayLike, F_v: ParamLike, F_c: ParamLike, tau_os: ParamLike) -> np.ndarray:
    """Coulomb (3.1) plus viscous (3.2) friction with offset: ``f = F_v qd + F_c sgn(qd) + tau_os``
    (``sgn(0) = 0``)."""
    return viscous(qd, F_v) + coulomb(qd, F_c) + np.asarray(tau_os)


@dataclass(frozen=True)
class CoulombViscousParams(ModelParamsBase):
    """Parameters of the Coulomb-viscous model with offset, (3.1) + (3.2), for one joint
    (units in the module docstring)."""

    model: ClassVar[str] = "coulomb-viscous"
    names: ClassVar[tuple[str, ...]] = COULOMB_VISCOUS_NAMES

    F_v: float = 0.0
    F_c: float = 0.0
    tau_os: float = 0.0

    def f(self, qd: ArrayLike) -> np.ndarray:
        """Friction characteristic ``f(qd) = F_v qd + F_c sgn(qd) + tau_os`` [N·m]."""
        return coulomb_viscous(qd, self.F_v, self.F_c, self.tau_os)

    def f_at(self, qd: float) -> float:
        """:meth:`f` of one velocity in plain floats: the same operations in the same order (bit for bit)."""
        sign = 1.0 if qd > 0 else -1.0 if qd < 0 else qd if qd != qd else 0.0  # np.sign's: NaN stays NaN
        return self.F_v * qd + self.F_c * sign + self.tau_os

    def quantities(self) -> dict[str, float]:
        """:meth:`ModelParamsBase.quantities`: no Stribeck effect (``F_s = F_c``, ``S = 0``), a sign function."""
        return {"F_v": self.F_v, "F_c": self.F_c, "F_s": self.F_c, "S": 0.0, "v_s": float("nan"),
                "tau_os": self.tau_os, "a": float("inf")}


class CoulombViscous(FrictionFamily):
    """The Coulomb-viscous family (module docstring): F_v, F_c >= 0, its design columns ``qd``, ``sgn(qd)``, 1
    (times F_v, F_c, tau_os), none of them depending on a parameter; under a velocity noise ``sgn(qd)``'s
    expectation is ``erf(qd / (sigma sqrt 2))`` (:mod:`~wbfriction.friction.families.gaussian`)."""

    name = "coulomb-viscous"
    equation = "3.1 + 3.2"
    params_class = CoulombViscousParams
    units = {"F_v": "N·m·s/rad", "F_c": "N·m", "tau_os": "N·m"}
    lower = np.array([0.0, 0.0, -np.inf])
    upper = np.array([np.inf, np.inf, np.inf])
    constant_columns = ("F_v", "F_c", "tau_os")
    column_factors = (("F_v",), ("F_c",), ("tau_os",))
    jump_column = 1


    def velocity_basis(self, params: ModelParamsBase,
                       qd: np.ndarray) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
        """``F_v, F_c, tau_os`` on ``[qd, sgn(qd), 1]`` (:meth:`FrictionFamily.velocity_basis`)."""
        p = cast(CoulombViscousParams, params)
        qd = np.asarray(qd, dtype=float)
        return ("F_v", "F_c", "tau_os"), np.column_stack([qd, np.sign(qd), np.ones_like(qd)]), \
            np.array([p.F_v, p.F_c, p.tau_os])

    def values(self, x: np.ndarray, qd: np.ndarray, delta_s: ParamLike) -> np.ndarray:
        return coulomb_viscous(qd, x[0], x[1], x[2])

    def jacobian(self, x: np.ndarray, qd: np.ndarray, delta_s: float) -> np.ndarray:
        J = np.empty((qd.size, len(self.names)))
        J[:, 0] = qd  # F_v
        J[:, 2] = 1.0  # tau_os
        J[:, 1] = np.sign(qd)
        return J

    def columns(self, qd: np.ndarray, delta_s: float, z: np.ndarray, jump: np.ndarray | None = None) -> np.ndarray:
        qd = np.asarray(qd, dtype=float)
        return np.column_stack([qd, np.sign(qd), np.ones_like(qd)])

    def jump(self, qd: np.ndarray, z: np.ndarray) -> np.ndarray:
        return np.sign(qd)

    def mean_values(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        F_v, F_c, tau_os = x
        return F_v * qd + F_c * sign_mean(qd, sigma) + tau_os

    def mean_jacobian(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        J = np.empty((qd.size, len(x)))
        J[:, 0] = qd
        J[:, 1] = sign_mean(qd, sigma)
        J[:, 2] = 1.0
        return J

    def mean_columns(self, qd: np.ndarray, sigma: float, delta_s: float, z: np.ndarray,
                     jump: np.ndarray | None = None) -> np.ndarray:
        one = np.ones_like(qd)
        if jump is None:
            jump = self.mean_jump(qd, sigma, z)
        return np.column_stack([qd, jump, one])

    def mean_jump(self, qd: np.ndarray, sigma: float, z: np.ndarray) -> np.ndarray:
        return sign_mean(qd, sigma)


COULOMB_VISCOUS = register_family(CoulombViscous())
"""The Coulomb-viscous family, registered."""
