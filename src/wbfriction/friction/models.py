"""Static friction models (thesis chapter 3), vectorised over samples and joints: the friction families of
:mod:`wbfriction.friction.families` by name, and what the rest of the package reads of them.

Sign convention (the one used everywhere in wbfriction):

* ``tau_f`` is the torque friction exerts **on the joint**. It enters the equation of
  motion as ``M qdd + h = S^T (tau + tau_f) + J^T lambda``, so a dissipative friction
  has ``qd * tau_f <= 0`` (thesis eq. 7.9).
* The models below return the thesis's friction characteristic ``f(qd)``, which points
  along the velocity: ``tau_f = -f(qd)``. Fitted parameters are therefore positive for
  dissipative friction (F_c, F_v > 0), as in the thesis's Tables 6.1 and 6.2.

Three families are built in (:data:`MODEL_NAMES`, simplest first), each with the offset
``tau_os`` of (3.4) (calibration errors of the torque sensing):

* ``coulomb-viscous``: Coulomb (3.1) plus viscous (3.2) friction,
  ``f = F_v qd + F_c sgn(qd) + tau_os`` (:class:`CoulombViscousParams`,
  :mod:`~wbfriction.friction.families.coulomb_viscous`);
* ``stribeck``: Coulomb friction with the Stribeck effect (3.3) plus viscous friction,
  ``f = F_v qd + sgn(qd) (F_c + (F_s - F_c) exp(-|qd / v_s|^delta_s)) + tau_os``
  (:class:`StribeckParams`; F_s the static friction, the level at rest; :mod:`~wbfriction.friction.families.stribeck`);
* ``thesis``: the smooth model (3.5) the thesis simulates and fits, which writes the static
  friction ``F_s = (1 + S) F_c`` and replaces ``sgn(qd)`` by ``tanh(a qd)``
  (:class:`FrictionParams`, :mod:`~wbfriction.friction.families.thesis`).

Another family plugs in with :func:`~wbfriction.friction.families.registry.register_family`: the functions below
that take a model's name take its name too.

All functions broadcast: ``qd`` may be (N,), (N, n_joints), ...; parameters are scalars
or arrays broadcastable to ``qd`` (e.g. shape (n_joints,)).

Units: qd [rad/s]; F_c, F_s, tau_os [N·m]; F_v [N·m·s/rad]; v_s [rad/s]; a [s/rad];
S and delta_s dimensionless.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import cast

import numpy as np

from wbfriction.friction.families.coulomb_viscous import (
    COULOMB_VISCOUS_NAMES,
    CoulombViscousParams,
    coulomb,
    coulomb_viscous,
    viscous,
)
from wbfriction.friction.families.names import BUILTIN_NAMES
from wbfriction.friction.families.params import ALL_PARAM_NAMES, ModelParamsBase, ParamLike, ParamsT
from wbfriction.friction.families.registry import check_family, family
from wbfriction.friction.families.stribeck import STRIBECK_NAMES, StribeckParams, stribeck, stribeck_viscous
from wbfriction.friction.families.thesis import PARAM_NAMES, FrictionParams, coulomb_viscous_stribeck

__all__ = ["ALL_PARAM_NAMES", "COULOMB_VISCOUS_NAMES", "MODEL_NAMES", "PARAM_NAMES", "STRIBECK_NAMES",
           "CoulombViscousParams", "FrictionParams", "ModelName", "ModelParams", "ModelParamsBase", "ParamLike",
           "ParamsT", "StribeckParams", "check_model", "coulomb", "coulomb_viscous", "coulomb_viscous_stribeck",
           "friction_torque", "model_columns", "model_jacobian", "model_values", "params_from_dict", "stack_params",
           "stribeck", "stribeck_viscous", "target_from_dict", "viscous"]

ModelName = str
"""A friction family's name: one of :data:`MODEL_NAMES` (Coulomb-viscous (3.1 + 3.2), Coulomb-Stribeck-viscous
(3.3 + 3.2), the thesis's smooth model (3.5); each with an offset ``tau_os``), or one registered
(:func:`~wbfriction.friction.families.registry.family_names`)."""

MODEL_NAMES: tuple[ModelName, ...] = BUILTIN_NAMES
"""The built-in families, simplest (fewest parameters) first."""

ModelParams = CoulombViscousParams | StribeckParams | FrictionParams
"""The parameters of one joint under any of the built-in families (another family's derive from
:class:`ModelParamsBase` too)."""


def model_values(x: np.ndarray, qd: np.ndarray, delta_s: ParamLike, model: ModelName = "thesis") -> np.ndarray:
    """``model``'s ``f(qd)`` [N·m] for the parameter vector ``x`` in the order of its names
    (:data:`PARAM_NAMES` for (3.5)), ``qd`` (N,) [rad/s]
    (:meth:`~wbfriction.friction.families.base.FrictionFamily.values`).

    Raises:
        UnknownFamilyError: no family of that name.
    """
    return family(model).values(x, qd, delta_s)


def model_columns(qd: np.ndarray, delta_s: float, model: ModelName, z: np.ndarray,
                  jump: np.ndarray | None = None) -> np.ndarray:
    """The design columns (N, K) of ``model``'s terms at velocities ``qd`` (N,) [rad/s], its non-linear parameters
    (the Stribeck velocity ``v_s``, the tanh slope ``a``) read from the fit's coordinates ``z`` (P,): the model is
    their sum, each times a product of its linear parameters
    (:attr:`~wbfriction.friction.families.base.FrictionFamily.column_factors`):

    * ``coulomb-viscous``: ``qd``, ``sgn(qd)``, 1 (times F_v, F_c, tau_os);
    * ``stribeck``: ``qd``, ``sgn(qd)``, ``sgn(qd) e``, 1 (times F_v, F_c, F_s - F_c, tau_os);
    * ``thesis`` (3.5): ``qd``, ``tanh(a qd)``, ``tanh(a qd) e``, 1 (times F_v, F_c, F_c S, tau_os);

    with ``e = exp(-|qd / v_s|^delta_s)``; ``jump``: the column of ``sgn(qd)`` or ``tanh(a qd)`` if known."""
    return family(model).columns(qd, delta_s, z, jump)


def model_jacobian(x: np.ndarray, qd: np.ndarray, delta_s: float, model: ModelName = "thesis") -> np.ndarray:
    """Jacobian (N, p) of :func:`model_values` with respect to ``x``, analytic."""
    return family(model).jacobian(x, qd, delta_s)


def check_model(model: str, what: str = "model") -> ModelName:
    """``model`` if it is a family's name (:func:`~wbfriction.friction.families.registry.check_family`).

    Raises:
        UnknownFamilyError: not a family's (named as ``what``, with the families known).
    """
    return check_family(model, what)


def params_from_dict(model: str, d: Mapping[str, object]) -> ModelParams:
    """Parameters of ``model`` from a mapping of their names (:meth:`ModelParamsBase.from_dict`; typed as a built-in
    family's, whose names the rest of the package reads: another family's parameters have them too where it reads
    them).

    Raises:
        InputError: an unknown model, an unknown parameter name, a value that is not a number.
    """
    return cast(ModelParams, family(check_model(model)).params_class.from_dict(d))


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
