"""The Cramér-Rao bound (issue 38) against exact cases: white noise, a coloured noise's exact Toeplitz information,
a fit's Monte Carlo spread, and the torque noise read off a residual."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.linalg import solve_banded

from wbfriction.fit.bound import cramer_rao, fisher_information, torque_noise
from wbfriction.fit.selection import fit_friction
from wbfriction.friction.models import model_values
from wbfriction.friction.noise import JointNoise, NoiseModel

DT = 1e-3


def test_white_noise_gives_the_least_squares_covariance():
    """Without position noise the spectrum is flat: the bound is ``sigma^2 (J^T J)^-1``, over every run."""
    rng = np.random.default_rng(0)
    J = rng.standard_normal((900, 3))
    rows = np.r_[np.arange(0, 400), np.arange(450, 950)]  # two runs
    noise = NoiseModel(torque=0.05, position=0.0, inertia=1.0, dt=DT)
    np.testing.assert_allclose(cramer_rao(J, rows, noise), 0.05**2 * np.linalg.inv(J.T @ J), rtol=1e-10)


def test_a_coloured_noise_is_the_exact_information_of_its_covariance():
    """White torque noise plus a position noise through the second difference: the covariance of the noise is
    banded (``sigma_tau^2 I + (M sigma_q / dt^2)^2 T``, ``T`` the second difference's [1 -4 6 -4 1]): the information
    is ``J^T Sigma^-1 J`` with that matrix written out whole, and its spectrum's (Whittle's) within 6 %."""
    n = 4000
    t = np.arange(n) * DT
    J = np.column_stack([np.sin(2 * np.pi * 0.7 * t), np.tanh(20 * np.sin(2 * np.pi * 0.4 * t)), np.ones(n)])
    noise = NoiseModel(torque=0.05, position=1e-4, inertia=2.0, dt=DT)
    c = (noise.inertia * noise.position / DT**2) ** 2
    bands = np.zeros((5, n))
    for k, v in zip(range(5), (c, -4 * c, 6 * c + noise.torque**2, -4 * c, c)):
        bands[k] = v  # rows of the banded (upper, diagonal, lower) form; the ends are cut alike
    exact = J.T @ solve_banded((2, 2), bands, J)
    np.testing.assert_allclose(fisher_information(J, np.arange(n), noise), exact, rtol=1e-8)
    freq = np.fft.rfftfreq(n, DT)
    F = np.fft.rfft(J, axis=0)
    weight = np.where((freq == 0) | (np.arange(freq.size) == n // 2), 1.0, 2.0) / (noise.psd(freq) * n)
    whittle = np.real((F.conj() * weight[:, None]).T @ F)
    np.testing.assert_allclose(np.diag(np.linalg.inv(whittle)), np.diag(np.linalg.inv(exact)), rtol=0.06)


def test_a_parameter_the_data_cannot_tell_has_an_infinite_bound():
    J = np.column_stack([np.ones(100), np.ones(100), np.arange(100.0)])  # the first two are one parameter
    cov = cramer_rao(J, np.arange(100), NoiseModel(0.05, 0.0, 1.0, DT))
    assert np.isinf(cov[0, 0]) and np.isinf(cov[1, 1]) and np.isfinite(cov[2, 2])


def test_a_parameter_with_next_to_no_information_has_an_infinite_bound_and_no_warning():
    """A column of 1e-160 (a Stribeck height at a velocity far beyond v_s): its bound overflows the floats' range;
    it is inf, quietly, the others' finite."""
    x = np.linspace(-1.0, 1.0, 100)
    J = np.column_stack([1e-160 * x**2, x, np.ones(100)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cov = cramer_rao(J, np.arange(100), NoiseModel(0.05, 0.0, 1.0, DT))
    assert np.isinf(cov[0, 0]) and np.all(np.isfinite(cov[1:, 1:]))


def test_the_torque_noise_is_the_residuals_spectrum_at_zero_frequency():
    """A white noise of 0.05 N·m plus a far larger noise seen through a derivative (a position noise of 1e-3 rad
    through the second difference, 2.4 N·m RMS): batch means find 0.05 within 10 %, over runs cut anywhere."""
    rng = np.random.default_rng(3)
    n = 40_000
    position = rng.normal(0.0, 1e-3, n + 2)
    residual = rng.normal(0.0, 0.05, n) + (position[2:] - 2 * position[1:-1] + position[:-2]) / DT**2 * 1e-3
    rows = np.r_[np.arange(0, 17_000), np.arange(18_000, 41_000)]
    assert np.std(residual) > 1.0
    assert torque_noise(residual[:len(rows)], rows, 256) == pytest.approx(0.05, rel=0.1)
    short = np.arange(0, 40_000, 200)[:, None] + np.arange(100)  # runs of 100: a quarter batch of 256 or more
    assert torque_noise(residual[:short.size], short.ravel(), 256) == pytest.approx(0.05, rel=0.1)
    assert np.isnan(torque_noise(residual[:10], np.arange(10), 256))


def test_least_squares_on_white_noise_reaches_the_bound():
    """The Coulomb-viscous model, white torque noise, 60 noise draws: the fit's RMS error of F_c and F_v is its
    bound's standard deviation within the Monte Carlo's spread (20 %), and the bound it reports is that one."""
    rng = np.random.default_rng(4)
    t = np.arange(5000) * DT
    qd = 0.8 * np.sin(2 * np.pi * 0.5 * t) + 0.3 * np.sin(2 * np.pi * 1.3 * t)
    x = np.array([0.3, 1.0, 0.1])
    noise = JointNoise(position=0.0, velocity=0.0, acceleration=0.0, inertia=1.0, dt=DT)
    errors, bounds = [], []
    for _ in range(60):
        y = model_values(x, qd, 2.0, "coulomb-viscous") + rng.normal(0.0, 0.05, t.size)
        fit = fit_friction(qd, -y, model="coulomb-viscous", noise=noise)
        errors.append([fit.params.F_v - x[0], fit.params.F_c - x[1]])
        bounds.append([fit.crb["F_v"], fit.crb["F_c"]])
        assert fit.torque_noise == pytest.approx(0.05, rel=0.25)
    rms, bound = np.sqrt(np.mean(np.square(errors), axis=0)), np.mean(bounds, axis=0)
    np.testing.assert_allclose(rms, bound, rtol=0.2)
