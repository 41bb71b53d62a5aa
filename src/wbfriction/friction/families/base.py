"""What a friction family is (:class:`FrictionFamily`): one model of the friction characteristic ``f(qd)``, with
everything the fit, the model choice and the exports need to know of it, so that a new model plugs in with one
subclass and one call (:func:`~wbfriction.friction.families.registry.register_family`).

A family declares (class attributes) its parameters (their dataclass, a :class:`~.params.ModelParamsBase`, whose
:attr:`~.params.ModelParamsBase.names` are the fit's order; their units), its bounds in the fit's coordinates, and how
its characteristic is linear in some parameters (the variable projection's design:
:attr:`~FrictionFamily.column_factors`); it computes (methods) the characteristic and its Jacobian, its design
columns, and their expectations under a Gaussian velocity noise (errors in variables, :mod:`wbfriction.fit.eiv`).

A family that has no closed form for the expectations inherits a 40-point Gauss-Hermite rule over its own
characteristic (:func:`~.gaussian.hermite_mean`): right for a continuous ``f``, not across a jump (``sgn``), where
the built-in families take closed forms. The smallest family, viscous friction with an offset::

    @dataclass(frozen=True)
    class ViscousParams(ModelParamsBase):
        model: ClassVar[str] = "viscous"
        names: ClassVar[tuple[str, ...]] = ("F_v", "tau_os")
        F_v: float = 0.0
        tau_os: float = 0.0

        def f(self, qd):
            return self.F_v * np.asarray(qd) + self.tau_os

        def quantities(self):
            return {"F_v": self.F_v, "F_c": 0.0, "F_s": 0.0, "S": 0.0, "v_s": float("nan"),
                    "tau_os": self.tau_os, "a": float("inf")}

    class Viscous(FrictionFamily):
        name, params_class = "viscous", ViscousParams
        units = {"F_v": "N·m·s/rad", "tau_os": "N·m"}
        lower, upper = np.array([0.0, -np.inf]), np.array([np.inf, np.inf])
        constant_columns = ("F_v", "tau_os")
        column_factors = (("F_v",), ("tau_os",))

        def values(self, x, qd, delta_s):
            return x[0] * qd + x[1]

        def jacobian(self, x, qd, delta_s):
            return np.column_stack([qd, np.ones_like(qd)])

        def columns(self, qd, delta_s, z, jump=None):
            return np.column_stack([qd, np.ones_like(qd)])

    register_family(Viscous())

Shapes: ``qd`` (N,) [rad/s] (``values`` broadcasts over any shape, the parameters over its last axis); ``x`` the
parameters (P,) in the order of :attr:`~FrictionFamily.names`; ``z`` the same in the fit's coordinates
(:meth:`~FrictionFamily.to_fit`); ``sigma`` the velocity noise's standard deviation [rad/s]; ``delta_s`` the Stribeck
exponent (dimensionless; ignored by a family without one). Sign convention and units: :mod:`wbfriction.friction.models`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Iterable, Mapping
from dataclasses import replace
from typing import ClassVar

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.families.gaussian import SMALL, hermite_mean
from wbfriction.friction.families.names import InvalidFamily
from wbfriction.friction.families.params import ModelParamsBase, ParamLike


class FrictionFamily(ABC):
    """One friction model (module docstring): its parameters, bounds, fit coordinates and variable-projection
    design (class attributes), its characteristic and expectations (methods).

    Attributes:
        name: the family's name (``wbfriction fit --model NAME``, :attr:`~.params.ModelParamsBase.model`).
        equation: the thesis's equations it writes (``3.3 + 3.2``), or "".
        params_class: its parameters' dataclass.
        units: each parameter's unit (``N·m``, ``N·m·s/rad``, ``rad/s``, ``s/rad``, ``1``).
        lower, upper: (P,) bounds in the fit's coordinates (:meth:`bounds`).
        speed_bounded: parameters whose upper bound is the data's largest speed (a Stribeck velocity beyond it is not
            identifiable).
        step_slopes: slopes [s/rad] whose upper bound means a step sharper than the data resolve (a tanh slope): the
            fit tries that bound, the status does not count it (:meth:`~wbfriction.fit.result.FitResult.steps`).
        constant_columns: parameters whose Jacobian column does not depend on the parameters (``qd``, ``sgn(qd)``,
            1): a filtered fit smooths it once.
        column_factors: per design column (:meth:`columns`), the parameters (fit coordinates: the name whose
            position holds it) whose product multiplies it; the characteristic is their sum.
        nonlinear: the parameters the design columns depend on, each a velocity [rad/s] or one of
            :attr:`step_slopes`: what the variable projection searches over.
        jump_column: the design column of the jump (``sgn(qd)``, ``tanh(a qd)``) or None: its expectation is
            computed once per value of :attr:`jump_params`.
        jump_params: the parameters the jump column depends on.
        varying_columns: the design columns, other than the jump's, that depend on :attr:`nonlinear`.
        held_with: pairs ``(a, b)``: ``a`` can be held at a value only with ``b`` held too (``a``'s fit coordinate
            involves ``b``).
    """

    name: ClassVar[str]
    equation: ClassVar[str] = ""
    params_class: ClassVar[type[ModelParamsBase]]
    units: ClassVar[Mapping[str, str]]
    lower: ClassVar[np.ndarray]
    upper: ClassVar[np.ndarray]
    speed_bounded: ClassVar[tuple[str, ...]] = ()
    step_slopes: ClassVar[tuple[str, ...]] = ()
    constant_columns: ClassVar[tuple[str, ...]] = ()
    column_factors: ClassVar[tuple[tuple[str, ...], ...]]
    nonlinear: ClassVar[tuple[str, ...]] = ()
    jump_column: ClassVar[int | None] = None
    jump_params: ClassVar[tuple[str, ...]] = ()
    varying_columns: ClassVar[tuple[int, ...]] = ()
    held_with: ClassVar[tuple[tuple[str, str], ...]] = ()

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r})"

    # what the family is: its parameters, their positions, their bounds

    @property
    def names(self) -> tuple[str, ...]:
        """The parameters' names, in the fit's order."""
        return self.params_class.names

    def index(self, name: str) -> int:
        """The position of parameter ``name`` in :attr:`names` (and in the fit's coordinates).

        Raises:
            ValueError: not one of this family's parameters.
        """
        return self.names.index(name)

    def positions(self, names: Iterable[str]) -> tuple[int, ...]:
        """The positions of ``names`` (:meth:`index`)."""
        return tuple(self.index(n) for n in names)

    def bounds(self, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds (P,) of the parameters in the fit's coordinates for velocities ``qd`` (N,)
        [rad/s]: :attr:`lower`, :attr:`upper`, those of :attr:`speed_bounded` at most the largest speed in ``qd``
        (and twice their lower bound)."""
        lower, upper = self.lower.copy(), self.upper.copy()
        for i in self.positions(self.speed_bounded):
            upper[i] = max(float(np.max(np.abs(qd))), 2 * lower[i])
        return lower, upper

    def check_fixed(self, fixed: Mapping[str, float] | None) -> dict[str, float]:
        """``fixed`` (parameter name: value held) as a dict, checked against :attr:`names` and :attr:`held_with`.

        Raises:
            InputError: a name that is not this family's; a parameter held without the one it goes with.
        """
        fixed = dict(fixed or {})
        if set(fixed) - set(self.names):
            raise InputError(f"unknown parameter(s) of the {self.name} model to fix: "
                             f"{', '.join(sorted(set(fixed) - set(self.names)))}")
        for held, other in self.held_with:
            if held in fixed and other not in fixed:
                raise InputError(f"the {self.name} model's {held} can be held only with {other} held too")
        return fixed

    # parameters as values

    def params(self, x: Iterable[float], delta_s: float = 2.0) -> ModelParamsBase:
        """The parameters of the vector ``x`` (P,) (:meth:`~.params.ModelParamsBase.from_vector`)."""
        return self.params_class.from_vector(x, delta_s)

    def from_quantities(self, quantities: Mapping[str, float]) -> ModelParamsBase:
        """This family's parameters out of ``quantities`` (any family's names, :data:`~.params.ALL_PARAM_NAMES`),
        each taken under its name (the others ignored): e.g. one set of numbers for every family of a study."""
        return self.params_class(**{n: quantities[n] for n in self.names})

    def static_level(self, params: ModelParamsBase) -> float:
        """The static friction F_s [N·m], the level at rest (what Isaac Lab's ``friction`` holds):
        ``quantities()["F_s"]`` (:meth:`~.params.ModelParamsBase.quantities`)."""
        return float(params.quantities()["F_s"])

    def viscous_level(self, params: ModelParamsBase) -> float:
        """The viscous friction F_v [N·m·s/rad] (URDF and MuJoCo ``damping``, Isaac Lab ``viscous_friction``)."""
        return float(params.quantities()["F_v"])

    def coulomb_level(self, params: ModelParamsBase) -> float:
        """The Coulomb friction F_c [N·m], the level in motion (URDF ``friction``, MuJoCo ``frictionloss``)."""
        return float(params.quantities()["F_c"])

    def transitions(self, params: ModelParamsBase) -> dict[str, float]:
        """The speeds [rad/s] at which the shape parameters of ``params`` act, by name (e.g. ``{"v_s": 0.05}``):
        each is a transition of the characteristic that the data must resolve, with samples inside and beyond it,
        for the family to be chosen (:mod:`wbfriction.fit.transition`). The default: none (a family whose shape is
        fixed by its magnitudes, as Coulomb-viscous)."""
        return {}

    # the fit's coordinates

    def to_fit(self, x: np.ndarray) -> np.ndarray:
        """The fit's coordinates (P,) of the parameters ``x`` (P,), a new array (the default: the same values; the
        Stribeck family's F_s becomes F_s - F_c, so that ``F_s >= F_c`` is a bound)."""
        return np.array(x, dtype=float)

    def from_fit(self, z: np.ndarray) -> np.ndarray:
        """The parameters (P,) from the fit's coordinates ``z`` (P,), a new array: the inverse of :meth:`to_fit`."""
        return np.array(z, dtype=float)

    def fit_jacobian(self, jac: np.ndarray) -> np.ndarray:
        """The Jacobian (N, P) in the fit's coordinates from ``jac`` (N, P) in the parameters' (the chain rule of
        :meth:`from_fit`; the default: ``jac`` itself)."""
        return jac

    # the characteristic

    @abstractmethod
    def values(self, x: np.ndarray, qd: np.ndarray, delta_s: ParamLike) -> np.ndarray:
        """``f(qd)`` [N·m] of the parameters ``x``: ``x[i]`` a scalar or an array broadcastable to ``qd``."""

    @abstractmethod
    def jacobian(self, x: np.ndarray, qd: np.ndarray, delta_s: float) -> np.ndarray:
        """Jacobian (N, P) of :meth:`values` with respect to ``x`` at ``qd`` (N,)."""

    @abstractmethod
    def columns(self, qd: np.ndarray, delta_s: float, z: np.ndarray, jump: np.ndarray | None = None) -> np.ndarray:
        """The design columns (N, K) at ``qd`` (N,), their non-linear parameters (:attr:`nonlinear`) read from the
        fit's coordinates ``z`` (P,): the characteristic is their sum, each times the product of its
        :attr:`column_factors`. ``jump``: the jump's column if known (:meth:`jump`)."""

    def jump(self, qd: np.ndarray, z: np.ndarray) -> np.ndarray:
        """The jump's design column (N,) (:attr:`jump_column`; it depends on :attr:`jump_params` alone)."""
        if self.jump_column is None:
            raise InvalidFamily(self.name, "no jump column")
        return self.columns(qd, 2.0, z)[:, self.jump_column]

    # the family as linear in its magnitudes, its non-linear parameters held (the terms beyond velocity)

    def coulomb_shape(self, params: ModelParamsBase, qd: np.ndarray) -> np.ndarray:
        """``g(qd)`` (N,): the shape of the Coulomb level, which a load or temperature term scales
        (:mod:`wbfriction.fit.terms`); ``sgn(qd)`` unless the family smooths it."""
        return np.sign(qd)

    def coulomb_sign(self, params: ModelParamsBase, qd: float) -> float:
        """:meth:`coulomb_shape` of one velocity [rad/s], in plain floats (a simulator's physics step)."""
        return math.copysign(1.0, qd) if qd else 0.0

    def velocity_basis(self, params: ModelParamsBase,
                       qd: np.ndarray) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
        """The characteristic as linear in its coefficients, the non-linear parameters held: ``f(qd) = B c``.

        The default holds for a family linear in every parameter, one per design column (:attr:`column_factors`):
        the coefficients are the parameters themselves.

        Returns:
            ``(names, B, c)``: the coefficients' names, the regressors (N, k) at ``qd`` (N,), the coefficients (k,).

        Raises:
            InvalidFamily: a family with non-linear parameters that does not say how it is linear.
        """
        if self.nonlinear or any(len(f) != 1 for f in self.column_factors):
            raise InvalidFamily(self.name, "its parameters are not one per design column: it must define "
                                "velocity_basis and with_coefficients for the terms beyond velocity")
        names = tuple(f[0] for f in self.column_factors)
        x = params.as_vector()
        return names, self.columns(np.asarray(qd, dtype=float), 2.0, self.to_fit(x)), x[list(self.positions(names))]

    def with_coefficients(self, params: ModelParamsBase, c: np.ndarray) -> ModelParamsBase:
        """``params`` with the linear coefficients ``c`` (k,) of :meth:`velocity_basis` (the non-linear ones
        kept)."""
        names = tuple(f[0] for f in self.column_factors)
        return replace(params, **{n: float(v) for n, v in zip(names, c)})

    # its expectation under a Gaussian velocity noise (module docstring; the model itself for sigma < SMALL)

    def expected_values(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        """``E[f(qd_true) | qd]`` [N·m] at the measured velocities ``qd`` (N,) under a white velocity noise of
        standard deviation ``sigma`` [rad/s]; :meth:`values` for ``sigma`` below
        :data:`~.gaussian.SMALL`."""
        if sigma < SMALL:
            return self.values(x, qd, delta_s)
        return self.mean_values(x, qd, sigma, delta_s)

    def expected_jacobian(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        """Jacobian (N, P) of :meth:`expected_values` with respect to ``x``."""
        if sigma < SMALL:
            return self.jacobian(x, qd, delta_s)
        return self.mean_jacobian(x, qd, sigma, delta_s)

    def expected_columns(self, qd: np.ndarray, sigma: float, delta_s: float, z: np.ndarray,
                         jump: np.ndarray | None = None) -> np.ndarray:
        """:meth:`columns` under the velocity noise: each column's expectation at the measured ``qd`` (N, K);
        ``jump``: the jump's (:meth:`expected_jump`) if known."""
        if sigma < SMALL:
            return self.columns(qd, delta_s, z, jump)
        return self.mean_columns(qd, sigma, delta_s, z, jump)

    def expected_jump(self, qd: np.ndarray, sigma: float, z: np.ndarray) -> np.ndarray:
        """The jump's column of :meth:`expected_columns` (N,): computed once for several values of the other
        non-linear parameters."""
        if sigma < SMALL:
            return self.jump(qd, z)
        return self.mean_jump(qd, sigma, z)

    def mean_values(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        """:meth:`expected_values` for ``sigma >= SMALL`` (the default: Gauss-Hermite over :meth:`values`)."""
        return hermite_mean(lambda u: self.values(x, u, delta_s), qd, sigma)

    def mean_jacobian(self, x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float) -> np.ndarray:
        """:meth:`expected_jacobian` for ``sigma >= SMALL`` (the default: Gauss-Hermite over :meth:`jacobian`,
        the derivative of the mean)."""
        return hermite_mean(lambda u: self.jacobian(x, u, delta_s), qd, sigma)

    def mean_columns(self, qd: np.ndarray, sigma: float, delta_s: float, z: np.ndarray,
                     jump: np.ndarray | None = None) -> np.ndarray:
        """:meth:`expected_columns` for ``sigma >= SMALL`` (the default: Gauss-Hermite over :meth:`columns`)."""
        out = hermite_mean(lambda u: self.columns(u, delta_s, z), qd, sigma)
        if jump is not None and self.jump_column is not None:
            out[:, self.jump_column] = jump
        return out

    def mean_jump(self, qd: np.ndarray, sigma: float, z: np.ndarray) -> np.ndarray:
        """:meth:`expected_jump` for ``sigma >= SMALL`` (the default: Gauss-Hermite over :meth:`jump`)."""
        return hermite_mean(lambda u: self.jump(u, z), qd, sigma)

    # a definition that holds together

    def validate(self) -> None:
        """Check the class attributes against each other (what :func:`~.registry.register_family` does first).

        Raises:
            InvalidFamily: a missing attribute, a name that is not a parameter's, bounds of another length than the
                parameters or crossed, a column out of range, a design column without factors.
        """
        def fail(problem: str) -> None:
            raise InvalidFamily(getattr(self, "name", type(self).__name__), problem)

        for attribute in ("name", "params_class", "units", "lower", "upper", "column_factors"):
            if not hasattr(self, attribute):
                fail(f"no {attribute}")
        if not self.name or not isinstance(self.name, str):
            fail("its name must be a non-empty string")
        if self.params_class.model != self.name:
            fail(f"its parameters' model is '{self.params_class.model}'")
        names = self.names
        if len(set(names)) != len(names):
            fail(f"parameter names repeated: {', '.join(names)}")
        if set(self.units) != set(names):
            fail(f"units of {', '.join(sorted(self.units))} for the parameters {', '.join(names)}")
        for label, bound in (("lower", self.lower), ("upper", self.upper)):
            if np.shape(bound) != (len(names),):
                fail(f"{label} has {np.size(bound)} bounds for {len(names)} parameters")
        if np.any(np.asarray(self.lower) > np.asarray(self.upper)):
            fail("a lower bound above its upper bound")
        used = {*self.speed_bounded, *self.step_slopes, *self.constant_columns, *self.nonlinear, *self.jump_params,
                *(n for f in self.column_factors for n in f), *(n for pair in self.held_with for n in pair)}
        if used - set(names):
            fail(f"not parameters of its: {', '.join(sorted(used - set(names)))}")
        k = len(self.column_factors)
        if any(not f for f in self.column_factors):
            fail("a design column without factors")
        columns = [*self.varying_columns, *(() if self.jump_column is None else (self.jump_column,))]
        if any(not 0 <= c < k for c in columns):
            fail(f"a design column out of its {k}")
