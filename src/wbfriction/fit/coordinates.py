"""The fit's bounds and coordinates: where each model's parameters may go, and the coordinates the solver moves
them in (thesis 6.2.2).

The bounds (:func:`model_bounds`) keep friction dissipative (F_v, F_c >= 0) and the Stribeck effect a drop from
static to Coulomb friction: (3.5)'s ``S >= 0``, and the Stribeck model's ``F_s >= F_c``, fitted as
``F_s - F_c >= 0`` (its standard error is F_s's own). A parameter that ends on one of its bounds is flagged in
:attr:`~wbfriction.fit.result.FitResult.at_bound` (:data:`AT_BOUND_RTOL`, :data:`AT_BOUND_SSR`): its value is the
bound's, not the data's.
"""

from __future__ import annotations

import numpy as np

from wbfriction.friction.models import (
    ModelName,
)

AT_BOUND_RTOL = 1e-6
"""A parameter within ``AT_BOUND_RTOL * max(1, |bound|)`` of a bound is at it."""


AT_BOUND_SSR = 0.01
"""An identifiable parameter is also at a bound when moving it there raises the sum of squared
residuals by less than ``AT_BOUND_SSR`` residual variances (for a linear model: it is less than
``sqrt(AT_BOUND_SSR) = 0.1`` standard errors from it); the solver's iterates stay strictly inside
the bounds and may stop short of one in a flat direction (e.g. S = 49.97 of 50)."""


AT_BOUND_NEAR = 1e-3
"""A parameter the data do not identify (infinite standard error) is at a bound within
``AT_BOUND_NEAR * max(1, |bound|)`` of it."""


LOWER = np.array([0.0, 0.0, 0.0, 1e-4, -np.inf, 1e-2])


UPPER = np.array([np.inf, np.inf, 50.0, 100.0, np.inf, 1e4])
"""Bounds of (F_v, F_c, S, v_s, tau_os, a) of model (3.5): dissipative viscous and Coulomb parts, static
friction at least the Coulomb level (S >= 0: the Stribeck effect is a drop from static to
Coulomb friction), positive Stribeck velocity and tanh slope. The fit further bounds ``v_s``
by the largest speed in the data: a Stribeck velocity beyond it is not identifiable, and
the Stribeck term would otherwise mimic viscous friction (S < 0, v_s large)."""


BOUNDS: dict[ModelName, tuple[np.ndarray, np.ndarray]] = {
    "coulomb-viscous": (np.array([0.0, 0.0, -np.inf]), np.array([np.inf, np.inf, np.inf])),
    # the fit's coordinates: F_s is fitted as the Stribeck drop F_s - F_c >= 0 (module docstring)
    "stribeck": (np.array([0.0, 0.0, 0.0, 1e-4, -np.inf]), np.array([np.inf, np.inf, np.inf, 100.0, np.inf])),
    "thesis": (LOWER, UPPER),
}


STEP_SLOPES = ("a",)
"""Slopes whose upper bound means a step (:meth:`FitResult.steps`)."""


_V_S = {"coulomb-viscous": None, "stribeck": 3, "thesis": 3}  # position of v_s, bounded by the data's speed


FIXED_COLUMNS: dict[ModelName, tuple[int, ...]] = {
    "coulomb-viscous": (0, 1, 2), "stribeck": (0, 4), "thesis": (0, 4)}
"""Columns of :func:`model_jacobian` that do not depend on the parameters: the model is linear in
those (F_v: ``qd``; F_c of the Coulomb-viscous model: ``sgn(qd)``; tau_os: 1)."""


def model_bounds(qd: np.ndarray, model: ModelName = "thesis") -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of ``model``'s parameters, in the fit's coordinates, for velocities
    ``qd`` (N,) [rad/s]: :data:`LOWER`, :data:`UPPER` for (3.5); for ``coulomb-viscous``
    F_v, F_c >= 0; for ``stribeck`` F_v, F_c >= 0, ``F_s >= F_c`` (its coordinate is F_s - F_c >= 0)
    and v_s in [1e-4, 100]; ``v_s`` at most the largest speed in ``qd``."""
    lower, upper = (b.copy() for b in BOUNDS[model])
    i = _V_S[model]
    if i is not None:
        upper[i] = max(float(np.max(np.abs(qd))), 2 * lower[i])
    return lower, upper


def to_fit_coordinates(model: ModelName, x: np.ndarray) -> np.ndarray:
    """The fit's coordinates of ``model``'s parameters ``x`` (P,) (in the order of its names, e.g.
    :data:`~wbfriction.friction.models.STRIBECK_NAMES`): the Stribeck model's F_s becomes F_s - F_c, so
    that ``F_s >= F_c`` is a bound; the others as they are."""
    z = np.array(x, dtype=float)
    if model == "stribeck":
        z[2] = x[2] - x[1]
    return z


def from_fit_coordinates(model: ModelName, z: np.ndarray) -> np.ndarray:
    """The model's parameters (P,) from the fit's coordinates ``z`` (P,): inverse of :func:`to_fit_coordinates`."""
    x = np.array(z, dtype=float)
    if model == "stribeck":
        x[2] = z[1] + z[2]
    return x


def fit_coordinates_jacobian(model: ModelName, jac: np.ndarray) -> np.ndarray:
    """The Jacobian (N, P) in the fit's coordinates from ``jac`` (N, P) in the model's (the chain rule of
    :func:`from_fit_coordinates`)."""
    if model == "stribeck":
        jac = jac.copy()
        jac[:, 1] += jac[:, 2]
    return jac
