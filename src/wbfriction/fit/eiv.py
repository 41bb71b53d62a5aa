"""Errors in variables: the friction models' expectation under a noisy velocity (issue 38).

The fit evaluates the model at the measured velocity ``u = qd + e``, while the friction followed the true one
``qd``. A velocity noise ``e`` inside a steep ``sgn``/``tanh`` biases F_c and F_v: near a reversal the measured
velocity has the wrong sign a fraction of the time. With the noise known (its standard deviation ``sigma``: the
positions' white noise through the velocity filter, measured from the data, :mod:`wbfriction.signals.choice`),
the fit compares the data with the friction's expectation given the measured velocity,

.. math:: E[f(qd) \\mid u] = \\int f(u - e)\\, \\varphi_\\sigma(e)\\, de ,

exact when the velocities' spread is flat over a few ``sigma`` (regression calibration: R. J. Carroll et al.,
*Measurement Error in Nonlinear Models*, 2nd ed., ch. 4). Why this rather than SIMEX or a full
errors-in-variables fit: ``sigma`` is measured, not to be estimated; the expectation is one closed form per model,
as fast as the model itself and with an analytic Jacobian, where SIMEX refits the model at several added noise
levels and extrapolates to an assumed curve, and a functional errors-in-variables fit adds every sample's true
velocity as an unknown.

Each family computes its own expectation (:meth:`~wbfriction.friction.families.base.FrictionFamily.expected_values`
and its Jacobian, columns and jump), out of the Gaussian means of :mod:`wbfriction.friction.families.gaussian`
(closed forms for ``sgn``, ``tanh`` through :data:`TANH_ERF` and the Gaussian Stribeck factor, ``delta_s = 2``).
Another ``delta_s`` has no closed form for the Stribeck factor ``e(u) = exp(-|u / v_s|^delta_s)``: the jump at zero
is taken in closed form, ``E[sgn(u) e(u)] = E[sgn(u)] - E[sgn(u) (1 - e(u))]`` (and alike with ``tanh``), and the
rest, continuous, by a 40-point Gauss-Hermite rule; its Jacobian by central differences. Jacobians otherwise:
analytic. The functions below are the families' by name.
"""

from __future__ import annotations

import numpy as np

from wbfriction.friction.families.gaussian import (
    ERF_ONE,
    SMALL,
    TANH_ERF,
    erf,
    sign_decay_mean,
    sign_mean,
    tanh_decay_mean,
    tanh_mean,
)
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import ModelName

__all__ = ["ERF_ONE", "SMALL", "TANH_ERF", "erf", "expected_columns", "expected_jacobian", "expected_jump",
           "expected_values", "sign_decay_mean", "sign_mean", "tanh_decay_mean", "tanh_mean"]


def expected_values(x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float, model: ModelName) -> np.ndarray:
    """``E[f(qd_true) | qd]`` [N·m] of ``model``'s parameters ``x`` (in the order of its names) at measured velocities
    ``qd`` (N,) [rad/s] with a white velocity noise of standard deviation ``sigma`` [rad/s] (module docstring); the
    model itself for ``sigma`` below :data:`SMALL`.

    Raises:
        UnknownFamilyError: no family named ``model``.
    """
    return family(model).expected_values(x, qd, sigma, delta_s)


def expected_jacobian(x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float, model: ModelName) -> np.ndarray:
    """Jacobian (N, p) of :func:`expected_values` with respect to ``x`` (module docstring)."""
    return family(model).expected_jacobian(x, qd, sigma, delta_s)


def expected_columns(qd: np.ndarray, sigma: float, delta_s: float, model: ModelName, z: np.ndarray,
                     jump: np.ndarray | None = None) -> np.ndarray:
    """:func:`~wbfriction.friction.models.model_columns` under a velocity noise of standard deviation ``sigma``
    [rad/s]: each term's expectation at the measured velocities ``qd`` (N,) (module docstring), (N, K), the non-linear
    parameters read from the fit's coordinates ``z`` (P,); the model's own columns for ``sigma`` below :data:`SMALL`.
    ``jump``: the jump's column (:func:`expected_jump`) if known."""
    return family(model).expected_columns(qd, sigma, delta_s, z, jump)


def expected_jump(qd: np.ndarray, sigma: float, model: ModelName, z: np.ndarray) -> np.ndarray:
    """The jump's column of :func:`expected_columns` (N,): ``E[tanh(a u)]`` for (3.5), ``E[sgn(u)]`` for the
    Coulomb-viscous and Stribeck models (it depends on ``a`` alone: computed once for several ``v_s``)."""
    return family(model).expected_jump(qd, sigma, z)
