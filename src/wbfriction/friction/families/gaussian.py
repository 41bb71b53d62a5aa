"""Means under a Gaussian velocity noise: what the families' expectations (:meth:`FrictionFamily.expected_values`,
errors in variables, :mod:`wbfriction.fit.eiv`) are made of, for ``u ~ N(mu, sigma^2)`` (``mu`` the measured
velocity [rad/s], ``sigma`` its noise's standard deviation [rad/s]).

Closed forms (``erf`` the error function; ``delta_s = 2``, the thesis's Gaussian Stribeck):

* ``E[sgn(u)] = erf(mu / (sigma sqrt 2))``;
* ``E[sgn(u) exp(-u^2 / v_s^2)] = kappa exp(-mu^2 / (v_s^2 + 2 sigma^2)) erf(mu' / (sigma' sqrt 2))`` (the product of
  two Gaussians: ``sigma'^2 = a b / (a + b)``, ``mu' = mu a / (a + b)``, ``a = v_s^2 / 2``, ``b = sigma^2``,
  ``kappa = v_s / sqrt(v_s^2 + 2 sigma^2)``);
* ``tanh(x) = sum_k c_k erf(b_k x)`` to 2.1e-7 (:data:`TANH_ERF`, six terms fitted once), and
  ``E[erf(c u)] = erf(c mu / sqrt(1 + 2 c^2 sigma^2))``; with the Stribeck factor, as above with ``mu', sigma'``.

What has no closed form is taken by a 40-point Gauss-Hermite rule (:func:`hermite_mean`).
"""

from __future__ import annotations

import math

import numpy as np

TANH_ERF = (
    (0.008807170824, 0.106167958788, 0.312483261569, 0.375288139486, 0.177682048682, 0.01957142065),
    (0.380254313692, 0.516670116239, 0.697199929594, 0.939584669203, 1.261711076348, 1.704557924796),
)
"""``(c_k, b_k)``: ``tanh(x) = sum_k c_k erf(b_k x)`` within 2.1e-7 for every real ``x`` (least squares on
[0, 40], ``sum c_k = 1``: exact at infinity; ``tests/fit/test_eiv.py``)."""

SMALL = 1e-12
"""A velocity noise below this [rad/s] is none: the model itself."""

HERMITE = np.polynomial.hermite_e.hermegauss(40)
"""The 40-point Gauss-Hermite rule (nodes, weights) of :func:`hermite_mean`."""


ERF_ONE = 6.0
"""``erf(x)`` is 1.0 exactly in double precision from x = 5.93 on (``1 - erf(x) < 2^-53``): :func:`erf` takes the
sign there."""


def erf(x):
    """SciPy's ``erf`` with the same bytes, computed only where ``|x| <`` :data:`ERF_ONE` (the sign elsewhere, what
    SciPy's rounds to): on a fast joint most of the samples' ``a u`` are there, and SciPy's ``erf`` is slowest."""
    from scipy.special import erf as scipy_erf

    x = np.asarray(x)
    if x.ndim == 0:
        return scipy_erf(x)
    out = np.sign(x)
    near = np.flatnonzero(np.abs(x) < ERF_ONE)
    out[near] = scipy_erf(x[near])
    return out


def hermite_mean(fn, qd: np.ndarray, sigma: float) -> np.ndarray:
    """``E[fn(qd + e)]``, ``e ~ N(0, sigma^2)``, by the 40-point Gauss-Hermite rule (:data:`HERMITE`): exact for a
    polynomial of degree up to 79, close for a smooth ``fn``, not for a jump."""
    z, w = HERMITE
    return sum(wi * fn(qd + sigma * zi) for zi, wi in zip(z, w)) / math.sqrt(2.0 * math.pi)


TWO_OVER_ROOT_PI = 2.0 / math.sqrt(math.pi)
"""``erf'(x) = 2 / sqrt(pi) exp(-x^2)``."""


def gauss_product(mu, sigma: float, v_s, derivatives: bool = True):
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


def tanh_terms(mu, var, a, derivatives: bool = True):
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
        slope = c * TWO_OVER_ROOT_PI * np.exp(-g**2) / np.sqrt(r)
        d_a = d_a + slope * mu / r * b
        d_mu = d_mu + slope * k
        d_var = d_var - slope * k**3 * mu / r
    return value, d_a, d_mu, d_var


def sign_mean(mu, sigma: float):
    """``E[sgn(u)]``, ``u ~ N(mu, sigma^2)``."""
    return erf(mu / (sigma * math.sqrt(2.0)))


def sign_decay(mu, sigma: float, v_s):
    """``E[sgn(u) exp(-u^2 / v_s^2)]``, ``u ~ N(mu, sigma^2)``, and its derivative in ``v_s``."""
    kappa, m, s2, d_kappa, d_m, d_s2 = gauss_product(mu, sigma, v_s)
    g = m / np.sqrt(2.0 * s2)
    slope = TWO_OVER_ROOT_PI * np.exp(-g**2)
    d_g = d_m / np.sqrt(2.0 * s2) - 0.5 * g / s2 * d_s2
    return kappa * erf(g), d_kappa * erf(g) + kappa * slope * d_g


def tanh_decay(mu, sigma: float, a, v_s):
    """``E[tanh(a u) exp(-u^2 / v_s^2)]``, ``u ~ N(mu, sigma^2)``, and its derivatives in ``a`` and ``v_s``."""
    kappa, m, s2, d_kappa, d_m, d_s2 = gauss_product(mu, sigma, v_s)
    value, d_a, d_mu, d_var = tanh_terms(m, s2, a)
    return kappa * value, kappa * d_a, d_kappa * value + kappa * (d_mu * d_m + d_var * d_s2)


def sign_decay_mean(mu, sigma: float, v_s):
    """``E[sgn(u) exp(-u^2 / v_s^2)]``, ``u ~ N(mu, sigma^2)``."""
    return sign_decay(mu, sigma, v_s)[0]


def tanh_mean(mu, sigma: float, a):
    """``E[tanh(a u)]``, ``u ~ N(mu, sigma^2)``, through :data:`TANH_ERF`."""
    return tanh_terms(mu, sigma**2, a, derivatives=False)[0]


def tanh_decay_mean(mu, sigma: float, a, v_s):
    """``E[tanh(a u) exp(-u^2 / v_s^2)]``, ``u ~ N(mu, sigma^2)``, through :data:`TANH_ERF`."""
    kappa, m, s2, *_ = gauss_product(mu, sigma, v_s, derivatives=False)
    return kappa * tanh_terms(m, s2, a, derivatives=False)[0]


def central_differences(fn, x: np.ndarray, n: int) -> np.ndarray:
    """Jacobian (n, P) of ``fn`` (P,) -> (n,) at ``x`` by central differences, step ``1e-6 max(|x_i|, 1e-6)``."""
    J = np.empty((n, len(x)))
    for i in range(len(x)):
        h = 1e-6 * max(abs(x[i]), 1e-6)
        up, down = np.array(x, dtype=float), np.array(x, dtype=float)
        up[i] += h
        down[i] -= h
        J[:, i] = (fn(up) - fn(down)) / (2 * h)
    return J
