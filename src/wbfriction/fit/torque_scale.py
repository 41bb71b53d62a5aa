"""The logged torque's scale uncertainty in the friction's standard errors.

A logged torque is a measurement times a scale known only so well: a motor's current times a torque constant from a
data sheet (a few per cent, and it moves with the magnets' temperature), a torque sensor through its calibration. A
relative scale error ``eps`` of joint ``j``'s torque makes the friction estimated on a swinging leg, a hung robot or
an arm,

.. math:: \\tau_{f,j} = (M \\ddot q + h)_j - (1 + \\epsilon)\\,\\tau_j,

off by ``-eps tau_j`` on every sample at once: the joint's whole torque, its gravity and inertia included, so 2 % of
a 5 N·m swing torque is 0.1 N·m, a sixth of a calf's Coulomb friction. The error is the same in every block of the
log, so no statistical error sees it (as a bias both routes share: :mod:`~wbfriction.fit.route_spread`), and a
friction fitted on a torque 2 % off can be ``ok`` several standard errors from the truth.

**How it enters.** The fit's values move with the data as its least squares linearised at them: ``dtheta = J^+ dy``,
``J = S dE[f]/dtheta`` the derivatives of the model the fit matched (its expectation under the velocity's noise,
:mod:`~wbfriction.fit.eiv`, through the estimate's smoother ``S`` along the whole series) on the samples fitted, over
the parameters the fit left free (those held, at a bound or not identifiable do not move). With ``dy = eps S tau``
and ``eps`` of standard deviation ``sigma`` (the robot TOML's ``[torque_scale_sd]``), F_c's and F_v's standard
errors from the scale are ``sigma |J^+ S tau|`` (:func:`torque_scale_spread`); they enter the fit's model spread in
quadrature (:attr:`~wbfriction.fit.result.FitResult.model_spread`), as the PD drivers' delay structure does, and
with it the error a user reads and the status.

**Limits.** On a floating base in contact, the contact forces solved for carry the other joints' torques too (each
with its own error); the joint's own row is taken alone, exact on a swinging leg, an arm or a hung robot. The
linearisation holds for errors of a few per cent, the range a scale is known to.

Sign convention: ``tau_f = -f(qd)``, the torque friction exerts on the joint (the README's).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.friction.families.registry import family


def torque_scale_spread(params: ModelParamsBase, qd: np.ndarray, tau: np.ndarray, rows: np.ndarray, sd: float,
                        free: Iterable[str], *, smoother: Callable[[np.ndarray], np.ndarray] | None = None,
                        velocity_noise: float = 0.0, magnitudes: Iterable[str] = ("F_c", "F_v")) -> dict[str, float]:
    """Per name of ``magnitudes`` the fit left free, the standard error its value takes from a torque scale known to
    ``sd`` (module docstring) [the parameter's unit].

    Args:
        params: the fitted model.
        qd, tau: (N,) the whole series' velocities [rad/s] and logged torques [N·m] (the smoother runs along it).
        rows: (N,) bool, the samples fitted.
        sd: the torque scale's relative standard deviation (0.02: 2 %), >= 0.
        free: the parameters the fit left free (held, at-bound and unidentifiable ones left out).
        smoother: the estimate's smoother (the fit's model goes through it), or None.
        velocity_noise: the velocity noise the fit's model expectation took [rad/s].
        magnitudes: the parameters whose spread is returned.

    Returns:
        {} where no sample is fitted, no parameter is free, or ``sd`` is 0.
    """
    names = [n for n in params.names if n in set(free)]
    qd, tau, rows = np.asarray(qd, dtype=float), np.asarray(tau, dtype=float), np.asarray(rows, dtype=bool)
    if sd <= 0 or not names or not rows.any():
        return {}
    smooth = (lambda x: x) if smoother is None else smoother
    x, delta_s = params.as_vector(), float(getattr(params, "delta_s", 2.0))
    jac = family(params.model).expected_jacobian(x, qd, velocity_noise, delta_s)  # (N, p), the fit's own
    J = np.column_stack([smooth(jac[:, params.names.index(n)])[rows] for n in names])
    dy = sd * smooth(tau)[rows]
    keep = np.isfinite(J).all(axis=1) & np.isfinite(dy)
    if not keep.any():
        return {}
    shift = np.linalg.lstsq(J[keep], dy[keep], rcond=None)[0]
    return {n: float(abs(shift[names.index(n)])) for n in magnitudes if n in names}
