"""The fit's bounds and coordinates: where each model's parameters may go, and the coordinates the solver moves
them in (thesis 6.2.2), as each family defines them (:class:`~wbfriction.friction.families.base.FrictionFamily`:
its :attr:`~wbfriction.friction.families.base.FrictionFamily.lower` and
:attr:`~wbfriction.friction.families.base.FrictionFamily.upper` bounds,
:meth:`~wbfriction.friction.families.base.FrictionFamily.bounds`,
:meth:`~wbfriction.friction.families.base.FrictionFamily.to_fit`).

The built-in families' bounds keep friction dissipative (F_v, F_c >= 0) and the Stribeck effect a drop from
static to Coulomb friction: (3.5)'s ``S >= 0``, and the Stribeck model's ``F_s >= F_c``, fitted as
``F_s - F_c >= 0`` (its standard error is F_s's own). A parameter that ends on one of its bounds is flagged in
:attr:`~wbfriction.fit.result.FitResult.at_bound` (:data:`AT_BOUND_RTOL`, :data:`AT_BOUND_SSR`): its value is the
bound's, not the data's.
"""

from __future__ import annotations

import numpy as np

from wbfriction.friction.families.registry import family
from wbfriction.friction.models import ModelName

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


def model_bounds(qd: np.ndarray, model: ModelName = "thesis") -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of ``model``'s parameters, in the fit's coordinates, for velocities
    ``qd`` (N,) [rad/s] (:meth:`~wbfriction.friction.families.base.FrictionFamily.bounds`):
    for (3.5) those of :data:`~wbfriction.friction.families.thesis.UPPER`; for ``coulomb-viscous`` F_v, F_c >= 0;
    for ``stribeck`` F_v, F_c >= 0, ``F_s >= F_c`` (its coordinate is F_s - F_c >= 0) and v_s in [1e-4, 100];
    ``v_s`` at most the largest speed in ``qd``."""
    return family(model).bounds(qd)


def to_fit_coordinates(model: ModelName, x: np.ndarray) -> np.ndarray:
    """The fit's coordinates of ``model``'s parameters ``x`` (P,) (in the order of its names, e.g.
    :data:`~wbfriction.friction.models.STRIBECK_NAMES`): the Stribeck model's F_s becomes F_s - F_c, so
    that ``F_s >= F_c`` is a bound; the others as they are."""
    return family(model).to_fit(x)


def from_fit_coordinates(model: ModelName, z: np.ndarray) -> np.ndarray:
    """The model's parameters (P,) from the fit's coordinates ``z`` (P,): inverse of :func:`to_fit_coordinates`."""
    return family(model).from_fit(z)


def fit_coordinates_jacobian(model: ModelName, jac: np.ndarray) -> np.ndarray:
    """The Jacobian (N, P) in the fit's coordinates from ``jac`` (N, P) in the model's (the chain rule of
    :func:`from_fit_coordinates`)."""
    return family(model).fit_jacobian(jac)
