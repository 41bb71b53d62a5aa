"""The inertia model and the friction identified together from walking logs (thesis 2.4, ch. 8).

The thesis found its real-robot friction estimates limited by an inaccurate inertia
model, and proposed a direct identification of the dynamic parameters. The inverse
dynamics are linear in the bodies' inertial parameters
``pi_b = (m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz)`` (about the body's
joint frame; ``pin.Inertia.toDynamicParameters`` order) and, for a fixed tanh slope
``a``, in the Coulomb, viscous and offset parameters of the friction model (3.5)
without its Stribeck term.

**The equations that hold without the contact forces.** In single support the stance
foot is welded to the ground and the robot is a fixed-base tree rooted at it
(:mod:`wbfriction.stance`); every joint row of that tree's inverse dynamics is free of
the contact wrench (which acts at the root). That is the floating-base dynamics
projected into the null space of the stance foot's Jacobian, in the coordinates of the
joint velocities. For torque-controlled joint ``i``:

.. math::

    Y_i(q, \\dot q, \\ddot q)\\,\\pi + F_{v,i}\\,\\dot q_i + F_{c,i}\\tanh(a\\,\\dot q_i) + \\tau_{os,i}
    = \\tau_i - I_{a,i}\\,\\ddot q_i

(``Y`` from ``pin.computeJointTorqueRegressor`` on the stance-rooted tree, its columns
mapped back to the original bodies; ``I_a`` the armature; ``tau_f = -f(qd)`` as in
:mod:`wbfriction.friction`). Position-controlled joints' rows are left out: their
torques are not logged. Stacked over the samples, the system is compressed as it is
built (a QR factorization of the rows seen so far), so long logs need memory of the
size of the parameter vector only.

**Base parameters.** A walk does not excite every parameter; the identifiable
combinations are found numerically by QR with column pivoting of the compressed
regressor (:func:`base_parameters`).

**Physical consistency and prior.** Each body's parameters are written through the
log-Cholesky parametrisation (Rucker & Wensing, *Smooth parameterization of rigid-body
inertia*, IEEE RA-L 2022; ``pin.LogCholeskyParameters``), so every estimate is a
physical rigid body (positive mass, positive-definite pseudo-inertia: the triangle
inequalities hold). A Tikhonov prior pulls the inertias toward the given model where
the data say nothing: its weight is ``prior`` times the largest squared singular value
of the scaled regressor, so only directions weaker than ``sqrt(prior)`` of the
best-excited one follow the prior. The URDF says nothing of friction: the friction
parameters get only the vanishing weight :data:`FRICTION_PRIOR` (which fixes those of a
joint that never moves). Pulled as hard as the inertias toward the friction that best
explains the data with the given model, they kept that model's error: on the demo's
walk, a 5.4 % error of an ankle's offset became 2.4 % without it. The problem is solved
with ``scipy.optimize.least_squares``.

**Choosing the prior.** Too weak a prior lets the barely excited bodies (arms that
hardly move in a walk) take any value that fits the noise of the model; too strong a
one keeps the model error. By default the weight is chosen from :data:`PRIOR_GRID` by
validation: fitted on the training samples but the last ``validation`` share of their
time span, scored by the torque residual on that share (contiguous in time, so that
neighbouring, correlated samples do not score their own fit), then refitted on all of
them. The compressed systems give every score without another pass over the log. The
weights are tried from strong to weak, and the search stops at the first weight that
scores worse than the best. (Each fit starts from the linear solution: started from a
neighbouring weight's, the non-linear solve stalls short of it.)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
import scipy.linalg
from scipy.optimize import least_squares, lsq_linear

from .estimate import EstimateOptions, stance_frame_pose
from .exceptions import InputError
from .kinematics import MeasuredKinematics, measure
from .log import Log
from .phases import segment
from .robot import Robot
from .stance import StanceModel, body_frame, stance_model

PARAMS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
"""The ten inertial parameters of a body, in ``pin.Inertia.toDynamicParameters`` order
[kg, kg·m, kg·m^2]: mass, first moments, rotational inertia about the joint frame."""
FRICTION = ("F_v", "F_c", "tau_os")
"""Friction parameters identified per torque-controlled joint (3.5 without Stribeck)."""
PRIOR_GRID = (1e-10, 1e-9, 1e-8, 1e-7, 1e-6)
"""Relative prior weights tried when :attr:`InertialOptions.prior` is None."""
FRICTION_PRIOR = 1e-12
"""Relative weight of the friction parameters' prior (module docstring)."""
STRIBECK = "F_s-F_c"
"""With a fixed Stribeck velocity ``v_s``, the Stribeck term's height ``F_s - F_c = S F_c`` [N·m]
too (``F_s`` the static friction of 3.4, ``S`` that of :func:`wbfriction.friction.smooth`)."""
FRICTION_LOWER = {"F_v": 0.0, "F_c": 0.0, "tau_os": -np.inf, STRIBECK: 0.0}
"""Physical friction: dissipative viscous and Coulomb parts, static friction at least the
Coulomb level (the bounds of :data:`wbfriction.identify.LOWER`); the offset is free."""


def body_parameters(model: pin.Model) -> np.ndarray:
    """The inertial parameters of every body (joint) of ``model``, (n_bodies, 10)."""
    return np.array([model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)])


def with_body_parameters(model: pin.Model, pi: np.ndarray) -> pin.Model:
    """A copy of ``model`` with body ``j``'s inertia from row ``j - 1`` of ``pi`` (n_bodies, 10)."""
    out = pin.Model(model)
    for j in range(1, model.njoints):
        out.inertias[j] = pin.Inertia.FromDynamicParameters(np.asarray(pi[j - 1], dtype=float))
    return out


def act_matrix(placement: pin.SE3) -> np.ndarray:
    """The linear map (10, 10) of ``placement.act`` on dynamic parameters: the parameters
    of a body expressed in a frame whose pose in the current one is ``placement``...
    i.e. ``toDynamicParameters(placement.act(I)) = A @ toDynamicParameters(I)``."""
    ref = np.array([1.0, 0, 0, 0, 1, 0, 1, 0, 0, 1])  # unit mass, unit inertia: the map is affine-free
    base = placement.act(pin.Inertia.FromDynamicParameters(ref)).toDynamicParameters()
    cols = []
    for k in range(10):
        e = ref.copy()
        e[k] += 1.0
        cols.append(placement.act(pin.Inertia.FromDynamicParameters(e)).toDynamicParameters() - base)
    return np.array(cols).T


@dataclass
class StanceRegressor:
    """Joint-torque regressor of the robot standing on one contact frame.

    The regressor of the stance-rooted tree is in the parameters of its own bodies, each
    expressed in the frame of the rooted joint that carries it; :attr:`to_rooted` maps the
    original model's parameters to those (a fixed linear map, so that a least-squares
    system built in rooted parameters is mapped once, not row by row).

    Attributes:
        stance: the stance-rooted model (:mod:`wbfriction.stance`).
        to_rooted: (10 n_bodies, 10 n_bodies): ``pi_rooted = to_rooted @ pi.ravel()``.
    """

    stance: StanceModel
    to_rooted: np.ndarray
    data: pin.Data = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.data = self.stance.model.createData()

    def joint_rows(self, frame_pose: np.ndarray, angles: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """``Y`` with ``Y @ to_rooted @ pi.ravel() = S (M qdd + h - J^T lambda)`` (without the
        armature): the generalized forces of the actuated joints, for each sample.

        Args:
            frame_pose: world pose of the stance frame (N, 7) (x, y, z, qx, qy, qz, qw).
            angles, qd, qdd: actuated joints' positions, velocities, accelerations (N, n_act).

        Returns:
            (N, n_act, 10 n_bodies), in the original joints' signs.
        """
        model, st = self.stance.model, self.stance
        q = st.layout.configuration(angles, frame_pose, st.sign)
        n = angles.shape[0]
        Y = np.empty((n, len(st.v_index), 10 * (model.njoints - 1)))
        v = np.zeros(model.nv)
        a = np.zeros(model.nv)
        for k in range(n):
            v[st.v_index] = qd[k] * st.sign
            a[st.v_index] = qdd[k] * st.sign
            Y[k] = pin.computeJointTorqueRegressor(model, self.data, q[k], v, a)[st.v_index]
        return Y * st.sign[None, :, None]


def stance_regressor(robot: Robot, contact_index: int) -> StanceRegressor:
    """The regressor of ``robot`` standing on contact ``contact_index`` (built once)."""
    key = ("regressor", contact_index)
    if key not in robot.cache:
        stance = stance_model(robot, contact_index)
        nb = robot.model.njoints - 1
        T = np.zeros((10 * nb, 10 * nb))
        for j in range(1, robot.model.njoints):
            f = stance.model.frames[stance.model.getFrameId(body_frame(j))]
            c = f.parentJoint - 1
            T[10 * c:10 * c + 10, 10 * (j - 1):10 * j] = act_matrix(f.placement)
        robot.cache[key] = StanceRegressor(stance, T)
    return robot.cache[key]


class CompressedLeastSquares:
    """``min |A x - b|^2`` over rows added block by block, kept as the triangular factor
    ``R`` (p, p) and ``z`` (p,) of the rows seen so far (``|A x - b|^2 = |R x - z|^2 + const``):
    memory of the size of ``x``, not of the data."""

    def __init__(self, n_params: int):
        self.n = n_params
        self._Rz = np.zeros((0, n_params + 1))
        self._floor = 0.0
        self.rows = 0

    def add(self, A: np.ndarray, b: np.ndarray) -> None:
        """Append rows ``A`` (m, p) with right-hand sides ``b`` (m,)."""
        stacked = np.vstack([self._Rz, np.column_stack([A, b])])
        self._Rz = scipy.linalg.qr(stacked, mode="r", overwrite_a=True, check_finite=False)[0][: self.n + 1]
        self.rows += len(b)

    def absorb(self, other: "CompressedLeastSquares", T: np.ndarray | None = None) -> None:
        """Append the rows of ``other`` (whose parameters are ``T @ x``, (p_other, p); identity if None)."""
        if other.rows == 0:
            return
        self.add(other.R if T is None else other.R @ T, other.z)
        self.rows += other.rows - other.n
        self._floor += other.residual_floor

    @property
    def residual_floor(self) -> float:
        """The smallest ``|A x - b|^2`` (so ``|A x - b|^2 = |R x - z|^2 + residual_floor``)."""
        corner = self._Rz[self.n, self.n] if self._Rz.shape[0] > self.n else 0.0
        return float(corner ** 2) + self._floor

    def rms(self, x: np.ndarray) -> float:
        """RMS of ``A x - b`` over the rows added."""
        r = self.R @ x - self.z
        return float(np.sqrt((r @ r + self.residual_floor) / max(self.rows, 1)))

    @property
    def R(self) -> np.ndarray:
        return np.triu(self._Rz[: self.n, : self.n])

    @property
    def z(self) -> np.ndarray:
        return self._Rz[: self.n, self.n]



@dataclass(frozen=True)
class BaseParameters:
    """The identifiable combinations of the parameters (base parameters).

    Attributes:
        independent: indices of the parameters chosen as base parameters (r,), the pivots
            of a QR factorization with column pivoting of the regressor.
        combination: (r, p): base parameter ``k`` is ``combination[k] @ x``, i.e. its
            independent parameter plus the dependent ones it absorbs.
        condition: condition number of the regressor's base-parameter columns, each scaled to
            unit norm (so that it does not depend on units).
        rank_tolerance: relative size of a pivot below which a column counts as dependent.
    """

    independent: np.ndarray
    combination: np.ndarray
    condition: float
    rank_tolerance: float

    @property
    def count(self) -> int:
        return len(self.independent)


def base_parameters(R: np.ndarray, rank_tolerance: float = 1e-8) -> BaseParameters:
    """Base parameters of a regressor given by its triangular factor ``R`` (p, p)
    (:class:`CompressedLeastSquares`; ``R`` and the stacked regressor have the same
    column dependencies), by QR with column pivoting: ``R P = Q [R1 R2]``, rank ``r`` where
    ``|R1_kk| > rank_tolerance |R1_11|``; the dependent columns are ``R1^-1 R2`` times
    the independent ones, so the base parameters are ``x_indep + R1^-1 R2 x_dep``.

    Columns are scaled to unit norm first, so the rank does not depend on units.
    """
    norms = np.linalg.norm(R, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    _, r_fac, perm = scipy.linalg.qr(R / scale, mode="economic", pivoting=True)
    diag = np.abs(np.diag(r_fac))
    rank = int(np.sum(diag > rank_tolerance * diag[0])) if diag.size and diag[0] > 0 else 0
    R1, R2 = r_fac[:rank, :rank], r_fac[:rank, rank:]
    K = scipy.linalg.solve_triangular(R1, R2)  # scaled dependent -> independent
    combination = np.zeros((rank, R.shape[1]))
    ind, dep = perm[:rank], perm[rank:]
    combination[np.arange(rank), ind] = 1.0
    combination[:, dep] = K * scale[dep][None, :] / scale[ind][:, None]
    s = np.linalg.svd((R / scale)[:, ind], compute_uv=False)
    return BaseParameters(np.sort(ind), combination[np.argsort(ind)], float(s[0] / s[-1]) if rank else np.inf,
                          rank_tolerance)


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


def _parameters(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


def _friction_lower(k: int, n_tc: int) -> np.ndarray:
    """Lower bounds (k n_tc,) of the friction parameters, the first ``k`` of ``(F_v, F_c, tau_os, F_s-F_c)``
    per joint (:data:`FRICTION_LOWER`)."""
    return np.tile([FRICTION_LOWER[n] for n in (*FRICTION, STRIBECK)[:k]], n_tc)


def _regularised(R: np.ndarray, z: np.ndarray, pi0: np.ndarray, friction0: np.ndarray, prior: float,
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
    lower = np.concatenate([np.full(10 * nb, -np.inf), _friction_lower(*friction0.shape[::-1])])
    x_lin, A, c = _regularised(R, z, pi0, friction0, prior, min_mass, lower)
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
        pi, jac = _parameters(v[: 10 * nb].reshape(nb, 10))
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


@dataclass(frozen=True)
class InertialOptions:
    """Options of :func:`identify_inertia`.

    Attributes:
        tanh_slope: ``a`` of the Coulomb term ``F_c tanh(a qd)`` [s/rad].
        stribeck_velocity: ``v_s`` [rad/s] of a Stribeck term ``(F_s - F_c) tanh(a qd) exp(-(qd/v_s)^2)``
            identified with the others (3.5 with ``delta_s = 2``; ``F_s - F_c = S F_c``), for
            example the one the acceleration route's fit found; None: no Stribeck term.
        stribeck_joints: the joints given the Stribeck term (None: every torque-controlled
            one). A joint that never moves faster than ``v_s`` cannot tell it from Coulomb
            friction: their columns would cancel with huge opposite values.
        stride: every ``stride``-th single-support sample enters the regression (1 kHz
            logs are far denser than the dynamics need).
        holdout: share of the log, at its end, kept out of the regression to compare the
            models' torque predictions.
        prior: relative weight of the prior toward the given model (:func:`fit_consistent`);
            None: chosen from :data:`PRIOR_GRID` by validation (module docstring).
        validation: share of the training samples' time span, at its end, that scores
            the priors of the grid.
        rank_tolerance: relative pivot below which a parameter is not identifiable
            (:func:`base_parameters`).
        min_mass: smallest mass a body's starting point gets [kg].
        block: samples per block of the compressed regression.
    """

    tanh_slope: float = 40.0
    stribeck_velocity: float | None = None
    stribeck_joints: tuple[str, ...] | None = None
    stride: int = 5
    holdout: float = 0.2
    prior: float | None = None
    validation: float = 0.25
    rank_tolerance: float = 1e-8
    min_mass: float = 1e-3
    block: int = 200


@dataclass
class TorqueFit:
    """RMS of measured minus predicted joint torques per torque-controlled joint [N·m]."""

    given: np.ndarray
    given_with_friction: np.ndarray
    identified: np.ndarray
    samples: int


@dataclass
class InertialIdentification:
    """What :func:`identify_inertia` found.

    Attributes:
        robot: the robot with the identified inertias (same structure as the given one).
        bodies: body names (the Pinocchio joint carrying each body) (nb,).
        pi_given, pi: inertial parameters of the given and identified model (nb, 10).
        friction_names: the friction parameters (:func:`friction_names`), k of them.
        friction: identified friction parameters per torque-controlled joint (n_tc, k).
        friction_given_model: the physical friction (:data:`FRICTION_LOWER`) that best
            explains the data with the given inertias (n_tc, k).
        base: the base parameters, over ``(pi.ravel(), friction.ravel())``.
        holdout: torque predictions on the held-out samples.
        samples: single-support samples in the regression.
        message: the optimizer's.
        prior: the prior's relative weight used.
        prior_scores: with the prior chosen by validation, the RMS torque residual on the
            validation samples for each weight tried [N·m].
    """

    robot: Robot
    bodies: tuple[str, ...]
    pi_given: np.ndarray
    pi: np.ndarray
    friction_names: tuple[str, ...]
    friction: np.ndarray
    friction_given_model: np.ndarray
    base: BaseParameters
    holdout: TorqueFit
    samples: int
    message: str
    prior: float
    prior_scores: dict[float, float] = field(default_factory=dict)


def friction_names(options: "InertialOptions") -> tuple[str, ...]:
    """The friction parameters identified per joint with ``options``."""
    return FRICTION + ((STRIBECK,) if options.stribeck_velocity is not None else ())


def _friction_columns(qd_tc: np.ndarray, options: "InertialOptions", stribeck: np.ndarray | None = None) -> np.ndarray:
    """(N, n_tc, k n_tc): joint ``i``'s row holds ``qd_i, tanh(a qd_i), 1`` (and the Stribeck
    column ``tanh(a qd_i) exp(-(qd_i / v_s)^2)`` where ``stribeck[i]``, else zero) in its ``k``
    columns, ``f(qd) = columns @ params``."""
    n, m = qd_tc.shape
    k = len(friction_names(options))
    out = np.zeros((n, m, k * m))
    idx = np.arange(m)
    coulomb = np.tanh(options.tanh_slope * qd_tc)
    out[:, idx, k * idx] = qd_tc
    out[:, idx, k * idx + 1] = coulomb
    out[:, idx, k * idx + 2] = 1.0
    if k == 4:
        on = np.ones(m, dtype=bool) if stribeck is None else stribeck
        out[:, idx, k * idx + 3] = coulomb * np.exp(-(qd_tc / options.stribeck_velocity) ** 2) * on
    return out


def _split(robot: Robot, log: Log, est: EstimateOptions, opts: InertialOptions):
    """Per log part: its kinematics, stance, and the training, validation and held-out
    single-support rows."""
    span = log.time[-1] - log.time[0]
    cut = log.time[0] + (1.0 - opts.holdout) * span
    cut_validation = log.time[0] + (1.0 - opts.holdout) * (1.0 - opts.validation) * span
    out = []
    for part in log.parts():
        try:
            kin = measure(part, est.diff, compensate_delay=est.compensate_delay,
                          torque_alignment=est.torque_alignment, filtering=est.filtering)
        except InputError:
            continue  # too short for the scheme: nothing to learn from it
        phases = segment(kin.time, kin.contact, est.lift_off_skip, est.touch_down_skip)
        use = kin.valid & phases.keep
        train = np.zeros_like(use)
        idx = np.flatnonzero(use & (part.time < cut))
        train[idx[:: opts.stride]] = True
        held = use & (part.time >= cut)
        validation = train & (part.time >= cut_validation)
        out.append((kin, phases.stance, train & ~validation, validation, held))
    return out


def _rows(robot: Robot, kin: MeasuredKinematics, r: np.ndarray, c: int, options: InertialOptions):
    """Regressor rows (rooted parameters), friction columns and right-hand side of samples ``r``."""
    reg = stance_regressor(robot, c)
    tc = robot.tc_index
    pose = stance_frame_pose(robot, reg.stance, kin.q[r], None if kin.base is None else kin.base[r])
    Y = reg.joint_rows(pose, kin.q[r], kin.qd[r], kin.qdd[r])[:, tc]
    stribeck = None if options.stribeck_joints is None else np.isin(robot.torque_controlled, options.stribeck_joints)
    F = _friction_columns(kin.qd[r][:, tc], options, stribeck)
    arm = robot.model.armature[robot.act_v_index][tc]
    b = kin.tau[r] - arm * kin.qdd[r][:, tc]
    return Y, F, b


def identify_inertia(robot: Robot, log: Log, estimate_options: EstimateOptions = EstimateOptions(),
                     options: InertialOptions = InertialOptions(), progress=None) -> InertialIdentification:
    """Identify every body's inertial parameters and the joints' Coulomb, viscous and
    offset friction from a walking log (module docstring), starting from and regularised
    toward ``robot``'s model.

    Args:
        robot: the given model.
        log: a log with single-support stretches.
        estimate_options: differentiation, torque alignment and phase margins, as for the
            friction estimate (:class:`~wbfriction.estimate.EstimateOptions`).
        options: :class:`InertialOptions`.
        progress: optional callable receiving numbers of samples done.

    Returns:
        :class:`InertialIdentification`.

    Raises:
        InputError: no single-support sample to learn from, or none held out.
    """
    parts = _split(robot, log, estimate_options, options)
    nb, n_tc = robot.model.njoints - 1, len(robot.torque_controlled)
    k = len(friction_names(options))
    p_in = 10 * nb
    fitting = _system(robot, parts, 2, options, progress)
    validating = _system(robot, parts, 3, options, progress)
    samples = (fitting.rows + validating.rows) // n_tc
    if samples == 0:
        raise InputError(f"{log.source}: no single-support sample to identify the inertia model from")
    total = CompressedLeastSquares(fitting.n)
    for system in (fitting, validating):
        total.absorb(system)
    R, z = total.R, total.z
    pi0 = body_parameters(robot.model)
    # physical friction that best explains the data with the given inertias: the start, and the given model's best case
    friction0 = lsq_linear(R[:, p_in:], z - R[:, :p_in] @ pi0.ravel(), bounds=(_friction_lower(k, n_tc), np.inf),
                           method="bvls").x.reshape(n_tc, k)
    base = base_parameters(R, options.rank_tolerance)
    prior, scores = options.prior, {}
    if prior is None:
        if fitting.rows == 0 or validating.rows == 0:
            raise InputError(f"{log.source}: too few single-support samples to choose the prior by validation "
                             "(give one)")
        for weight in sorted(PRIOR_GRID, reverse=True):  # strong to weak
            trial = fit_consistent(fitting.R, fitting.z, pi0, friction0, weight, options.min_mass)
            scores[weight] = validating.rms(np.concatenate([trial.pi.ravel(), trial.friction.ravel()]))
            if scores[weight] > min(scores.values()):
                break  # past the best weight: weaker priors only fit the noise more closely
        prior = min(scores, key=scores.get)
    fit = fit_consistent(R, z, pi0, friction0, prior, options.min_mass)
    if k == len(FRICTION) + 1 and options.stribeck_joints is not None:  # no column: no Stribeck term, not a bound
        fit.friction[~np.isin(robot.torque_controlled, options.stribeck_joints), -1] = 0.0
    identified = dataclasses.replace(robot, model=with_body_parameters(robot.model, fit.pi), cache={})
    holdout = _torque_fit(robot, parts, pi0, friction0, fit, options)
    if holdout.samples == 0:
        raise InputError(f"{log.source}: no single-support sample in the held-out {options.holdout:.0%} of the log")
    return InertialIdentification(identified, tuple(robot.model.names[1:]), pi0, fit.pi, friction_names(options),
                                  fit.friction, friction0, base, holdout, samples, fit.message, prior, scores)


def _system(robot: Robot, parts, which: int, options: InertialOptions, progress=None) -> CompressedLeastSquares:
    """The compressed system of the rows ``part[which]`` of every part (:func:`_split`), in
    the original bodies' parameters: per stance, built in its rooted parameters, then mapped."""
    nb, n_tc = robot.model.njoints - 1, len(robot.torque_controlled)
    k = len(friction_names(options))
    p = 10 * nb + k * n_tc
    systems = {c: CompressedLeastSquares(p) for c in range(len(robot.contact_frames))}
    for part in parts:
        kin, stance, rows = part[0], part[1], part[which]
        for c, system in systems.items():
            r = np.flatnonzero(rows & (stance == c))
            for start in range(0, r.size, options.block):
                rr = r[start:start + options.block]
                Y, F, b = _rows(robot, kin, rr, c, options)
                system.add(np.concatenate([Y, F], axis=2).reshape(-1, p), b.ravel())
                if progress is not None:
                    progress(rr.size)
    total = CompressedLeastSquares(p)
    for c, system in systems.items():
        if system.rows:
            total.absorb(system, scipy.linalg.block_diag(stance_regressor(robot, c).to_rooted, np.eye(k * n_tc)))
    return total


def _torque_fit(robot: Robot, parts, pi0: np.ndarray, friction0: np.ndarray, fit: ConsistentFit,
                options: InertialOptions) -> TorqueFit:
    """RMS torque errors of the given model (without and with its best friction) and of the
    identified one on the held-out samples."""
    n_tc = len(robot.torque_controlled)
    sq = np.zeros((3, n_tc))
    count = 0
    for part in parts:
        kin, stance, *_, rows = part
        for c in range(len(robot.contact_frames)):
            r = np.flatnonzero(rows & (stance == c))
            for start in range(0, r.size, 1000):
                rr = r[start:start + 1000]
                Y, F, b = _rows(robot, kin, rr, c, options)
                T = stance_regressor(robot, c).to_rooted
                given = Y @ (T @ pi0.ravel())
                preds = (given, given + F @ friction0.ravel(), Y @ (T @ fit.pi.ravel()) + F @ fit.friction.ravel())
                for k, pred in enumerate(preds):
                    sq[k] += np.sum((pred - b) ** 2, axis=0)
                count += rr.size
    rms = np.sqrt(sq / max(count, 1))
    return TorqueFit(rms[0], rms[1], rms[2], count)
