"""Variable projection: the friction fit's start from its non-linear parameters alone (issue 41).

Every friction family (:mod:`wbfriction.friction.families`) is a sum of terms: a design column that depends at most on
the family's non-linear parameters (:attr:`~wbfriction.friction.families.base.FrictionFamily.nonlinear`: the Stribeck
velocity ``v_s`` and the tanh slope ``a`` of the built-in ones;
:meth:`~wbfriction.friction.families.base.FrictionFamily.columns`, its expectation under the velocity noise
:meth:`~wbfriction.friction.families.base.FrictionFamily.expected_columns`), times a product of the linear parameters
(:attr:`~wbfriction.friction.families.base.FrictionFamily.column_factors`). Model (3.5), for instance, is
``F_v qd + F_c tanh(a qd) + (F_c S) tanh(a qd) exp(-|qd / v_s|^delta_s) + tau_os``: linear in
``(F_v, F_c, F_c S, tau_os)`` once ``(v_s, a)`` is set. The least-squares fit over every parameter is then one over
``(v_s, a)`` alone of the residual the linear solve leaves (Golub and Pereyra, "The differentiation of pseudo-inverses
and nonlinear least squares problems whose variables separate", SIAM J. Numer. Anal. 10(2), 1973): a problem of two
parameters (one for the Stribeck model, none for the Coulomb-viscous one), each of its evaluations an exact bounded
linear solve (F_v, F_c, F_s - F_c, F_c S >= 0).

:func:`projected_start` searches it: a coarse grid over the logarithms of the non-linear parameters (:data:`GRID`
points a parameter) marks the basins (the grid's local minima), a bounded least-squares search refines the best
:data:`BASINS` of them, and the best is returned, in the fit's coordinates, as the start of the fit over every
parameter (:func:`wbfriction.fit.selection.fit_friction`), which then converges in a few iterations and gives the
Jacobian of the standard errors. The grid replaces random multi-starts: it is the same for every joint of a given
speed.

Parameters held at a value (``fit_friction``'s ``fixed``) leave the product of the others in each term: a term whose
parameters are all held is subtracted from the data, terms left with the same free parameters share an unknown
(:func:`linear_part`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wbfriction.fit.smoothing import row_smoothing
from wbfriction.friction.families.base import FrictionFamily
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import ModelName

GRID = 7
"""Grid points per non-linear parameter: a velocity (``v_s``) from 0.02 to 1 times the joint's speed (the 90th
percentile of ``|qd|``), a slope (``a``, one of the family's
:attr:`~wbfriction.friction.families.base.FrictionFamily.step_slopes`) from 1 to 300 over it, evenly in logarithm
(and the slope's upper bound). Six missed the global
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


def factor_positions(fam: FrictionFamily) -> tuple[tuple[int, ...], ...]:
    """Per design column of ``fam``, the positions (fit coordinates) of the parameters whose product multiplies it
    (:attr:`~wbfriction.friction.families.base.FrictionFamily.column_factors`): (3.5)'s Stribeck term is ``F_c S``
    times its column, the Stribeck model's ``F_s - F_c``."""
    return tuple(fam.positions(f) for f in fam.column_factors)


def linear_part(model: ModelName, held: np.ndarray, free: np.ndarray, lower: np.ndarray,
                upper: np.ndarray) -> LinearPart:
    """:class:`LinearPart` of ``model`` with the parameters not ``free`` (P,) held at ``held`` (P,) (fit
    coordinates; ``lower``, ``upper`` (P,) their bounds). A product of two free parameters is one unknown (a term
    can have at most two, :func:`factor_positions`)."""
    terms = factor_positions(family(model))
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
    each logarithm of the non-linear parameters (the free ones among them), on the rows fitted, with the model's
    expectation under the velocity noise and, with a smoother, passed through it along the whole series (as
    :func:`~wbfriction.fit.solve.filtered_problem`).

    Args:
        model: the model (a family's name).
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

    Raises:
        UnknownFamilyError: no family named ``model``.
    """

    def __init__(self, model: ModelName, qd: np.ndarray, y: np.ndarray, rows: np.ndarray, smoother, sigma: float,
                 delta_s: float, held: np.ndarray, free: np.ndarray, lower: np.ndarray, upper: np.ndarray):
        self.family = fam = family(model)
        self.model, self.rows = model, rows
        self.sigma, self.delta_s, self.held = sigma, delta_s, held
        self.y = y[rows]
        self.smoothing = None if smoother is None else row_smoothing(smoother, qd.size, rows)
        self.qd = qd[rows] if self.smoothing is None else qd[self.smoothing.support]
        self.part = linear_part(model, held, free, lower, upper)
        self.theta = tuple(i for i in fam.positions(fam.nonlinear) if free[i])
        self.slopes = tuple(fam.names[i] in fam.step_slopes for i in self.theta)  # else a velocity
        self.theta_bounds = (np.log(np.maximum(lower[list(self.theta)], 1e-300)), np.log(upper[list(self.theta)]))
        self.jump_at = fam.positions(fam.jump_params)
        k = len(fam.column_factors)
        self.fixed = [c for c in range(k) if c != fam.jump_column and c not in fam.varying_columns]
        self._ends: np.ndarray | None = None  # the columns that depend on no parameter (qd, 1), on the rows (smoothed)
        # the jump's parameters (a), its column, on the rows (smoothed)
        self._jump: tuple[tuple[float, ...], np.ndarray, np.ndarray] | None = None

    def _columns(self, log_theta: np.ndarray) -> np.ndarray:
        """The model's columns (n, K) on the rows fitted at ``log_theta``, smoothed if the fit is; the jump column,
        which depends on the jump's parameters alone (``a``), is kept for the next call (a grid's row, a step in
        ``v_s``)."""
        fam = self.family
        z = self.held.copy()
        z[list(self.theta)] = np.exp(log_theta)
        if fam.jump_column is not None:
            key = tuple(z[i] for i in self.jump_at)
            if self._jump is None or self._jump[0] != key:
                jump = fam.expected_jump(self.qd, self.sigma, z)
                self._jump = (key, jump, jump if self.smoothing is None else self.smoothing(jump))
        columns = fam.expected_columns(self.qd, self.sigma, self.delta_s, z,
                                       jump=None if self._jump is None else self._jump[1])
        if self.smoothing is None:
            return columns
        # the columns of no parameter (qd and 1) smoothed once, the jump once for each value of its parameters
        if self._ends is None:
            self._ends = self.smoothing(columns[:, self.fixed])
        out = np.empty((self.rows.size, columns.shape[1]))
        out[:, self.fixed] = self._ends
        if self._jump is not None and fam.jump_column is not None:
            out[:, fam.jump_column] = self._jump[2]
        for c in fam.varying_columns:  # the Stribeck column
            out[:, c] = self.smoothing(columns[:, c])
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
    """The grid's axes: the logarithms of the free non-linear parameters (``log v_s``, ``log a``) for a joint of
    ``speed`` [rad/s] (:data:`GRID` points each, and a slope's upper bound), inside the bounds."""
    axes = []
    lo, hi = projection.theta_bounds
    for j, slope in enumerate(projection.slopes):
        if not slope:  # a velocity
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
    # noise-free data the grid fits exactly (a friction of zero: issue 63) have a best cost of zero: the scale is
    # held to 1e-12 of the worst grid point's residual (1 where every point is exact), or the search's residuals
    # overflow to inf and NaN
    worst = float(np.max(costs, where=np.isfinite(costs), initial=0.0))
    scale = 1.0 / max(math.sqrt(float(costs.min())), 1e-12 * math.sqrt(worst) if worst > 0 else 1.0)
    best = min((least_squares(lambda t: scale * projection.residual(t), grid[k], bounds=projection.theta_bounds,
                              method="trf", diff_step=1e-7, ftol=1e-12, xtol=1e-10, gtol=1e-14, max_nfev=50)
                for k in grid_minima(costs)[:basins]), key=lambda r: r.cost)
    return projection.params(best.x)

