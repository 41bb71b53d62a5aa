"""A toy friction family, one file: Coulomb friction with a fixed tanh slope, viscous friction and an offset,
``f = F_v qd + F_c tanh(A qd) + tau_os`` with ``A`` = 40 s/rad (model (3.5) with ``S = 0`` and its slope held).
Linear in every parameter, so the base class's velocity basis and Gauss-Hermite expectation serve it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.friction.families.base import FrictionFamily
from wbfriction.friction.families.params import ModelParamsBase

NAME = "fixed-slope"
A = 40.0
"""The tanh slope held [s/rad]."""


@dataclass(frozen=True)
class FixedSlopeParams(ModelParamsBase):
    """``f = F_v qd + F_c tanh(A qd) + tau_os`` [N·m] (module docstring)."""

    model: ClassVar[str] = NAME
    names: ClassVar[tuple[str, ...]] = ("F_v", "F_c", "tau_os")

    F_v: float = 0.0
    F_c: float = 0.0
    tau_os: float = 0.0

    def f(self, qd: ArrayLike) -> np.ndarray:
        qd = np.asarray(qd, dtype=float)
        return self.F_v * qd + self.F_c * np.tanh(A * qd) + self.tau_os

    def quantities(self) -> dict[str, float]:
        return {"F_v": self.F_v, "F_c": self.F_c, "F_s": self.F_c, "S": 0.0, "v_s": float("nan"),
                "tau_os": self.tau_os, "a": A}


class FixedSlope(FrictionFamily):
    """The family (module docstring)."""

    name, equation, params_class = NAME, "3.5, S = 0, a held", FixedSlopeParams
    units = {"F_v": "N·m·s/rad", "F_c": "N·m", "tau_os": "N·m"}
    lower, upper = np.array([0.0, 0.0, -np.inf]), np.array([np.inf, np.inf, np.inf])
    constant_columns = ("F_v", "F_c", "tau_os")
    column_factors = (("F_v",), ("F_c",), ("tau_os",))

    def values(self, x, qd, delta_s):
        qd = np.asarray(qd, dtype=float)
        return x[0] * qd + x[1] * np.tanh(A * qd) + x[2]

    def jacobian(self, x, qd, delta_s):
        return self.columns(qd, delta_s, x)

    def columns(self, qd, delta_s, z, jump=None):
        qd = np.asarray(qd, dtype=float)
        return np.column_stack([qd, np.tanh(A * qd), np.ones_like(qd)])
