"""How well a motion determines each parameter: the Cramér-Rao bound of the model's own Fisher information, and the
share of its status's limit it comes to (what ``excite`` minimises).

**A joint whose torque is measured** (an arm's sensors or currents; ``estimate`` then ``fit``): its friction
``f(qd; p)`` is measured sample by sample with the noise of :mod:`wbfriction.fit.bound` (the torque's white noise,
and the positions' seen through the joint's inertia and a second derivative), so the information of a motion is
that module's ``I = J^T Sigma^-1 J`` with ``J`` the family's Jacobian at the motion's velocities
(:func:`torque_bound`): the fit's own bound, on the motion designed instead of the motion logged.

**The criterion.** A fit is ``weak`` when a standard error exceeds :data:`~wbfriction.fit.status.WEAK` of what the
parameter stands for (:func:`~wbfriction.fit.status.verdict`): F_c and F_v their own values, ``tau_os`` the joint's
F_c. The share of that limit a bound comes to, ``rho = bound / (WEAK x scale)`` (:func:`limit_shares`), is below 1
for a parameter the motion determines well enough to be ``ok``, whatever its unit; a design minimises the largest
``rho`` over the parameters asked for (the worst relative Cramér-Rao bound: E-optimality on the statuses' scale,
rather than D-optimality, whose determinant a well-determined parameter can carry while another stays weak).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from wbfriction.fit.bound import cramer_rao
from wbfriction.fit.status import WEAK
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.friction.families.registry import family
from wbfriction.friction.noise import NoiseModel

FRICTION_READ = ("F_c", "F_v")
"""The parameters ``excite`` asks a torque-measured joint's motion to determine by default (what a user reads off a
fit, :data:`~wbfriction.fit.status.READ`)."""


def scales(params: ModelParamsBase, names: Sequence[str]) -> np.ndarray:
    """What each parameter of ``names`` is judged against (n,) (module docstring): its own value, ``tau_os`` the
    joint's F_c; a parameter at zero: 1 of its unit."""
    q = params.quantities()
    values = np.array([abs(q["F_c"]) if n == "tau_os" else abs(float(getattr(params, n))) for n in names])
    return np.where(values > 0, values, 1.0)


def torque_bound(params: ModelParamsBase, qd: np.ndarray, noise: NoiseModel) -> dict[str, float]:
    """The Cramér-Rao bound [the parameter's unit] of each of ``params``' family's parameters, from a motion's
    velocities ``qd`` (N,) [rad/s] sampled every ``noise.dt`` (one stretch) and the joint's ``noise``
    (:func:`~wbfriction.fit.bound.cramer_rao`): infinite for a parameter the motion does not determine."""
    fam = family(params.model)
    x = params.as_vector()
    jac = fam.jacobian(x, np.asarray(qd, dtype=float), float(getattr(params, "delta_s", 2.0)))
    cov = cramer_rao(jac, np.arange(len(qd)), noise)
    return dict(zip(fam.names, map(float, np.sqrt(np.clip(np.diag(cov), 0.0, None)))))


def limit_shares(bound: Mapping[str, float], params: ModelParamsBase, asked: Sequence[str]) -> np.ndarray:
    """``rho`` (n,) of each parameter of ``asked`` (module docstring): its bound over :data:`WEAK` of its scale."""
    return np.array([bound[n] for n in asked]) / (WEAK * scales(params, asked))
