"""Physically consistent inertial parameters, fitted with a prior toward the given model and bounded friction.

Each body is written through its log-Cholesky parameters (Rucker & Wensing, *Smooth
parameterization of rigid-body inertia*, IEEE RA-L 2022; ``pin.LogCholeskyParameters``), so
every estimate is a physical rigid body (positive mass, positive-definite pseudo-inertia: the
triangle inequalities hold). :func:`fit_consistent` solves the regularised least squares of
the identification (:mod:`wbfriction.inertia.identification`) over such bodies, with the
friction parameters bounded to physical values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import scipy.linalg
from scipy.optimize import least_squares, lsq_linear

FRICTION = ("F_v", "F_c", "tau_os")
"""Friction parameters identified per torque-controlled joint (3.5 without Stribeck)."""
FRICTION_PRIOR = 1e-12
"""Relative weight of the friction parameters' prior (module docstring)."""
STRIBECK = "F_s-F_c"
"""With a fixed Stribeck velocity ``v_s``, the Stribeck term's height ``F_s - F_c = S F_c`` [N·m]
too (``F_s`` the static friction of 3.4, ``S`` that of :func:`wbfriction.friction.models.coulomb_viscous_stribeck`)."""
FRICTION_LOWER = {"F_v": 0.0, "F_c": 0.0, "tau_os": -np.inf, STRIBECK: 0.0}
"""Physical friction: dissipative viscous and Coulomb parts, static friction at least the
Coulomb level (the bounds of :data:`wbfriction.friction.fit.LOWER`); the offset is free."""


def log_cholesky(pi: np.ndarray, min_mass: float = 1e-3) -> np.ndarray:
    """Log-Cholesky parameters (10,) of a body with dynamic parameters ``pi`` (10,), in
    ``pin.LogCholeskyParameters`` order ``(alpha, d1, d2, d3, s12, s23, s13, t1, t2, t3)``:
    the pseudo-inertia ``J = U U^T`` with ``U = e^alpha [[e^d1, s12, s13, t1], [0, e^d2,
    s23, t2], [0, 0, e^d3, t3], [0, 0, 0, 1]]`` (Rucker & Wensing 2022).

    A body without mass or with a singular pseudo-inertia (a point or a rod) has none: it
    is replaced by a solid sphere of ``min_mass`` [kg] and 1 cm radius at its centre of
    mass (or origin), the nearest start a physical parametrisation can take.
    """
    J = pin.PseudoInertia.FromDynamicParameters(np.asarray(pi, dtype=float)).toMatrix()
    flip = np.eye(4)[::-1]
    try:
        U = flip @ np.linalg.cholesky(flip @ J @ flip) @ flip
    except np.linalg.LinAlgError:
        m = max(float(pi[0]), min_mass)
        c = np.asarray(pi[1:4]) / pi[0] if pi[0] > 0 else np.zeros(3)
        sphere = pin.Inertia(m, c, np.eye(3) * 0.4 * m * 0.01 ** 2)
        return log_cholesky(sphere.toDynamicParameters(), min_mass)
    alpha = np.log(U[3, 3])
    Un = U / U[3, 3]
    return np.array([alpha, *np.log(np.diag(Un)[:3]), Un[0, 1], Un[1, 2], Un[0, 2], *Un[:3, 3]])


def _dynamic_parameters(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Dynamic parameters (nb, 10) of log-Cholesky parameters (nb, 10), and their Jacobians (nb, 10, 10)."""
    pi, jac = np.empty_like(theta), np.empty((len(theta), 10, 10))
    for b, t in enumerate(theta):
        lc = pin.LogCholeskyParameters(t)
        pi[b] = lc.toDynamicParameters()
        jac[b] = lc.calculateJacobian()
    return pi, jac


def parameter_scales(pi0: np.ndarray, min_mass: float = 1e-3, length: float = 0.1) -> np.ndarray:
    """Scale of each inertial parameter (nb, 10), for the prior and for the rank test:
    ``m``, ``m length``, ``m length^2`` with ``m`` the body's given mass (at least ``min_mass``)
    and ``length`` a body size [m]."""
    m = np.maximum(pi0[:, 0], min_mass)[:, None]
    return np.hstack([m, np.repeat(m * length, 3, axis=1), np.repeat(m * length ** 2, 6, axis=1)])


@dataclass(frozen=True)
class ConsistentFit:
    """Result of :func:`fit_consistent`: inertial parameters (nb, 10), physically consistent;
    friction parameters (n_tc, 3) (``F_v, F_c, tau_os``); the optimizer's message."""

    pi: np.ndarray
    friction: np.ndarray
    cost: float
    message: str


def is_consistent(pi: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """Physical consistency of bodies (nb, 10) -> (nb,): a positive-definite pseudo-inertia
    (positive mass and principal moments that satisfy the triangle inequalities; Wensing et
    al., *Linear matrix inequalities for physically consistent inertial parameter
    identification*, IEEE RA-L 2018), its smallest eigenvalue above ``margin`` times its largest."""
    out = np.empty(len(pi), dtype=bool)
    for b, p in enumerate(pi):
        ev = np.linalg.eigvalsh(pin.PseudoInertia.FromDynamicParameters(np.asarray(p, dtype=float)).toMatrix())
        out[b] = ev[0] > margin * max(ev[-1], 0.0) and ev[-1] > 0
    return out


def nearest_consistent(pi: np.ndarray, margin: float = 1e-12) -> np.ndarray:
    """Bodies (nb, 10) with every pseudo-inertia eigenvalue raised to at least ``margin`` times
    the largest (the nearest such pseudo-inertia in the Frobenius norm): a body that rounding
    left just outside the physical set (an optimum on its boundary, a thin plate or a rod)
    comes back inside; a physical one is unchanged."""
    out = np.array(pi, dtype=float)
    for b, p in enumerate(out):
        J = pin.PseudoInertia.FromDynamicParameters(p).toMatrix()
        ev, V = np.linalg.eigh(J)
        floor = margin * max(ev[-1], 0.0)
        if ev[-1] > 0 and ev[0] <= floor:
            J = (V * np.maximum(ev, floor)) @ V.T
            out[b] = pin.PseudoInertia.FromMatrix(0.5 * (J + J.T)).toDynamicParameters()
    return out


def friction_lower_bounds(k: int, n_tc: int) -> np.ndarray:
    """Lower bounds (k n_tc,) of the friction parameters, the first ``k`` of ``(F_v, F_c, tau_os, F_s-F_c)``
    per joint (:data:`FRICTION_LOWER`)."""
    return np.tile([FRICTION_LOWER[n] for n in (*FRICTION, STRIBECK)[:k]], n_tc)


def regularised_problem(R: np.ndarray, z: np.ndarray, pi0: np.ndarray, friction0: np.ndarray, prior: float,
                 min_mass: float, lower: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`fit_consistent`'s objective ``|A x - c|^2`` (``A`` (2p, p), ``c`` (2p,)) and
    its minimum ``x_lin`` without the bodies' consistency constraint, with the friction
    bounds ``lower`` (a bounded linear least squares)."""
    x0 = np.concatenate([pi0.ravel(), friction0.ravel()])
    d = 1.0 / np.concatenate([parameter_scales(pi0, min_mass).ravel(), np.ones(friction0.size)])
    relative = np.concatenate([np.full(pi0.size, prior), np.full(friction0.size, FRICTION_PRIOR)])
    w = np.sqrt(relative) * np.linalg.norm(R / d[None, :], 2) * d
    A, c = np.vstack([R, np.diag(w)]), np.concatenate([z, w * x0])
    scaled = A / d[None, :]  # in the parameters times d: columns of comparable size
    if np.isfinite(lower).any():
        x_lin = lsq_linear(scaled, c, bounds=(lower * d, np.inf), method="bvls").x / d
    else:
        x_lin = np.linalg.lstsq(scaled, c, rcond=None)[0] / d
    return x_lin, A, c


def fit_consistent(R: np.ndarray, z: np.ndarray, pi0: np.ndarray, friction0: np.ndarray, prior: float = 1e-9,
                   min_mass: float = 1e-3) -> ConsistentFit:
    """Solve ``min |R x - z|^2 + |W D (x - x0)|^2`` over physically consistent bodies and
    friction (:data:`FRICTION_LOWER`).

    ``x = (pi.ravel(), friction.ravel())``; ``x0`` is the given model (``pi0``,
    ``friction0``); ``D`` divides by :func:`parameter_scales` (1 for friction);
    ``W^2 = sigma_max(R D^-1)^2`` times ``prior`` on the inertial parameters and
    :data:`FRICTION_PRIOR` on the friction ones. The friction is bounded (a joint that
    never leaves the linear part of ``tanh`` cannot tell its viscous from its Coulomb
    friction: unbounded, they cancel with huge opposite values). The linear solution with
    these bounds (``scipy.optimize.lsq_linear``) is taken when every body it gives is
    physically consistent (:func:`is_consistent`); otherwise each body is written through
    its log-Cholesky parameters (so that every iterate is a rigid body) and the problem is
    solved by ``scipy.optimize.least_squares``, from the linear solution's consistent
    bodies and friction and the given model's other bodies (trust-region steps by LSMR, on
    the problem compressed to ``p`` rows; stopped after 200 evaluations: on the demo's
    walk, 2000 lower the cost by 0.2 %); a body that rounding leaves on the boundary of
    the physical set is then brought inside (:func:`nearest_consistent`).

    Args:
        R, z: the compressed regressor (p, p) and right-hand side (p,), columns ordered as ``x``.
        pi0: given inertial parameters (nb, 10); friction0: starting friction (n_tc, k), its
            columns the first ``k`` of ``(F_v, F_c, tau_os, F_s-F_c)``.
        prior: relative weight of the inertial parameters' prior.
        min_mass: smallest mass of a body's starting point [kg] (:func:`log_cholesky`).
    """
    nb = len(pi0)
    lower = np.concatenate([np.full(10 * nb, -np.inf), friction_lower_bounds(*friction0.shape[::-1])])
    x_lin, A, c = regularised_problem(R, z, pi0, friction0, prior, min_mass, lower)
    pi_lin = x_lin[: 10 * nb].reshape(nb, 10)
    ok = is_consistent(pi_lin, 1e-12)
    if ok.all():
        r = A @ x_lin - c
        return ConsistentFit(pi_lin, x_lin[10 * nb:].reshape(friction0.shape), 0.5 * float(r @ r),
                             "the linear least-squares solution is physically consistent")
    # |A x - c|^2 = |T x - e|^2 + floor (A = Q T): the same problem in half the rows
    Q, T = scipy.linalg.qr(A, mode="economic")
    e = Q.T @ c
    floor = float(c @ c - e @ e)

    def unpack(v):
        pi, jac = _dynamic_parameters(v[: 10 * nb].reshape(nb, 10))
        return np.concatenate([pi.ravel(), v[10 * nb:]]), jac

    def fun(v):
        return T @ unpack(v)[0] - e

    def jac(v):
        jb = unpack(v)[1]  # d pi_b / d theta_b (nb, 10, 10); friction enters as itself
        out = T.copy()
        out[:, : 10 * nb] = np.einsum("rbi,bij->rbj", T[:, : 10 * nb].reshape(-1, nb, 10), jb).reshape(-1, 10 * nb)
        return out

    nearest = nearest_consistent(pi_lin, 1e-4)
    theta0 = np.array([log_cholesky(p, min_mass) for p in np.where(ok[:, None], pi_lin, nearest)])
    start = np.concatenate([theta0.ravel(), np.maximum(x_lin[10 * nb:], lower[10 * nb:])])  # max: bvls rounding
    with np.errstate(over="ignore", invalid="ignore"):  # trial steps may overflow exp(): trf then shrinks them
        res = least_squares(fun, start, jac=jac, bounds=(lower, np.inf), method="trf", x_scale="jac",
                            tr_solver="lsmr", max_nfev=200)
    x, _ = unpack(res.x)
    return ConsistentFit(nearest_consistent(x[: 10 * nb].reshape(nb, 10)), x[10 * nb:].reshape(friction0.shape),
                         float(res.cost + 0.5 * floor),
                         f"{int((~ok).sum())} bodies of the linear solution were not physical: {res.message}")
