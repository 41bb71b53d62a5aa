"""The given model's best friction: for given inertias, the physical friction (and armature when identified) that
best explains the identification's compressed system (:mod:`wbfriction.inertia.identification`: the start of the
fit, the prior's centre, and the friction of every candidate model of the held-out gate,
:mod:`~wbfriction.inertia.validation`)."""

from __future__ import annotations

import numpy as np


class BestRest:
    """The physical friction (and armature when identified) that best explains the compressed system
    ``R`` (p, p), ``z`` (p,) with given inertias: ``min |R_rest x - (z - R_in pi)|`` over ``x >= lower``.

    The problem splits by joint: a joint's friction and armature columns act on its own rows only, so
    the columns of two joints are orthogonal (``R_i^T R_j = A_i^T A_j = 0``) and each joint's
    parameters solve a bounded least squares of their own, here reduced to k x k (``R_j = Q_j T_j``):
    the same minimum as the whole bounded problem, for a few k x k solves instead of a p x (k n_tc)
    one per candidate model. A joint whose unbounded minimum keeps the bounds (the usual case) takes it
    by one triangular solve; the others by a bounded least squares (BVLS).

    Args:
        R, z: the compressed system (p, p), (p,), the bodies' parameters first
            (:func:`~wbfriction.inertia.system.compressed_system`).
        lower: lower bounds of the parameters (p,) (the bodies' ignored).
        p_in: the number of the bodies' parameters (10 nb).
        columns: each torque-controlled joint's own columns after the bodies' (n_tc, k[+1])
            (:func:`~wbfriction.inertia.rows.own_columns`).
    """

    def __init__(self, R: np.ndarray, z: np.ndarray, lower: np.ndarray, p_in: int, columns: np.ndarray):
        import scipy.linalg
        self.R, self.z, self.p_in = R, z, p_in
        self.columns = list(columns)
        self.n_rest = R.shape[1] - p_in
        self.lower = lower[p_in:]
        self.factors = [scipy.linalg.qr(R[:, p_in + cols], mode="economic") for cols in self.columns]

    def __call__(self, pi: np.ndarray) -> np.ndarray:
        """The best rest parameters (k n_tc [+ n_tc],) for the inertias ``pi`` (nb, 10)."""
        import scipy.linalg
        from scipy.optimize import lsq_linear
        rhs = self.z - self.R[:, :self.p_in] @ pi.ravel()
        out = np.zeros(self.n_rest)
        for cols, (Q, T) in zip(self.columns, self.factors):
            y, lo = Q.T @ rhs, self.lower[cols]
            if not np.any(T):
                continue  # a joint without rows: nothing to fit
            pivots = np.abs(np.diag(T))
            if pivots.min() > 1e-12 * pivots.max():
                x = scipy.linalg.solve_triangular(T, y, check_finite=False)
                if np.all(x >= lo):
                    out[cols] = x
                    continue
            out[cols] = lsq_linear(T, y, bounds=(lo, np.full(len(cols), np.inf)), method="bvls").x
        return out
