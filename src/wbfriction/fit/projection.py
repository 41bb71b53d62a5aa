"""Variable projection: the friction fit's start from its non-linear parameters alone (issue 41).

Every model of :mod:`wbfriction.friction.models` is a sum of terms: a column that depends at most on the Stribeck
velocity ``v_s`` and the tanh slope ``a`` (:func:`~wbfriction.friction.models.model_columns`, its expectation under
the velocity noise :func:`~wbfriction.fit.eiv.expected_columns`), times a product of the linear parameters
(:data:`TERMS`). Model (3.5), for instance, is
``F_v qd + F_c tanh(a qd) + (F_c S) tanh(a qd) exp(-|qd / v_s|^delta_s) + tau_os``: linear in
``(F_v, F_c, F_c S, tau_os)`` once ``(v_s, a)`` is set. The least-squares fit over every parameter is then one over
``(v_s, a)`` alone of the residual the linear solve leaves (Golub and Pereyra, "The differentiation of pseudo-inverses
and nonlinear least squares problems whose variables separate", SIAM J. Numer. Anal. 10(2), 1973): a problem of two
parameters (one for the Stribeck model, none for the Coulomb-viscous one), each of its evaluations an exact bounded
linear solve (F_v, F_c, F_s - F_c, F_c S >= 0).

:func:`projected_start` searches it: a coarse grid over ``log (v_s, a)`` (:data:`GRID` points a parameter) marks the
basins (the grid's local minima), a bounded least-squares search refines the best :data:`BASINS` of them, and the
best is returned, in the fit's coordinates, as the start of the fit over every parameter
(:func:`wbfriction.fit.selection.fit_friction`), which then converges in a few iterations and gives the Jacobian of
the standard errors. The grid replaces random multi-starts: it is the same for every joint of a given speed.

Parameters held at a value (``fit_friction``'s ``fixed``) leave the product of the others in each term: a term whose
parameters are all held is subtracted from the data, terms left with the same free parameters share an unknown
(:func:`linear_part`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wbfriction.fit.eiv import expected_columns, expected_jump
from wbfriction.fit.smoothing import row_smoothing
from wbfriction.friction.models import ModelName

TERMS: dict[ModelName, tuple[tuple[int, ...], ...]] = {
    "coulomb-viscous": ((0,), (1,), (2,)),
    "stribeck": ((0,), (1,), (2,), (4,)),
    "thesis": ((0,), (1,), (1, 2), (4,)),
}
"""The parameters (positions in the fit's coordinates, :func:`~wbfriction.fit.coordinates.to_fit_coordinates`) whose
product multiplies each column of :func:`~wbfriction.friction.models.model_columns`: (3.5)'s Stribeck term is
``F_c S`` times its column, the Stribeck model's ``F_s - F_c``."""

NONLINEAR: dict[ModelName, tuple[int, ...]] = {"coulomb-viscous": (), "stribeck": (3,), "thesis": (3, 5)}
"""Positions of ``v_s`` and ``a`` (the parameters the columns depend on) in the fit's coordinates."""

GRID = 7
"""Grid points per non-linear parameter: ``v_s`` from 0.02 to 1 times the joint's speed (the 90th percentile of
``|qd|``), ``a`` from 1 to 300 over it, evenly in logarithm (and ``a``'s upper bound). Six missed the global
minimum of noise-free (3.5) with a soft jump (``a = 10``) and a Stribeck velocity as narrow as it (0.05 rad/s):
the grid's only two basins both led elsewhere (``tests/friction/test_models.py``)."""

BASINS = 3
"""The grid's local minima refined, best first."""


@dataclass(frozen=True)
class LinearPart:
    """How the linear parameters enter once some are held.

    Attributes:
        unknowns: the free parameters (fit coordinates) whose product is each unknown (U,).
        weights: (K, U) the factor (a product of held values) of column k in unknown u.
        offset: (K,) the factor of column k in the held part of the model (0 where the column has a free parameter).
        lower, upper: (U,) bounds of the unknowns: a parameter's own, or ``[0, inf)`` for a product (its
            parameters are all non-negative).
    """

    unknowns: tuple[tuple[int, ...], ...]
    weights: np.ndarray
    offset: np.ndarray
    lower: np.ndarray
    upper: np.ndarray

    def params(self, c: np.ndarray, held: np.ndarray) -> np.ndarray:
        """The fit's coordinates (P,) with the unknowns ``c`` (U,) put back into ``held`` (P,): a product's other
        parameter divided by the one already known (0 when that one is 0)."""
        z = held.copy()
        known = {i for i in range(z.size)} - {i for u in self.unknowns for i in u}
        for u, value in sorted(zip(self.unknowns, c), key=lambda p: len(p[0])):
            rest = [i for i in u if i not in known]
            if not rest:
                continue
            factor = math.prod(z[i] for i in u if i in known)
            z[rest[0]] = value / factor if factor > 0 else 0.0
            known.add(rest[0])
        return z


def linear_part(model: ModelName, held: np.ndarray, free: np.ndarray, lower: np.ndarray,
                upper: np.ndarray) -> LinearPart:
    """:class:`LinearPart` of ``model`` with the parameters not ``free`` (P,) held at ``held`` (P,) (fit
    coordinates; ``lower``, ``upper`` (P,) their bounds). A product of two free parameters is one unknown (a term
    can have at most two, :data:`TERMS`)."""
    terms = TERMS[model]
    unknowns: list[tuple[int, ...]] = []
    factors: list[tuple[int, int, float]] = []
    offset = np.zeros(len(terms))
    for k, monomial in enumerate(terms):
        free_part = tuple(i for i in monomial if free[i])
        factor = math.prod(float(held[i]) for i in monomial if not free[i])
        if not free_part:
            offset[k] = factor
            continue
        if free_part not in unknowns:
            unknowns.append(free_part)
        factors.append((k, unknowns.index(free_part), factor))
    weights = np.zeros((len(terms), len(unknowns)))
    for k, u, factor in factors:
        weights[k, u] = factor
    lo = np.array([lower[u[0]] if len(u) == 1 else 0.0 for u in unknowns])
    hi = np.array([upper[u[0]] if len(u) == 1 else np.inf for u in unknowns])
    return LinearPart(tuple(unknowns), weights, offset, lo, hi)


def bounded_linear_solve(A: np.ndarray, b: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """``argmin |A c - b|`` over ``lower <= c <= upper`` (U,), for ``A`` (n, U): through the triangular factor of
    ``[A b]`` (a U x U problem), the unconstrained solution where it is feasible, else SciPy's bounded-variable
    least squares on the factor."""
    from scipy.linalg.lapack import dgeqrf
    n = A.shape[1]
    R = dgeqrf(np.column_stack([A, b]))[0][: n + 1]  # LAPACK's QR alone: R in its upper triangle
    R_A, r_b = np.triu(R[:n, :n]), R[:n, n]
    c = np.linalg.lstsq(R_A, r_b, rcond=None)[0]
    if np.all(c >= lower) and np.all(c <= upper):
        return c
    from scipy.optimize import lsq_linear
    return lsq_linear(R_A, r_b, bounds=(lower, upper), method="bvls").x


class Projection:
    """The variable-projection functional of one joint's fit: the residual (n,) the bounded linear solve leaves at
    each ``log (v_s, a)`` (the free ones among them), on the rows fitted, with the model's expectation under the
    velocity noise and, with a smoother, passed through it along the whole series (as
    :func:`~wbfriction.fit.solve.filtered_problem`).

    Args:
        model: the model.
        qd: velocities (N,) [rad/s] (the whole series with a smoother, NaN where left out of it; else the rows used).
        y: ``-tau_f`` (N,) [N·m], as ``qd``.
        rows: the rows fitted (n,) (indices into ``qd``).
        smoother: the estimate's smoother, or None.
        sigma: the velocity noise [rad/s].
        delta_s: the Stribeck exponent.
        held, free: the fit's coordinates (P,) of the held parameters, and which are free (P,) bool.
        lower, upper: the bounds (P,) in the fit's coordinates.

    With a smoother, the columns are computed on the samples the smoother's output on the rows fitted depends on alone
    (:func:`~wbfriction.fit.smoothing.row_smoothing`).
    """

    def __init__(self, model: ModelName, qd: np.ndarray, y: np.ndarray, rows: np.ndarray, smoother, sigma: float,
                 delta_s: float, held: np.ndarray, free: np.ndarray, lower: np.ndarray, upper: np.ndarray):
        self.model, self.rows = model, rows
        self.sigma, self.delta_s, self.held = sigma, delta_s, held
        self.y = y[rows]
        self.smoothing = None if smoother is None else row_smoothing(smoother, qd.size, rows)
        self.qd = qd[rows] if self.smoothing is None else qd[self.smoothing.support]
        self.part = linear_part(model, held, free, lower, upper)
        self.theta = tuple(i for i in NONLINEAR[model] if free[i])
        self.theta_bounds = (np.log(np.maximum(lower[list(self.theta)], 1e-300)), np.log(upper[list(self.theta)]))
        self._ends: np.ndarray | None = None  # the columns qd and 1, on the rows (smoothed)
        self._jump: tuple[float, np.ndarray, np.ndarray] | None = None  # a, its column, on the rows (smoothed)

    def _columns(self, log_theta: np.ndarray) -> np.ndarray:
        """The model's columns (n, K) on the rows fitted at ``log_theta``, smoothed if the fit is; the jump column,
        which depends on ``a`` alone, is kept for the next call (a grid's row, a step in ``v_s``)."""
        z = self.held.copy()
        z[list(self.theta)] = np.exp(log_theta)
        v_s, a = (z[3], z[5]) if self.model == "thesis" else (z[3] if self.model == "stribeck" else 1.0, 1.0)
        if self._jump is None or self._jump[0] != a:
            jump = expected_jump(self.qd, self.sigma, self.model, a)
            self._jump = (a, jump, jump if self.smoothing is None else self.smoothing(jump))
        columns = expected_columns(self.qd, self.sigma, self.delta_s, self.model, v_s, a, jump=self._jump[1])
        if self.smoothing is None:
            return columns
        # qd and 1 (the first and last columns) smoothed once, the jump once for each a
        ends = [0, columns.shape[1] - 1]
        if self._ends is None:
            self._ends = self.smoothing(columns[:, ends])
        out = np.empty((self.rows.size, columns.shape[1]))
        out[:, ends], out[:, 1] = self._ends, self._jump[2]
        if columns.shape[1] == 4:  # the Stribeck column
            out[:, 2] = self.smoothing(columns[:, 2])
        return out

    def solve(self, log_theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The unknowns (U,) of the bounded linear solve at ``log_theta`` and the residual (n,) it leaves (model
        minus data)."""
        columns = self._columns(np.asarray(log_theta, dtype=float))
        A, b = columns @ self.part.weights, self.y - columns @ self.part.offset
        c = bounded_linear_solve(A, b, self.part.lower, self.part.upper)
        return c, A @ c - b

    def residual(self, log_theta: np.ndarray) -> np.ndarray:
        """The residual (n,) at ``log_theta`` (the functional :func:`projected_start` minimises)."""
        return self.solve(log_theta)[1]

    def params(self, log_theta: np.ndarray) -> np.ndarray:
        """The fit's coordinates (P,) at ``log_theta``: the non-linear parameters and the linear solve's."""
        z = self.held.copy()
        z[list(self.theta)] = np.exp(log_theta)
        return self.part.params(self.solve(log_theta)[0], z)


def theta_axes(projection: Projection, speed: float) -> list[np.ndarray]:
    """The grid's axes: ``log v_s`` and ``log a`` (the free ones) for a joint of ``speed`` [rad/s] (:data:`GRID`
    points each, and ``a``'s upper bound), inside the bounds."""
    axes = []
    lo, hi = projection.theta_bounds
    for j, i in enumerate(projection.theta):
        if i == 3:
            values = np.log(np.geomspace(0.02, 1.0, GRID) * speed)
        else:  # and the bound: a jump sharper than the data's sampling (a sign function) runs a there
            values = np.append(np.log(np.geomspace(1.0, 300.0, GRID) / speed), hi[j])
        axes.append(np.unique(np.clip(values, lo[j] + 1e-9, hi[j] - 1e-9)))
    return axes


def grid_minima(costs: np.ndarray) -> np.ndarray:
    """Indices of the local minima of ``costs`` (a grid, any dimension: no neighbour along an axis is lower), best
    first."""
    is_min = np.ones(costs.shape, dtype=bool)
    for axis in range(costs.ndim):
        for step in (1, -1):
            neighbour = np.roll(costs, step, axis=axis)
            edge: list[slice | int] = [slice(None)] * costs.ndim
            edge[axis] = 0 if step == 1 else -1
            neighbour[tuple(edge)] = np.inf
            is_min &= costs <= neighbour
    flat = np.flatnonzero(is_min.ravel())
    return flat[np.argsort(costs.ravel()[flat], kind="stable")]


def projected_start(projection: Projection, speed: float, basins: int = BASINS) -> np.ndarray:
    """The minimum of the variable-projection functional found from the grid's best ``basins`` local minima
    (module docstring), as the fit's coordinates (P,): the start of the fit over every parameter. The search's
    residual is divided by the grid's best (its tolerances relative to it: noise-free data end near zero).

    Args:
        projection: the joint's :class:`Projection`.
        speed: the joint's speed [rad/s] (the grid's scale, at least 1e-3).
        basins: how many of the grid's local minima are refined (:data:`BASINS`; 1 for a joint that hardly moved,
            whose functional is flat wherever it is not noise).
    """
    if not projection.theta:
        return projection.params(np.empty(0))
    from scipy.optimize import least_squares
    axes = theta_axes(projection, max(speed, 1e-3))
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(axes))
    costs = np.empty(len(grid))
    for k in np.argsort(grid[:, -1], kind="stable"):  # a's values in turn: its column computed once for each
        r = projection.residual(grid[k])
        costs[k] = float(r @ r)
    costs = costs.reshape([len(x) for x in axes])
    scale = 1.0 / max(math.sqrt(float(costs.min())), 1e-300)
    best = min((least_squares(lambda t: scale * projection.residual(t), grid[k], bounds=projection.theta_bounds,
                              method="trf", diff_step=1e-7, ftol=1e-12, xtol=1e-10, gtol=1e-14, max_nfev=50)
                for k in grid_minima(costs)[:basins]), key=lambda r: r.cost)
    return projection.params(best.x)

