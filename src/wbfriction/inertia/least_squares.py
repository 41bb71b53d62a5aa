"""Least squares over long logs in memory of the size of the parameters, and the identifiable combinations.

:class:`CompressedLeastSquares` keeps the triangular factor of the rows seen so far;
:func:`base_parameters` finds the base parameters of a regressor by QR with column pivoting.

**Rounding.** A regressor with dependent columns (a walk's, an arm's: the parameters that act only in
combination) has a factor that is not unique: after a dependent column, the QR's reflection is set by
rounding noise, and each block added hands a rounding-chosen share of its residual to the rows of the
dependent columns. The smallest residual over all columns (:attr:`CompressedLeastSquares.residual_floor`)
is therefore a figure of the rounding (the BLAS thread count changed it by 0.5 % on a TALOS walk) and
too small (by 5 % on that walk's rows and 14 % on a simulated Panda's, without a Stribeck term); the one
over the base parameters (:meth:`CompressedLeastSquares.residual`) is that of a well-posed problem, the
same to 1e-12 whatever the rounding and equal to the stacked rows' least squares. For the same reason
the condition number is that of the identifiable part (:class:`BaseParameters`), not of the columns
the pivoting chose among near ties.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


class CompressedLeastSquares:
    """``min |A x - b|^2`` over rows added block by block, kept as the triangular factor
    ``R`` (p, p) and ``z`` (p,) of the rows seen so far (``|A x - b|^2 = |R x - z|^2 + const``):
    memory of the size of ``x``, not of the data."""

    def __init__(self, n_params: int, min_rows: int = 0):
        """``min_rows``: rows are held back until at least this many are pending, then factorized
        together with the factor (a QR of ``min_rows + p`` rows costs about as much per row as one
        of many more, and far less than blocks of fewer rows than ``p``); 0: each block at once."""
        self.n = n_params
        self.min_rows = min_rows
        self._Rz = np.zeros((0, n_params + 1))
        self._pending: list[np.ndarray] = []
        self._pending_rows = 0
        self._floor = 0.0
        self.rows = 0

    def add(self, A: np.ndarray, b: np.ndarray) -> None:
        """Append rows ``A`` (m, p) with right-hand sides ``b`` (m,)."""
        self._pending.append(np.column_stack([A, b]))
        self._pending_rows += len(b)
        self.rows += len(b)
        if self._pending_rows >= self.min_rows:
            self._flush()

    def _flush(self) -> None:
        """Factorize the pending rows with the factor."""
        import scipy.linalg
        if not self._pending:
            return
        stacked = np.vstack([self._Rz, *self._pending])
        self._pending, self._pending_rows = [], 0
        self._Rz = scipy.linalg.qr(stacked, mode="r", overwrite_a=True, check_finite=False)[0][: self.n + 1]

    def absorb(self, other: CompressedLeastSquares, T: np.ndarray | None = None) -> None:
        """Append the rows of ``other`` (whose parameters are ``T @ x``, (p_other, p); identity if None)."""
        self.absorb_all([(other, T)])

    def absorb_all(self, others: Sequence[tuple[CompressedLeastSquares, np.ndarray | None]]) -> None:
        """Append the rows of each ``other`` (whose parameters are ``T @ x``, (p_other, p); identity if
        None), all their factors in one QR."""
        parts = [(o, T) for o, T in others if o.rows]
        if not parts:
            return
        for other, T in parts:
            self._pending.append(np.column_stack([other.R if T is None else other.R @ T, other.z]))
            self._floor += other.residual_floor
            self.rows += other.rows
        self._flush()

    @property
    def residual_floor(self) -> float:
        """The smallest ``|A x - b|^2`` (so ``|A x - b|^2 = |R x - z|^2 + residual_floor``)."""
        self._flush()
        corner = self._Rz[self.n, self.n] if self._Rz.shape[0] > self.n else 0.0
        return float(corner ** 2) + self._floor

    def base_parameters(self, rank_tolerance: float = 1e-8) -> BaseParameters:
        """The base parameters of the rows added (:func:`base_parameters`), with their residual."""
        return base_parameters(self.R, rank_tolerance, self.z)

    def residual(self, base: BaseParameters) -> float:
        """The smallest ``|A x - b|^2`` over ``x`` zero outside the independent columns of ``base`` (made
        by :meth:`base_parameters`): the least-squares residual of the base parameters (module docstring:
        unlike :attr:`residual_floor`, it does not depend on rounding)."""
        if base.off_span is None:
            raise ValueError("base parameters found without the right-hand side: no residual")
        return base.off_span + self.residual_floor if self.rows else 0.0

    def rms(self, x: np.ndarray) -> float:
        """RMS of ``A x - b`` over the rows added."""
        r = self.R @ x - self.z
        return float(np.sqrt((r @ r + self.residual_floor) / max(self.rows, 1)))

    @property
    def R(self) -> np.ndarray:
        self._flush()
        return np.triu(self._Rz[: self.n, : self.n])

    @property
    def z(self) -> np.ndarray:
        self._flush()
        return self._Rz[: self.n, self.n]



@dataclass(frozen=True)
class BaseParameters:
    """The identifiable combinations of the parameters (base parameters).

    Attributes:
        independent: indices of the parameters chosen as base parameters (r,), the pivots
            of a QR factorization with column pivoting of the regressor.
        combination: (r, p): base parameter ``k`` is ``combination[k] @ x``, i.e. its
            independent parameter plus the dependent ones it absorbs.
        condition: condition number of the identifiable part of the regressor, its columns each
            scaled to unit norm (so that it does not depend on units): its largest singular value over
            its ``r``-th (the same whichever columns the pivoting chose as independent among near ties).
        rank_tolerance: relative size of a pivot below which a column counts as dependent.
        off_span: given the right-hand side ``z`` of the factor, ``|z|^2`` outside the span of the
            independent columns (the part of the residual of the base parameters' least squares that the
            factor holds); None without it.
    """

    independent: np.ndarray
    combination: np.ndarray
    condition: float
    rank_tolerance: float
    off_span: float | None = None

    @property
    def count(self) -> int:
        return len(self.independent)


def base_parameters(R: np.ndarray, rank_tolerance: float = 1e-8, z: np.ndarray | None = None) -> BaseParameters:
    """Base parameters of a regressor given by its triangular factor ``R`` (p, p)
    (:class:`CompressedLeastSquares`; ``R`` and the stacked regressor have the same
    column dependencies), by one QR with column pivoting: ``R P = Q [R1 R2]``, rank ``r`` where
    ``|R1_kk| > rank_tolerance |R1_11|``; the dependent columns are ``R1^-1 R2`` times
    the independent ones, so the base parameters are ``x_indep + R1^-1 R2 x_dep`` (Gautier, *Numerical
    calculation of the base inertial parameters of robots*, J. Robotic Systems 1991). With the right-hand side
    ``z`` (p,), the same factorization gives the base parameters' residual: the first ``r`` columns of ``Q`` span
    the independent columns, so ``z - Q_r Q_r^T z`` is ``z`` outside them (:attr:`BaseParameters.off_span`).

    Columns are scaled to unit norm first, so the rank does not depend on units. (On a walk or an arm the
    pivots fall by ten orders of magnitude at the rank, from 1e-5 to 1e-15: the default tolerance sits in
    that gap, far from rounding.)
    """
    import scipy.linalg
    norms = np.linalg.norm(R, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    q_fac, r_fac, perm = scipy.linalg.qr(R / scale, mode="economic", pivoting=True)
    diag = np.abs(np.diag(r_fac))
    rank = int(np.sum(diag > rank_tolerance * diag[0])) if diag.size and diag[0] > 0 else 0
    off_span = None
    if z is not None:
        off = z - q_fac[:, :rank] @ (q_fac[:, :rank].T @ z)
        off_span = float(off @ off)
    R1, R2 = r_fac[:rank, :rank], r_fac[:rank, rank:]
    K = scipy.linalg.solve_triangular(R1, R2)  # scaled dependent -> independent
    combination = np.zeros((rank, R.shape[1]))
    ind, dep = perm[:rank], perm[rank:]
    combination[np.arange(rank), ind] = 1.0
    combination[:, dep] = K * scale[dep][None, :] / scale[ind][:, None]
    s = np.linalg.svd(R / scale, compute_uv=False)
    return BaseParameters(np.sort(ind), combination[np.argsort(ind)], float(s[0] / s[rank - 1]) if rank else np.inf,
                          rank_tolerance, off_span)
