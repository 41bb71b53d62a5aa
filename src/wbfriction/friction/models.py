"""Static friction models (thesis chapter 3), vectorised over samples and joints.

Sign convention (the one used everywhere in wbfriction):

* ``tau_f`` is the torque friction exerts **on the joint**. It enters the equation of
  motion as ``M qdd + h = S^T (tau + tau_f) + J^T lambda``, so a dissipative friction
  has ``qd * tau_f <= 0`` (thesis eq. 7.9).
* The models below return the thesis's friction characteristic ``f(qd)``, which points
  along the velocity: ``tau_f = -f(qd)``. Fitted parameters are therefore positive for
  dissipative friction (F_c, F_v > 0), as in the thesis's Tables 6.1 and 6.2.

Three models are fitted (:data:`MODEL_NAMES`, simplest first), each with the offset
``tau_os`` of (3.4) (calibration errors of the torque sensing):

* ``coulomb-viscous``: Coulomb (3.1) plus viscous (3.2) friction,
  ``f = F_v qd + F_c sgn(qd) + tau_os`` (:class:`CoulombViscousParams`);
* ``stribeck``: Coulomb friction with the Stribeck effect (3.3) plus viscous friction,
  ``f = F_v qd + sgn(qd) (F_c + (F_s - F_c) exp(-|qd / v_s|^delta_s)) + tau_os``
  (:class:`StribeckParams`; F_s the static friction, the level at rest);
* ``thesis``: the smooth model (3.5) the thesis simulates and fits, which writes the static
  friction ``F_s = (1 + S) F_c`` and replaces ``sgn(qd)`` by ``tanh(a qd)``
  (:class:`FrictionParams`).

All functions broadcast: ``qd`` may be (N,), (N, n_joints), ...; parameters are scalars
or arrays broadcastable to ``qd`` (e.g. shape (n_joints,)).

Units: qd [rad/s]; F_c, F_s, tau_os [N·m]; F_v [N·m·s/rad]; v_s [rad/s]; a [s/rad];
S and delta_s dimensionless.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, fields
from typing import ClassVar, Literal, TypeVar, cast, get_args

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.exceptions import InputError

ModelName = Literal["coulomb-viscous", "stribeck", "thesis"]
"""A friction model: Coulomb-viscous (3.1 + 3.2), Coulomb-Stribeck-viscous (3.3 + 3.2), or the
thesis's smooth model (3.5); each with an offset ``tau_os`` (module docstring)."""

MODEL_NAMES: tuple[ModelName, ...] = get_args(ModelName)
"""The models, simplest (fewest parameters) first."""

PARAM_NAMES = ("F_v", "F_c", "S", "v_s", "tau_os", "a")
"""Names of the fitted parameters of model (3.5), in the order used by the fit."""

COULOMB_VISCOUS_NAMES = ("F_v", "F_c", "tau_os")
"""Names of the parameters of the Coulomb-viscous model, in the order used by the fit."""

STRIBECK_NAMES = ("F_v", "F_c", "F_s", "v_s", "tau_os")
"""Names of the parameters of the Coulomb-Stribeck-viscous model, in the order used by the fit."""

ALL_PARAM_NAMES = ("F_v", "F_c", "F_s", "S", "v_s", "tau_os", "a")
"""Every model's parameter names, in one order (e.g. the columns of a table of several models)."""

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


def coulomb_viscous(qd: ArrayLike, F_v: ParamLike, F_c: ParamLike, tau_os: ParamLike) -> np.ndarray:
    """Coulomb (3.1) plus viscous (3.2) friction with offset: ``f = F_v qd + F_c sgn(qd) + tau_os``
    (``sgn(0) = 0``)."""
    return viscous(qd, F_v) + coulomb(qd, F_c) + np.asarray(tau_os)


def stribeck_viscous(qd: ArrayLike, F_v: ParamLike, F_c: ParamLike, F_s: ParamLike, v_s: ParamLike,
                     tau_os: ParamLike, delta_s: ParamLike = 2.0) -> np.ndarray:
    """Coulomb friction with the Stribeck effect (3.3) plus viscous friction (3.2), with offset:
    ``f = F_v qd + sgn(qd) (F_c + (F_s - F_c) exp(-|qd / v_s|^delta_s)) + tau_os``."""
    return viscous(qd, F_v) + stribeck(qd, F_c, F_s, v_s, delta_s) + np.asarray(tau_os)


def model_values(x: np.ndarray, qd: np.ndarray, delta_s: ParamLike, model: ModelName = "thesis") -> np.ndarray:
    """``model``'s ``f(qd)`` [N·m] for the parameter vector ``x`` in the order of its names
    (:data:`~wbfriction.friction.models.PARAM_NAMES` for (3.5)), ``qd`` (N,) [rad/s]."""
    if model == "coulomb-viscous":
        return coulomb_viscous(qd, x[0], x[1], x[2])
    if model == "stribeck":
        return stribeck_viscous(qd, x[0], x[1], x[2], x[3], x[4], delta_s)
    return coulomb_viscous_stribeck(qd, x[0], x[1], x[2], x[3], x[4], x[5], delta_s)


def model_columns(qd: np.ndarray, delta_s: float, model: ModelName = "thesis", v_s: float = 1.0,
                  a: float = 1.0, jump: np.ndarray | None = None) -> np.ndarray:
    """The columns (N, K) of ``model``'s terms at velocities ``qd`` (N,) [rad/s]: the model is their sum, each
    times a product of its linear parameters (:data:`~wbfriction.fit.projection.TERMS`), once the Stribeck
    velocity ``v_s`` [rad/s] and the tanh slope ``a`` [s/rad] are set (ignored where the model has none):

    * ``coulomb-viscous``: ``qd``, ``sgn(qd)``, 1 (times F_v, F_c, tau_os);
    * ``stribeck``: ``qd``, ``sgn(qd)``, ``sgn(qd) e``, 1 (times F_v, F_c, F_s - F_c, tau_os);
    * ``thesis`` (3.5): ``qd``, ``tanh(a qd)``, ``tanh(a qd) e``, 1 (times F_v, F_c, F_c S, tau_os);

    with ``e = exp(-|qd / v_s|^delta_s)``; ``jump``: the column of ``sgn(qd)`` or ``tanh(a qd)`` if known."""
    qd = np.asarray(qd, dtype=float)
    one = np.ones_like(qd)
    if model == "coulomb-viscous":
        return np.column_stack([qd, np.sign(qd), one])
    e = np.exp(-np.abs(qd / v_s) ** delta_s)
    if jump is None:
        jump = np.sign(qd) if model == "stribeck" else np.tanh(a * qd)
    return np.column_stack([qd, jump, jump * e, one])


def model_jacobian(x: np.ndarray, qd: np.ndarray, delta_s: float, model: ModelName = "thesis") -> np.ndarray:
    """Jacobian (N, p) of :func:`model_values` with respect to ``x``, analytic."""
    J = np.empty((qd.size, len(MODEL_PARAMS[model].names)))
    J[:, 0] = qd  # F_v
    J[:, -1 if model == "coulomb-viscous" else 4] = 1.0  # tau_os
    if model == "coulomb-viscous":
        J[:, 1] = np.sign(qd)
        return J
    u = np.abs(qd / x[3])  # |qd / v_s|
    ud = u**delta_s
    e = np.exp(-ud)
    if model == "stribeck":
        _, F_c, F_s, v_s, _ = x
        sgn = np.sign(qd)
        J[:, 1] = sgn * (1.0 - e)
        J[:, 2] = sgn * e
        J[:, 3] = sgn * (F_s - F_c) * e * delta_s * ud / v_s
        return J
    _, F_c, S, v_s, _, a = x
    th = np.tanh(a * qd)
    J[:, 1] = th * (1.0 + S * e)
    J[:, 2] = F_c * th * e
    # d/dv_s of exp(-(|qd|/v_s)^d) = e * d * u^d / v_s
    J[:, 3] = F_c * th * S * e * delta_s * ud / v_s
    J[:, 5] = F_c * (1.0 - th**2) * qd * (1.0 + S * e)
    return J


ParamsT = TypeVar("ParamsT", bound="ModelParamsBase")
"""Any of the models' parameter classes."""


@dataclass(frozen=True)
class ModelParamsBase:
    """What the parameter sets of the models share: their model's name, their fitted
    parameters' names (in the fit's order), ``f``, ``torque`` and conversions."""

    model: ClassVar[ModelName]
    names: ClassVar[tuple[str, ...]]

    def f(self, qd: ArrayLike) -> np.ndarray:
        """Friction characteristic ``f(qd)`` [N·m] (``qd`` [rad/s], any shape)."""
        raise NotImplementedError

    def quantities(self) -> dict[str, float]:
        """Every model's parameters in this model's terms (:data:`ALL_PARAM_NAMES`): what a fit of any model is
        compared with (:meth:`values_in`); a quantity this model does not have is NaN (a Stribeck velocity without
        a Stribeck effect), a jump this model makes is a tanh slope ``a = inf``."""
        raise NotImplementedError

    def values_in(self, model: ModelName) -> dict[str, float]:
        """These parameters under the names of ``model``'s (:meth:`quantities`), e.g. an injected friction of one
        model against a fit of another."""
        q = self.quantities()
        return {n: q[n] for n in MODEL_PARAMS[model].names}

    def to_target(self) -> dict[str, float | str]:
        """These parameters and their model's name, as a simulator's ``friction_true`` metadata holds them
        (:func:`target_from_dict` reads them back)."""
        return {"model": self.model, **self.to_dict()}

    def torque(self, qd: ArrayLike) -> np.ndarray:
        """Torque friction exerts on the joint, ``tau_f = -f(qd)`` [N·m]."""
        return -self.f(qd)

    def as_vector(self) -> np.ndarray:
        """The fitted parameters in :attr:`names` order."""
        return np.array([getattr(self, n) for n in self.names])

    @classmethod
    def from_vector(cls: type[ParamsT], x: Iterable[float], delta_s: float = 2.0) -> ParamsT:
        """Parameters from the fitted values in :attr:`names` order (and the Stribeck exponent
        ``delta_s``, for the models that have one)."""
        values = dict(zip(cls.names, map(float, x), strict=True))
        if "delta_s" in {f.name for f in fields(cls)}:
            values["delta_s"] = float(delta_s)
        return cls(**values)

    def to_dict(self) -> dict[str, float]:
        """Every parameter by name (the inverse of :meth:`from_dict`)."""
        return asdict(self)

    @classmethod
    def from_dict(cls: type[ParamsT], d: Mapping[str, object]) -> ParamsT:
        """Parameters from a mapping of their names (missing ones take the defaults).

        Raises:
            InputError: an unknown name, or a value that is not a number.
        """
        names = {f.name for f in fields(cls)}
        unknown = set(d) - names
        if unknown:
            raise InputError(f"unknown friction parameter(s) of the {cls.model} model: {', '.join(sorted(unknown))}")
        try:
            return cls(**{k: float(cast(float, v)) for k, v in d.items()})
        except (TypeError, ValueError) as exc:
            raise InputError(str(exc)) from None


@dataclass(frozen=True)
class CoulombViscousParams(ModelParamsBase):
    """Parameters of the Coulomb-viscous model with offset, (3.1) + (3.2), for one joint
    (units in the module docstring)."""

    model: ClassVar[ModelName] = "coulomb-viscous"
    names: ClassVar[tuple[str, ...]] = COULOMB_VISCOUS_NAMES

    F_v: float = 0.0
    F_c: float = 0.0
    tau_os: float = 0.0

    def f(self, qd: ArrayLike) -> np.ndarray:
        """Friction characteristic ``f(qd) = F_v qd + F_c sgn(qd) + tau_os`` [N·m]."""
        return coulomb_viscous(qd, self.F_v, self.F_c, self.tau_os)

    def quantities(self) -> dict[str, float]:
        """:meth:`ModelParamsBase.quantities`: no Stribeck effect (``F_s = F_c``, ``S = 0``), a sign function."""
        return {"F_v": self.F_v, "F_c": self.F_c, "F_s": self.F_c, "S": 0.0, "v_s": float("nan"),
                "tau_os": self.tau_os, "a": float("inf")}


@dataclass(frozen=True)
class StribeckParams(ModelParamsBase):
    """Parameters of the Coulomb-Stribeck-viscous model with offset, (3.3) + (3.2), for one
    joint: static friction ``F_s`` (at rest), Coulomb friction ``F_c`` (beyond the Stribeck
    velocity ``v_s``), viscous ``F_v``, offset ``tau_os`` (units in the module docstring)."""

    model: ClassVar[ModelName] = "stribeck"
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


@dataclass(frozen=True)
class FrictionParams(ModelParamsBase):
    """Parameters of model (3.5) for one joint (units in the module docstring)."""

    model: ClassVar[ModelName] = "thesis"
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


ModelParams = CoulombViscousParams | StribeckParams | FrictionParams
"""The parameters of one joint under any of the models."""

MODEL_PARAMS: dict[ModelName, type[ModelParams]] = {
    "coulomb-viscous": CoulombViscousParams, "stribeck": StribeckParams, "thesis": FrictionParams}
"""The parameter class of each model."""


def check_model(model: str, what: str = "model") -> ModelName:
    """``model`` as a :data:`ModelName`.

    Raises:
        InputError: not one of :data:`MODEL_NAMES` (named as ``what``).
    """
    if model not in MODEL_NAMES:
        raise InputError(f"{what} must be one of {', '.join(MODEL_NAMES)}, got '{model}'")
    return cast(ModelName, model)


def params_from_dict(model: str, d: Mapping[str, object]) -> ModelParams:
    """Parameters of ``model`` from a mapping of their names (:meth:`ModelParamsBase.from_dict`).

    Raises:
        InputError: an unknown model, an unknown parameter name, a value that is not a number.
    """
    return MODEL_PARAMS[check_model(model)].from_dict(d)


def target_from_dict(d: Mapping[str, object]) -> ModelParams:
    """Parameters of any model from a ``friction_true`` entry (:meth:`ModelParamsBase.to_target`); without a
    ``model`` key (logs of earlier versions), of (3.5).

    Raises:
        InputError: an unknown model, an unknown parameter name, a value that is not a number.
    """
    values = dict(d)
    return params_from_dict(str(values.pop("model", "thesis")), values)


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
