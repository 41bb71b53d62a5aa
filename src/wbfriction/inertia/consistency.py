"""Physically consistent inertial parameters, fitted with a prior toward the given model and bounded friction.

Every estimate is a physical rigid body: its pseudo-inertia is positive semidefinite (positive mass,
principal moments that satisfy the triangle inequalities; the linear matrix inequality of Wensing et al.,
IEEE RA-L 2018). :func:`fit_consistent` solves the regularised least squares of the identification
(:mod:`wbfriction.inertia.identification`) over such bodies, with the friction parameters and the
armature bounded to physical values: a convex conic program, solved exactly (Clarabel).

**The prior** (:class:`PriorUncertainty`, :func:`prior_model`) is a Gaussian one around the given
model, stated where a model's uncertainty is known: per body, its mass (relative), its centre of
mass (a length) and its rotational inertia about the centre of mass (relative to the body's
largest principal moment); per joint, its armature (relative to the robot's joint inertias) and
its friction (relative to the torques the joint sees: the URDF says nothing of friction, so this
prior is weak; it keeps a joint that hardly moves from taking a friction that its motion
elsewhere would contradict). It is linearised at the given model: ``|L (x - x0)|^2`` counts
standard deviations.

Why a real arm's masses ran to -100 % before (the KUKA LWR4+ logs of ``../shared/real-data``):
the prior was scaled per parameter about the joint frame (mass in kg, first moments with 0.1 m,
inertias with 0.01 m^2). A lever arm ``d`` makes a body's mass act like ``d^2`` of rotational
inertia, so the mass was the cheapest carrier of every change the data asked of the combinations
it enters (Khalil's regrouped base parameters), and ran to the boundary first; the prior's weight
(1e-9 of the largest squared singular value) held nothing the data touched; and most of what the
data asked was noise: central differences of those logs put three quarters of the accelerations'
power above a quarter of the sampling rate, and noise in the regressor shrinks inertias (errors
in variables; :attr:`wbfriction.inertia.identification.InertialIdentification.acceleration_noise`
flags it). In physical parameters a mass cannot carry such changes without moving many standard
deviations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.fit.solver import SolverOutcome
from wbfriction.inertia.options import PriorUncertainty

FRICTION = ("F_v", "F_c", "tau_os")
"""Friction parameters identified per torque-controlled joint (3.5 without Stribeck)."""
STRIBECK = "F_s-F_c"
"""With a fixed Stribeck velocity ``v_s``, the Stribeck term's height ``F_s - F_c = S F_c`` [N·m]
too (``F_s`` the static friction of 3.4, ``S`` that of :func:`wbfriction.friction.models.coulomb_viscous_stribeck`)."""
FRICTION_LOWER = {"F_v": 0.0, "F_c": 0.0, "tau_os": -np.inf, STRIBECK: 0.0}
"""Physical friction: dissipative viscous and Coulomb parts, static friction at least the
Coulomb level (the bounds of :data:`wbfriction.friction.families.thesis.LOWER`); the offset is free."""
PHYSICAL = ("m", "c_x", "c_y", "c_z", "I_xx", "I_xy", "I_yy", "I_xz", "I_yz", "I_zz")
"""A body's physical parameters: mass [kg], centre of mass in the joint frame [m], rotational
inertia about the centre of mass in the joint frame's axes [kg·m^2] (the prior's coordinates)."""
_PAIRS = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))  # the inertia entries in PHYSICAL / pin order


def _sphere(pi: np.ndarray, min_mass: float) -> np.ndarray:
    """A solid sphere of 1 cm radius, at least ``min_mass`` [kg], at the body's centre of mass (or origin)."""
    m = max(float(pi[0]), min_mass)
    c = np.asarray(pi[1:4]) / pi[0] if pi[0] > 0 else np.zeros(3)
    return pin.Inertia(m, c, np.eye(3) * 0.4 * m * 0.01 ** 2).toDynamicParameters()


def physical_jacobian(pi: np.ndarray) -> np.ndarray:
    """``d pi / d phi`` (10, 10) at a body with dynamic parameters ``pi`` (10,), ``phi`` its
    :data:`PHYSICAL` parameters: ``pi = (m, m c, I_c + m (|c|^2 1 - c c^T))``."""
    inertia = pin.Inertia.FromDynamicParameters(np.asarray(pi, dtype=float))
    m, c = inertia.mass, np.asarray(inertia.lever)

    def vec(S: np.ndarray) -> np.ndarray:
        return np.array([S[i, j] for i, j in _PAIRS])

    J = np.zeros((10, 10))
    J[0, 0], J[1:4, 0], J[4:, 0] = 1.0, c, vec((c @ c) * np.eye(3) - np.outer(c, c))
    for i in range(3):
        e = np.eye(3)[i]
        J[1 + i, 1 + i] = m
        J[4:, 1 + i] = m * vec(2.0 * c[i] * np.eye(3) - np.outer(e, c) - np.outer(c, e))
    J[4:, 4:] = np.eye(6)
    return J


def body_prior(pi: np.ndarray, uncertainty: PriorUncertainty = PriorUncertainty(),
               min_mass: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """The prior of a body with given dynamic parameters ``pi`` (10,): the standard deviations (10,) of
    its physical parameters (:data:`PHYSICAL`, :class:`PriorUncertainty`), and the square root of the
    prior's information ``L`` (10, 10): ``|L dpi|`` is a change ``dpi`` of its dynamic parameters in
    standard deviations of the physical ones, to first order. A massless or flat body is measured at
    a ``min_mass`` [kg] sphere of 1 cm radius."""
    pi = np.asarray(pi, dtype=float)
    if pi[0] < min_mass or not is_consistent(pi[None], 1e-12)[0]:
        pi = _sphere(pi, min_mass)
    inertia = pin.Inertia.FromDynamicParameters(pi)
    m = inertia.mass
    moment = max(float(np.linalg.eigvalsh(inertia.inertia)[-1]), 0.4 * m * 0.01 ** 2)
    std = np.array([uncertainty.mass * m] + [uncertainty.com] * 3 + [uncertainty.inertia * moment] * 6)
    return std, np.linalg.solve(physical_jacobian(pi), np.eye(10)) / std[:, None]


@dataclass(frozen=True)
class Prior:
    """A Gaussian prior over the identification's parameters ``x = (pi.ravel(), rest)``: the bodies'
    dynamic parameters (10 per body) then the joints' friction and armature.

    Attributes:
        x0: the given model (p,).
        bodies: square roots of the bodies' prior information (nb, 10, 10) (:func:`body_prior`).
        body_std: standard deviations of the bodies' physical parameters (nb, 10) (:data:`PHYSICAL`).
        std: standard deviations of the other parameters (p - 10 nb,).
    """

    x0: np.ndarray
    bodies: np.ndarray
    body_std: np.ndarray
    std: np.ndarray

    @property
    def nb(self) -> int:
        return len(self.bodies)

    @property
    def L(self) -> np.ndarray:
        """The square root of the prior's information (p, p), block diagonal."""
        import scipy.linalg
        return scipy.linalg.block_diag(*self.bodies, np.diag(1.0 / self.std))

    @property
    def L_inv(self) -> np.ndarray:
        """``L^-1`` (p, p): the map from standard deviations to parameters."""
        import scipy.linalg
        return scipy.linalg.block_diag(*(np.linalg.inv(B) for B in self.bodies), np.diag(self.std))


def prior_model(pi0: np.ndarray, rest0: np.ndarray, rest_std: np.ndarray,
                uncertainty: PriorUncertainty = PriorUncertainty(), min_mass: float = 1e-3) -> Prior:
    """The prior of given bodies ``pi0`` (nb, 10) and other parameters ``rest0`` with standard deviations
    ``rest_std`` (k,)."""
    stds, roots = zip(*(body_prior(p, uncertainty, min_mass) for p in pi0))
    return Prior(np.concatenate([np.asarray(pi0, dtype=float).ravel(), rest0]), np.array(roots), np.array(stds),
                 np.asarray(rest_std, dtype=float))


@dataclass(frozen=True)
class ConsistentFit:
    """Result of :func:`fit_consistent`: inertial parameters (nb, 10), physically consistent; the
    other parameters (friction, armature) (k,); half the objective; what happened, in words; and, when
    the conic solve ran, why it stopped and the number of bodies of the linear solution that were not
    physical (None and 0 otherwise)."""

    pi: np.ndarray
    rest: np.ndarray
    cost: float
    message: str
    solver: SolverOutcome | None = None
    unphysical: int = 0

    @property
    def x(self) -> np.ndarray:
        return np.concatenate([self.pi.ravel(), self.rest])


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


class RegularisedProblem:
    """:func:`fit_consistent`'s objective ``|R x - z|^2 + w |L (x - x0)|^2`` for any prior weight ``w``, set up once.

    In standard deviations of the prior (``x = x0 + L^-1 y``) it is ``|B y - c0|^2 + w |y|^2`` with ``B = R L^-1``
    and ``c0 = z - R x0``: Tikhonov's standard form. One singular value decomposition ``B = U diag(s) V^T``
    serves every weight (Hansen, *Rank-Deficient and Discrete Ill-Posed Problems*, SIAM 1998, sec. 4.2; the
    generalized SVD of the pair ``(R, L)`` in the prior's coordinates): the unbounded minimum is
    ``y(w) = V diag(s / (s^2 + w)) U^T c0``, and the objective is ``|T_w y - e_w|^2`` plus a constant, with
    ``T_w = diag(sqrt(s^2 + w)) V^T`` (p, p) and ``e_w = diag(s / sqrt(s^2 + w)) U^T c0``: the bounded and the
    conic solves of a weight start from these, not from the ``2p`` stacked rows. Choosing the weight by
    validation (:mod:`wbfriction.inertia.identification`) solves one problem per weight on one decomposition.

    Args:
        R, z: the compressed regressor (m, p) and right-hand side (m,), columns ordered as ``x``.
        prior: the given model and its uncertainty.
        lower: lower bounds (p,) (those of the bodies' parameters are ignored).
    """

    def __init__(self, R: np.ndarray, z: np.ndarray, prior: Prior, lower: np.ndarray):
        import scipy.linalg
        self.R, self.z, self.prior, self.lower = R, z, prior, lower
        self.L, self.L_inv = prior.L, prior.L_inv
        B = R @ self.L_inv
        U, sv, self.Vt = scipy.linalg.svd(B, full_matrices=True)
        p = len(prior.x0)
        self.s = np.zeros(p)
        self.s[:sv.size] = sv
        self.d = np.zeros(p)  # U^T c0, in the directions of V
        self.d[:sv.size] = (U.T @ (z - R @ prior.x0))[:sv.size]
        self.lo = _lower_in_std(prior, lower)

    def compressed(self, weight: float) -> tuple[np.ndarray, np.ndarray]:
        """``T_w`` (p, p) and ``e_w`` (p,): the objective of weight ``weight`` in standard deviations, up to a
        constant (class docstring)."""
        root = np.sqrt(self.s ** 2 + weight)
        return root[:, None] * self.Vt, self.s * self.d / root

    def linear(self, weight: float) -> np.ndarray:
        """The minimum ``x`` (p,) without the bodies' consistency constraint, with the bounds on the parameters
        after the bodies': the unbounded minimum where it keeps them, else a bounded linear least squares on
        the compressed objective (:meth:`compressed`)."""
        y = self.Vt.T @ (self.s * self.d / (self.s ** 2 + weight))
        if np.any(y < self.lo):
            from scipy.optimize import lsq_linear
            T, e = self.compressed(weight)
            y = lsq_linear(T, e, bounds=(self.lo, np.inf), method="bvls").x
        return self.prior.x0 + self.L_inv @ y

    def objective(self, x: np.ndarray, weight: float) -> float:
        """``|R x - z|^2 + weight |L (x - x0)|^2``."""
        r, q = self.R @ x - self.z, self.L @ (x - self.prior.x0)
        return float(r @ r + weight * (q @ q))

    def conic(self, weight: float, margin: float = 0.0) -> tuple[np.ndarray, SolverOutcome]:
        """The exact minimum over positive-semidefinite pseudo-inertias and the bounds: a convex quadratic program
        with one 4 x 4 semidefinite cone per body (the linear matrix inequality of Wensing et al. 2018, about
        ``J(pi) - margin J(pi_0)``), solved by Clarabel's interior-point method in standard deviations of the
        prior (its quadratic form ``T_w^T T_w = B^T B + w 1``, :meth:`compressed`)."""
        import clarabel
        import scipy.sparse as sp
        prior = self.prior
        T, e = self.compressed(weight)
        p, nb = len(prior.x0), prior.nb
        G = _svec_pseudo_inertia()
        blocks, b = [], []
        for k, root in enumerate(prior.bodies):  # J(pi_b) - margin J(x0_b) = (1 - margin) J(x0_b) + G L_b^-1 y_b
            row = np.zeros((10, p))
            row[:, 10 * k:10 * k + 10] = -G @ np.linalg.inv(root)
            blocks.append(row)
            b.append((1.0 - margin) * (G @ prior.x0[10 * k:10 * k + 10]))
        bounded = np.flatnonzero(np.isfinite(self.lo))  # y_i >= lo_i: -y_i + s = -lo_i, s >= 0
        blocks.append(-np.eye(p)[bounded])
        b.append(-self.lo[bounded])
        cones = ([clarabel.PSDTriangleConeT(4)] * nb
                 + ([clarabel.NonnegativeConeT(len(bounded))] if len(bounded) else []))
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        P = sp.csc_matrix(np.triu(T.T @ T))
        solution = clarabel.DefaultSolver(P, -(T.T @ e), sp.csc_matrix(np.vstack(blocks)), np.concatenate(b), cones,
                                          settings).solve()
        status = str(solution.status)
        converged = status in ("Solved", "AlmostSolved")
        meaning = ("converged: the minimum over physical bodies" if status == "Solved" else
                   "converged to reduced accuracy: its residuals are small but above its tolerance"
                   if converged else f"stopped without a minimum (Clarabel: {status})")
        return prior.x0 + self.L_inv @ np.asarray(solution.x), SolverOutcome(status, None, converged, meaning)

    def fit(self, weight: float, margin: float = 0.0) -> ConsistentFit:
        """:func:`fit_consistent` of this problem with the prior's weight ``weight``."""
        prior, lower = self.prior, self.lower
        nb, n_in = prior.nb, 10 * prior.nb
        x_lin = self.linear(weight)
        pi0 = prior.x0[:n_in].reshape(nb, 10)
        ok = is_consistent(x_lin[:n_in].reshape(nb, 10) - margin * pi0, 1e-12)
        if ok.all():
            return ConsistentFit(x_lin[:n_in].reshape(nb, 10), x_lin[n_in:], 0.5 * self.objective(x_lin, weight),
                                 "the linear least-squares solution is physically consistent"
                                 + (f" and keeps {margin:g} of the given pseudo-inertias" if margin else ""))
        x, outcome = self.conic(weight, margin)
        x[:n_in] = (margin * pi0 + nearest_consistent(x[:n_in].reshape(nb, 10) - margin * pi0)).ravel()
        x[n_in:] = np.maximum(x[n_in:], lower[n_in:])  # an interior point's last digits
        return ConsistentFit(x[:n_in].reshape(nb, 10), x[n_in:], 0.5 * self.objective(x, weight),
                             f"{int((~ok).sum())} bodies of the linear solution were not physical"
                             + (f" or kept less than {margin:g} of the given pseudo-inertia" if margin else "")
                             + f"; the conic solve {outcome.meaning}",
                             outcome, int((~ok).sum()))


def _lower_in_std(prior: Prior, lower: np.ndarray) -> np.ndarray:
    """The lower bounds of the parameters after the bodies' in standard deviations of the prior (the bodies':
    ``-inf``)."""
    n_in = 10 * prior.nb
    lo = np.full(len(prior.x0), -np.inf)
    lo[n_in:] = (lower[n_in:] - prior.x0[n_in:]) / prior.std
    return lo


def _svec_pseudo_inertia() -> np.ndarray:
    """The linear map (10, 10) from a body's dynamic parameters to its pseudo-inertia's upper triangle,
    column by column, the off-diagonal entries times sqrt(2) (the vectorisation of Clarabel's
    ``PSDTriangleConeT``, under which the Frobenius norm is the Euclidean one)."""
    iu = [(i, j) for j in range(4) for i in range(j + 1)]
    scale = np.array([1.0 if i == j else np.sqrt(2.0) for i, j in iu])
    G = np.empty((10, 10))
    for k, e in enumerate(np.eye(10)):
        J = pin.PseudoInertia.FromDynamicParameters(e).toMatrix()
        G[:, k] = scale * np.array([J[i, j] for i, j in iu])
    return G


def fit_consistent(R: np.ndarray, z: np.ndarray, prior: Prior, weight: float, lower: np.ndarray,
                   margin: float = 0.0) -> ConsistentFit:
    """Solve ``min |R x - z|^2 + weight |L (x - x0)|^2`` over physically consistent bodies that keep
    ``margin`` of the given ones (``J(pi) - margin J(pi_0) >= 0``) and bounded other parameters (friction:
    :data:`FRICTION_LOWER`; armature: >= 0).

    ``x = (pi.ravel(), rest)``; ``x0``, ``L``: the :class:`Prior`. The problem is convex: a quadratic
    over each body's pseudo-inertia constrained positive semidefinite (Wensing et al., *Linear matrix
    inequalities for physically consistent inertial parameter identification*, IEEE RA-L 2018) and
    bounds on the rest. The linear solution with the bounds (:meth:`RegularisedProblem.linear`) is taken when
    every body it gives is physically consistent (:func:`is_consistent`; it is then the minimum);
    otherwise the conic program is solved by Clarabel (:meth:`RegularisedProblem.conic`), and a body left on the
    boundary of the physical set (a flat or a point body, where the minimum often lies) is brought
    just inside (:func:`nearest_consistent`).

    (A log-Cholesky parametrisation solved by ``scipy.optimize.least_squares`` was used before: on the
    KUKA LWR4+ logs it stopped at its evaluation limit with three times the minimum's cost, since a
    body whose optimum is on the boundary has its log-Cholesky optimum at infinity, and its result
    moved with small changes of the weight.)

    Args:
        R, z: the compressed regressor (p, p) and right-hand side (p,), columns ordered as ``x``.
        prior: the given model and its uncertainty.
        weight: the prior's weight (the data's residual variance times the prior's relative weight,
            :mod:`wbfriction.inertia.identification`).
        lower: lower bounds (p,) (those of the bodies' parameters are ignored).
        margin: the share of each given body's pseudo-inertia ``J(pi_0)`` the fit keeps, in [0, 1): its mass, and
            its mass's second moment along every direction about every point, at least ``margin`` times the given
            body's (``J`` is linear in ``pi``, so the constraint is the same cone about ``pi - margin pi_0``). 0: any
            physical body, including the rods and points a base parameter's combination can push a link to
            (:attr:`~wbfriction.inertia.options.InertialOptions.link_margin`).
    """
    return RegularisedProblem(R, z, prior, lower).fit(weight, margin)
