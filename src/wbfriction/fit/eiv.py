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

Closed forms (``erf`` the error function; ``delta_s = 2``, the thesis's Gaussian Stribeck):

* ``E[sgn(u)] = erf(mu / (sigma sqrt 2))``;
* ``E[sgn(u) exp(-u^2 / v_s^2)] = kappa exp(-mu^2 / (v_s^2 + 2 sigma^2)) erf(mu' / (sigma' sqrt 2))`` (the product of
  two Gaussians: ``sigma'^2 = a b / (a + b)``, ``mu' = mu a / (a + b)``, ``a = v_s^2 / 2``, ``b = sigma^2``,
  ``kappa = v_s / sqrt(v_s^2 + 2 sigma^2)``);
* ``tanh(x) = sum_k c_k erf(b_k x)`` to 2.1e-7 (:data:`TANH_ERF`, six terms fitted once), and
  ``E[erf(c u)] = erf(c mu / sqrt(1 + 2 c^2 sigma^2))``; with the Stribeck factor, as above with ``mu', sigma'``.

Another ``delta_s`` has no closed form for the Stribeck factor ``e(u) = exp(-|u / v_s|^delta_s)``: the jump at zero
is taken in closed form, ``E[sgn(u) e(u)] = E[sgn(u)] - E[sgn(u) (1 - e(u))]`` (and alike with ``tanh``), and the
rest, continuous, by a 40-point Gauss-Hermite rule; its Jacobian by central differences. Jacobians otherwise:
analytic.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import erf as _scipy_erf

from wbfriction.friction.models import ModelName, model_columns, model_jacobian, model_values

TANH_ERF = (
    (0.008807170824, 0.106167958788, 0.312483261569, 0.375288139486, 0.177682048682, 0.01957142065),
    (0.380254313692, 0.516670116239, 0.697199929594, 0.939584669203, 1.261711076348, 1.704557924796),
)
"""``(c_k, b_k)``: ``tanh(x) = sum_k c_k erf(b_k x)`` within 2.1e-7 for every real ``x`` (least squares on
[0, 40], ``sum c_k = 1``: exact at infinity; ``tests/fit/test_eiv.py``)."""

SMALL = 1e-12
"""A velocity noise below this [rad/s] is none: the model itself."""

_HERMITE = np.polynomial.hermite_e.hermegauss(40)


ERF_ONE = 6.0
"""``erf(x)`` is 1.0 exactly in double precision from x = 5.93 on (``1 - erf(x) < 2^-53``): :func:`erf` takes the
sign there."""


def erf(x):
    """SciPy's ``erf`` with the same bytes, computed only where ``|x| <`` :data:`ERF_ONE` (the sign elsewhere, what
    SciPy's rounds to): on a fast joint most of the samples' ``a u`` are there, and SciPy's ``erf`` is slowest."""
    x = np.asarray(x)
    if x.ndim == 0:
        return _scipy_erf(x)
    out = np.sign(x)
    near = np.flatnonzero(np.abs(x) < ERF_ONE)
    out[near] = _scipy_erf(x[near])
    return out


def _hermite(fn, qd: np.ndarray, sigma: float) -> np.ndarray:
    """``E[fn(qd + e)]``, ``e ~ N(0, sigma^2)``, by the 40-point Gauss-Hermite rule."""
    z, w = _HERMITE
    return sum(wi * fn(qd + sigma * zi) for zi, wi in zip(z, w)) / math.sqrt(2.0 * math.pi)


_TWO_OVER_ROOT_PI = 2.0 / math.sqrt(math.pi)


def _gauss_product(mu, sigma: float, v_s, derivatives: bool = True):
    """``exp(-u^2 / v_s^2) N(u; mu, sigma^2) = kappa N(u; mu', sigma'^2)`` (module docstring):
    ``(kappa, mu', sigma'^2)`` and their derivatives in ``v_s`` (zeros without ``derivatives``: the fit evaluates
    the model more often than its Jacobian)."""
    A, B = 0.5 * v_s**2, sigma**2
    D = A + B
    kappa = np.sqrt(A / D) * np.exp(-0.5 * mu**2 / D)
    if not derivatives:
        return kappa, mu * A / D, A * B / D, 0.0, 0.0, 0.0
    dA = v_s  # dA / dv_s
    d_kappa = kappa * (0.5 / A - 0.5 / D + 0.5 * mu**2 / D**2) * dA
    return kappa, mu * A / D, A * B / D, d_kappa, mu * B / D**2 * dA, B**2 / D**2 * dA


def _tanh_terms(mu, var, a, derivatives: bool = True):
    """``E[tanh(a u)]``, ``u ~ N(mu, var)``, through :data:`TANH_ERF`, with its derivatives in ``a``, ``mu``, ``var``
    (zeros without ``derivatives``): ``E[erf(k u)] = erf(g)``, ``g = k mu / sqrt(1 + 2 k^2 var)``."""
    value = d_a = d_mu = d_var = 0.0
    for c, b in zip(*TANH_ERF):
        k = b * a
        r = 1.0 + 2.0 * k**2 * var
        g = k * mu / np.sqrt(r)
        value = value + c * erf(g)
        if not derivatives:
            continue
        slope = c * _TWO_OVER_ROOT_PI * np.exp(-g**2) / np.sqrt(r)
        d_a = d_a + slope * mu / r * b
        d_mu = d_mu + slope * k
        d_var = d_var - slope * k**3 * mu / r
    return value, d_a, d_mu, d_var


def sign_mean(mu, sigma: float):
    """``E[sgn(u)]``, ``u ~ N(mu, sigma^2)``."""
    return erf(mu / (sigma * math.sqrt(2.0)))


def _sign_decay(mu, sigma: float, v_s):
    """``E[sgn(u) exp(-u^2 / v_s^2)]``, ``u ~ N(mu, sigma^2)``, and its derivative in ``v_s``."""
    kappa, m, s2, d_kappa, d_m, d_s2 = _gauss_product(mu, sigma, v_s)
    g = m / np.sqrt(2.0 * s2)
    slope = _TWO_OVER_ROOT_PI * np.exp(-g**2)
    d_g = d_m / np.sqrt(2.0 * s2) - 0.5 * g / s2 * d_s2
    return kappa * erf(g), d_kappa * erf(g) + kappa * slope * d_g


def _tanh_decay(mu, sigma: float, a, v_s):
    """``E[tanh(a u) exp(-u^2 / v_s^2)]``, ``u ~ N(mu, sigma^2)``, and its derivatives in ``a`` and ``v_s``."""
    kappa, m, s2, d_kappa, d_m, d_s2 = _gauss_product(mu, sigma, v_s)
    value, d_a, d_mu, d_var = _tanh_terms(m, s2, a)
    return kappa * value, kappa * d_a, d_kappa * value + kappa * (d_mu * d_m + d_var * d_s2)


def sign_decay_mean(mu, sigma: float, v_s):
    """``E[sgn(u) exp(-u^2 / v_s^2)]``, ``u ~ N(mu, sigma^2)``."""
    return _sign_decay(mu, sigma, v_s)[0]


def tanh_mean(mu, sigma: float, a):
    """``E[tanh(a u)]``, ``u ~ N(mu, sigma^2)``, through :data:`TANH_ERF`."""
    return _tanh_terms(mu, sigma**2, a, derivatives=False)[0]


def tanh_decay_mean(mu, sigma: float, a, v_s):
    """``E[tanh(a u) exp(-u^2 / v_s^2)]``, ``u ~ N(mu, sigma^2)``, through :data:`TANH_ERF`."""
    kappa, m, s2, *_ = _gauss_product(mu, sigma, v_s, derivatives=False)
    return kappa * _tanh_terms(m, s2, a, derivatives=False)[0]


def _other_exponent(x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float, model: ModelName) -> np.ndarray:
    """:func:`expected_values` of the Stribeck and thesis models for ``delta_s != 2`` (module docstring)."""
    if model == "stribeck":
        F_v, F_c, F_s, v_s, tau_os = x
        rest = _hermite(lambda u: np.sign(u) * (1.0 - np.exp(-np.abs(u / v_s) ** delta_s)), qd, sigma)
        return F_v * qd + F_s * sign_mean(qd, sigma) - (F_s - F_c) * rest + tau_os
    F_v, F_c, S, v_s, tau_os, a = x
    rest = _hermite(lambda u: np.tanh(a * u) * (1.0 - np.exp(-np.abs(u / v_s) ** delta_s)), qd, sigma)
    return F_v * qd + F_c * ((1.0 + S) * tanh_mean(qd, sigma, a) - S * rest) + tau_os


def expected_values(x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float, model: ModelName) -> np.ndarray:
    """``E[f(qd_true) | qd]`` [N·m] of ``model``'s parameters ``x`` (in the order of its names) at measured velocities
    ``qd`` (N,) [rad/s] with a white velocity noise of standard deviation ``sigma`` [rad/s] (module docstring); the
    model itself for ``sigma`` below :data:`SMALL`."""
    if sigma < SMALL:
        return model_values(x, qd, delta_s, model)
    if model != "coulomb-viscous" and delta_s != 2.0:
        return _other_exponent(x, qd, sigma, delta_s, model)
    if model == "coulomb-viscous":
        F_v, F_c, tau_os = x
        return F_v * qd + F_c * sign_mean(qd, sigma) + tau_os
    if model == "stribeck":
        F_v, F_c, F_s, v_s, tau_os = x
        return F_v * qd + F_c * sign_mean(qd, sigma) + (F_s - F_c) * sign_decay_mean(qd, sigma, v_s) + tau_os
    F_v, F_c, S, v_s, tau_os, a = x
    return F_v * qd + F_c * (tanh_mean(qd, sigma, a) + S * tanh_decay_mean(qd, sigma, a, v_s)) + tau_os


def expected_columns(qd: np.ndarray, sigma: float, delta_s: float, model: ModelName, v_s: float = 1.0,
                     a: float = 1.0, jump: np.ndarray | None = None) -> np.ndarray:
    """:func:`~wbfriction.friction.models.model_columns` under a velocity noise of standard deviation ``sigma``
    [rad/s]: each term's expectation at the measured velocities ``qd`` (N,) (module docstring), (N, K); the model's
    own columns for ``sigma`` below :data:`SMALL`. ``jump``: the jump's column (:func:`expected_jump`) if known."""
    if sigma < SMALL:
        return model_columns(qd, delta_s, model, v_s, a, jump)
    one = np.ones_like(qd)
    if jump is None:
        jump = expected_jump(qd, sigma, model, a)
    if model == "coulomb-viscous":
        return np.column_stack([qd, jump, one])
    if delta_s == 2.0:
        decay = sign_decay_mean(qd, sigma, v_s) if model == "stribeck" else tanh_decay_mean(qd, sigma, a, v_s)
    else:  # the jump's expectation less that of its continuous rest (module docstring)
        shape = np.sign if model == "stribeck" else (lambda u: np.tanh(a * u))
        decay = jump - _hermite(lambda u: shape(u) * (1.0 - np.exp(-np.abs(u / v_s) ** delta_s)), qd, sigma)
    return np.column_stack([qd, jump, decay, one])


def expected_jump(qd: np.ndarray, sigma: float, model: ModelName, a: float = 1.0) -> np.ndarray:
    """The jump's column of :func:`expected_columns` (N,): ``E[tanh(a u)]`` for (3.5), ``E[sgn(u)]`` otherwise (it
    depends on ``a`` alone: computed once for several ``v_s``)."""
    if sigma < SMALL:
        return np.tanh(a * qd) if model == "thesis" else np.sign(qd)
    return tanh_mean(qd, sigma, a) if model == "thesis" else sign_mean(qd, sigma)


def expected_jacobian(x: np.ndarray, qd: np.ndarray, sigma: float, delta_s: float, model: ModelName) -> np.ndarray:
    """Jacobian (N, p) of :func:`expected_values` with respect to ``x`` (module docstring)."""
    if sigma < SMALL:
        return model_jacobian(x, qd, delta_s, model)
    if model != "coulomb-viscous" and delta_s != 2.0:
        J = np.empty((qd.size, len(x)))
        for i in range(len(x)):
            h = 1e-6 * max(abs(x[i]), 1e-6)
            up, down = np.array(x, dtype=float), np.array(x, dtype=float)
            up[i] += h
            down[i] -= h
            J[:, i] = (_other_exponent(up, qd, sigma, delta_s, model)
                       - _other_exponent(down, qd, sigma, delta_s, model)) / (2 * h)
        return J
    J = np.empty((qd.size, len(x)))
    J[:, 0] = qd
    if model == "coulomb-viscous":
        J[:, 1] = sign_mean(qd, sigma)
        J[:, 2] = 1.0
        return J
    if model == "stribeck":
        F_v, F_c, F_s, v_s, tau_os = x
        sgn = sign_mean(qd, sigma)
        decay, d_vs = _sign_decay(qd, sigma, v_s)
        J[:, 1] = sgn - decay
        J[:, 2] = decay
        J[:, 3] = (F_s - F_c) * d_vs
        J[:, 4] = 1.0
        return J
    F_v, F_c, S, v_s, tau_os, a = x
    th, th_a, _, _ = _tanh_terms(qd, sigma**2, a)
    decay, decay_a, decay_vs = _tanh_decay(qd, sigma, a, v_s)
    J[:, 1] = th + S * decay
    J[:, 2] = F_c * decay
    J[:, 3] = F_c * S * decay_vs
    J[:, 4] = 1.0
    J[:, 5] = F_c * (th_a + S * decay_a)
    return J
