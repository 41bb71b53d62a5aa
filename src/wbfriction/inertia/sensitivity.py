"""Sensitivity of the friction estimate to inertia-model errors (thesis 7.2, Fig. 7.5, 7.6).

The estimate ``tau_f = M_mod Delta qdd`` (5.13) inherits every error of the inertia model.
The thesis scaled each rigid body's 6x6 spatial inertia ``M_i`` and re-ran the estimate:

* ``all``: ``M_i <- f M_i`` (mass, first moment and rotational inertia alike, Fig. 7.5);
* ``mass`` / ``rotational``: through the eigendecomposition of ``M_i``, only the eigenvalues
  of the mass or of the principal moments of inertia are scaled, and the matrix is
  transformed back (Fig. 7.6).

The eigendecomposition is taken about the body's centre of mass, where the spatial inertia
is block-diagonal, ``M_i = diag(m 1_3, I_c)``: its eigenvalues are the mass (three times,
eigenvectors in the linear part) and the principal moments ``I_c = R diag(I_1, I_2, I_3) R^T``
(eigenvectors along the principal axes). Scaling one set and transforming back gives a
physically consistent rigid body with the same centre of mass and principal axes:
``mass`` scales ``m`` (hence ``m c`` and the parallel-axis terms elsewhere), ``rotational``
scales ``I_c`` only. (About another point the eigenvectors mix the linear and angular parts,
and scaling a subset of eigenvalues does not give a rigid-body inertia.)

Thesis findings, reproduced on simulated logs (tests): a mass error shifts the friction
curve (up or down with the sign of the gravity torque the model gets wrong); a
rotational-inertia error leaves the curve in place but splits it into branches for rising
and falling velocity (its error is proportional to the acceleration); both produce friction
that generates power (:mod:`wbfriction.fit.energy`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import FrictionEstimate, estimate_resolved, resolve_differentiation
from wbfriction.friction.options import EstimateOptions
from wbfriction.friction.route import resolve_route
from wbfriction.inertia.options import PARTS, InertiaPart
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress


def principal_inertia(inertia: pin.Inertia) -> tuple[np.ndarray, np.ndarray]:
    """Eigendecomposition of the rotational block of the spatial inertia about the centre
    of mass: principal moments ``(3,)`` [kg·m^2] (ascending) and axes ``R`` (3, 3) (columns),
    ``I_c = R diag(moments) R^T``."""
    moments, axes = np.linalg.eigh(np.asarray(inertia.inertia))
    return moments, axes


def scale_inertia(inertia: pin.Inertia, factor: float, part: InertiaPart = "all") -> pin.Inertia:
    """One body's spatial inertia with its mass and/or principal-moment eigenvalues scaled
    (module docstring).

    Args:
        inertia: the body's inertia (mass, centre of mass ``c`` in the body frame, ``I_c``).
        factor: scaling factor (> 0).
        part: ``all``, ``mass`` or ``rotational``.

    Returns:
        A new :class:`pinocchio.Inertia` with the same centre of mass.

    Raises:
        InputError: unknown ``part`` or a factor <= 0.
    """
    if part not in PARTS:
        raise InputError(f"unknown inertia part '{part}': choose one of {', '.join(PARTS)}")
    if not factor > 0:
        raise InputError(f"inertia scaling factor must be > 0, got {factor}")
    moments, axes = principal_inertia(inertia)
    f_mass = factor if part in ("all", "mass") else 1.0
    f_rot = factor if part in ("all", "rotational") else 1.0
    I_c = axes @ np.diag(f_rot * moments) @ axes.T
    return pin.Inertia(f_mass * inertia.mass, np.asarray(inertia.lever).copy(), 0.5 * (I_c + I_c.T))


def scaled_robot(robot: Robot, factor: float, part: InertiaPart = "all") -> Robot:
    """A copy of ``robot`` whose every body (the base included) has its inertia scaled by
    :func:`scale_inertia`; derived models (stance trees) are rebuilt from it."""
    model = pin.Model(robot.model)
    for j in range(1, model.njoints):
        model.inertias[j] = scale_inertia(model.inertias[j], factor, part)
    return dataclasses.replace(robot, model=model, cache={})


@dataclass
class JointSensitivity:
    """Change of one joint's estimate for one scaling factor, against the unscaled model.

    Attributes:
        joint, factor: the joint and the factor.
        shift: mean of ``tau_f(f) - tau_f(1)`` over the valid samples [N·m]: the curve's
            vertical displacement (Fig. 7.5).
        split: mean of that change over samples of rising velocity minus its mean over
            samples of falling velocity [N·m]: how far the branches separate (Fig. 7.6).
        generating_share: share of valid samples whose friction generates power
            (:func:`wbfriction.fit.energy.generating_share`, the given offset removed).
    """

    joint: str
    factor: float
    shift: float
    split: float
    generating_share: float


@dataclass
class Sensitivity:
    """Estimates of one log under scaled inertia models.

    Attributes:
        part: ``all``, ``mass`` or ``rotational``.
        factors: the factors, 1.0 (the model as given) first.
        estimates: one :class:`~wbfriction.friction.estimate.FrictionEstimate` per factor.
    """

    part: InertiaPart
    factors: tuple[float, ...]
    estimates: tuple[FrictionEstimate, ...]

    @property
    def reference(self) -> FrictionEstimate:
        return self.estimates[0]

    def reference_offsets(self, joints: list[str]) -> dict[str, float]:
        """The torque offset ``tau_os`` of model (3.5) fitted to the reference estimate of each
        joint [N·m] (0 where too few samples): the offset to remove before the power check
        of every factor (:meth:`joint`)."""
        from wbfriction.fit.joints import fit_joints
        from wbfriction.fit.result import fitted_offsets

        ref = self.reference
        idx = [ref.joints.index(j) for j in joints]
        fits = fit_joints(joints, ref.qd[:, idx], ref.tau_f[:, idx], ref.valid[:, idx])
        return {j: 0.0 for j in joints} | fitted_offsets(fits)

    def reference_share(self, joint: str, tau_os: float = 0.0) -> float:
        """Share of the reference estimate's valid samples of ``joint`` that generate power."""
        from wbfriction.fit.energy import generating_share

        ref = self.reference
        i = ref.joints.index(joint)
        return generating_share(ref.qd[ref.valid[:, i], i], ref.tau_f[ref.valid[:, i], i], tau_os)

    def joint(self, joint: str, tau_os: float = 0.0) -> list[JointSensitivity]:
        """:class:`JointSensitivity` of ``joint`` for every factor but the reference; ``tau_os``:
        the torque offset [N·m] removed before the power check (e.g. the one identified on the
        reference: an offset refitted per factor would absorb the mass error's shift)."""
        from wbfriction.fit.energy import generating_share

        ref = self.reference
        i = ref.joints.index(joint)
        rising = np.gradient(ref.qd[:, i], ref.time) > 0
        out = []
        for f, est in zip(self.factors[1:], self.estimates[1:]):
            valid = ref.valid[:, i] & est.valid[:, i]
            change = est.tau_f[:, i] - ref.tau_f[:, i]
            up, down = valid & rising, valid & ~rising
            split = float(np.mean(change[up]) - np.mean(change[down])) if up.any() and down.any() else float("nan")
            out.append(JointSensitivity(joint, f, float(np.mean(change[valid])) if valid.any() else float("nan"),
                                        split, generating_share(est.qd[valid, i], est.tau_f[valid, i], tau_os)))
        return out


def parse_factors(text: str) -> tuple[float, ...]:
    """``"0.9,0.95,1.05"`` -> (0.9, 0.95, 1.05).

    Raises:
        InputError: a value that is not a positive number, or none at all.
    """
    try:
        values = tuple(float(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise InputError(f"--factors must be comma-separated numbers, got '{text}'") from None
    if not values or any(not v > 0 for v in values):
        raise InputError(f"--factors must be positive numbers, got '{text}'")
    return values


def inertia_sensitivity(robot: Robot, log: Log, factors, part: InertiaPart = "all",
                        options: EstimateOptions = EstimateOptions(),
                        progress: StageProgress | None = None) -> Sensitivity:
    """Re-run the estimate of a log with every body's inertia scaled, by the route and differentiation its options
    resolve to once (:func:`~wbfriction.friction.estimate.resolve_differentiation`,
    :func:`~wbfriction.friction.route.resolve_route`), without the other route's check.

    Args:
        robot: the model as given (factor 1).
        log: the log.
        factors: scaling factors (> 0); 1.0 is added first as the reference.
        part: ``all``, ``mass`` or ``rotational`` (:func:`scale_inertia`).
        options: estimator options.
        progress: optional callable(label) called before each estimate.

    Raises:
        InputError: bad ``part`` or factors, or what :func:`~wbfriction.friction.estimate.estimate_log` raises.
    """
    if part not in PARTS:
        raise InputError(f"unknown inertia part '{part}': choose one of {', '.join(PARTS)}")
    factors = (1.0, *[float(f) for f in factors if f != 1.0])
    options, _ = resolve_differentiation(options, log)
    options, _ = resolve_route(dataclasses.replace(options, check_route=False), log)
    estimates = []
    for f in factors:
        if progress is not None:
            progress(f"estimate with {part} inertia x {f:g}")
        model = robot if f == 1.0 else scaled_robot(robot, f, part)
        estimates.append(estimate_resolved(model, log, options))
    return Sensitivity(part, factors, tuple(estimates))
