"""Variable projection (wbfriction.fit.projection): the models' columns against their values, the bounded linear
solve against SciPy's on the whole problem, the held parameters, the grid's minima, and the start it gives: the truth
on noise-free data, the multi-start optimum on the studies' joints."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import lsq_linear

from wbfriction.fit.coordinates import model_bounds, to_fit_coordinates
from wbfriction.fit.eiv import expected_columns, expected_values
from wbfriction.fit.joints import stick_margin
from wbfriction.fit.projection import (
    Projection,
    bounded_linear_solve,
    factor_positions,
    grid_minima,
    linear_part,
    projected_start,
)
from wbfriction.fit.selection import fit_friction
from wbfriction.fit.solve import stick_speed
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import ModelName

QD = np.concatenate([np.linspace(-1.5, 1.5, 1201), 0.4 * np.sin(np.linspace(0.0, 30.0, 1500))])

TRUTH: dict[ModelName, np.ndarray] = {  # the model's parameters, in the order of its names
    "coulomb-viscous": np.array([0.3, 0.5, 0.1]),
    "stribeck": np.array([0.3, 0.5, 0.8, 0.15, -0.05]),
    "thesis": np.array([0.3, 0.5, 0.6, 0.15, 0.05, 40.0]),
}


def linear_coefficients(model: ModelName, x: np.ndarray) -> np.ndarray:
    """The products of the family's column factors (:func:`factor_positions`) at the model's parameters ``x``."""
    z = to_fit_coordinates(model, x)
    return np.array([np.prod(z[list(m)]) for m in factor_positions(family(model))])


@pytest.mark.parametrize("model", ["coulomb-viscous", "stribeck", "thesis"])
@pytest.mark.parametrize(("sigma", "delta_s"), [(0.0, 2.0), (0.02, 2.0), (0.02, 1.5), (0.0, 1.5)])
def test_the_columns_times_their_products_are_the_model(model, sigma, delta_s):
    """Each model's columns (its expectation under the velocity noise, or itself) times the products of its linear
    parameters are :func:`expected_values`, an independent implementation, for the thesis's exponent and another."""
    x = TRUTH[model]
    columns = expected_columns(QD, sigma, delta_s, model, to_fit_coordinates(model, x))
    np.testing.assert_allclose(columns @ linear_coefficients(model, x), expected_values(x, QD, sigma, delta_s, model),
                               rtol=1e-9, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(5, 60), k=st.integers(1, 4))
def test_the_bounded_solve_is_scipys_on_the_whole_problem(seed, n, k):
    """The solve through the triangular factor is SciPy's bounded least squares on the whole (n, k) problem, with
    non-negative and free unknowns, active bounds or not."""
    rng = np.random.default_rng(seed)
    A, b = rng.normal(size=(n, k)), rng.normal(size=n)
    lower = np.where(rng.random(k) < 0.7, 0.0, -np.inf)
    upper = np.where(rng.random(k) < 0.2, 0.3, np.inf)
    c = bounded_linear_solve(A, b, lower, upper)
    reference = lsq_linear(A, b, bounds=(lower, upper), method="bvls", tol=1e-12).x
    assert np.all(c >= lower - 1e-12) and np.all(c <= upper + 1e-12)
    cost, best = np.sum((A @ c - b) ** 2), np.sum((A @ reference - b) ** 2)
    assert cost <= best * (1 + 1e-9) + 1e-12


def test_held_parameters_leave_the_products_of_the_others():
    """(3.5) with F_c held: the Stribeck column's unknown is S, weighted by F_c, and the Coulomb column goes to the
    held part; with S held, F_c's column is the Coulomb one plus S times the Stribeck one; every unknown back in
    place gives the parameters."""
    lower, upper = model_bounds(QD, "thesis")
    held = np.array([0.0, 0.5, 0.0, 0.0, 0.0, 0.0])
    part = linear_part("thesis", held, np.array([True, False, True, True, True, True]), lower, upper)
    assert part.unknowns == ((0,), (2,), (4,))
    np.testing.assert_array_equal(part.weights, [[1, 0, 0], [0, 0, 0], [0, 0.5, 0], [0, 0, 1]])
    np.testing.assert_array_equal(part.offset, [0, 0.5, 0, 0])
    assert part.upper[1] == 50.0  # S's own bound
    np.testing.assert_allclose(part.params(np.array([0.3, 0.6, 0.05]), held), [0.3, 0.5, 0.6, 0.0, 0.05, 0.0])
    held = np.array([0.0, 0.0, 0.6, 0.0, 0.0, 0.0])
    part = linear_part("thesis", held, np.array([True, True, False, True, True, True]), lower, upper)
    assert part.unknowns == ((0,), (1,), (4,))
    np.testing.assert_array_equal(part.weights[:, 1], [0, 1, 0.6, 0])
    free = np.ones(6, dtype=bool)
    part = linear_part("thesis", np.zeros(6), free, lower, upper)
    assert part.unknowns == ((0,), (1,), (1, 2), (4,)) and part.lower[2] == 0.0 and part.upper[2] == np.inf
    np.testing.assert_allclose(part.params(np.array([0.3, 0.5, 0.3, 0.05]), np.zeros(6)), [0.3, 0.5, 0.6, 0, 0.05, 0])


def test_the_grid_minima_are_its_local_minima_best_first():
    costs = np.array([[5.0, 4.0, 6.0], [7.0, 8.0, 1.0], [2.0, 9.0, 3.0]])
    np.testing.assert_array_equal(grid_minima(costs), [5, 6, 1])  # 1.0, 2.0, 4.0; 3.0 has 1.0 above it
    np.testing.assert_array_equal(grid_minima(np.array([3.0, 1.0, 2.0, 0.5])), [3, 1])


@pytest.mark.parametrize("model", ["coulomb-viscous", "stribeck", "thesis"])
@pytest.mark.parametrize("sigma", [0.0, 0.01])
def test_the_start_is_the_truth_on_noise_free_data(model, sigma):
    """Noise-free friction (its expectation under a known velocity noise, or itself): the start found over the
    non-linear parameters alone is the truth, every parameter within 1e-6 (the linear ones solved exactly)."""
    x = TRUTH[model]
    y = expected_values(x, QD, sigma, 2.0, model)
    lower, upper = model_bounds(QD, model)
    p = len(x)
    projection = Projection(model, QD, y, np.arange(QD.size), None, sigma, 2.0, np.zeros(p), np.ones(p, dtype=bool),
                            lower, upper)
    start = projected_start(projection, float(np.percentile(np.abs(QD), 90)))
    np.testing.assert_allclose(start, to_fit_coordinates(model, x), rtol=1e-6, atol=1e-9)


def test_the_start_is_the_truth_through_a_smoother_and_with_held_parameters():
    """(3.5) through a moving average along the whole series, S held at its true value, samples left out: the start
    is the truth."""
    x = TRUTH["thesis"]
    smoother = lambda f: np.apply_along_axis(lambda c: np.convolve(c, np.ones(9) / 9, mode="same"), 0, f)  # noqa: E731
    y = smoother(expected_values(x, QD, 0.0, 2.0, "thesis"))
    rows = np.flatnonzero(np.arange(QD.size) % 7 != 3)[10:-10]
    lower, upper = model_bounds(QD, "thesis")
    held = np.zeros(6)
    held[2] = x[2]
    projection = Projection("thesis", QD, y, rows, smoother, 0.0, 2.0, held,
                            np.array([True, True, False, True, True, True]), lower, upper)
    np.testing.assert_allclose(projected_start(projection, 1.0), x, rtol=1e-6)


@pytest.mark.slow
def test_the_fit_is_the_multi_start_optimum_on_the_studies_joints(talos, combined_walk):
    """The studies' joints (the legs of the combined walk, Table 6.1 friction, the studies' position and torque
    noise, the acceleration route with its smoother and the noise expectation): the fit from the projected start
    is the best of a brute-force multi-start (12 starts over (S, v_s, a) around the linear fit, and the truth, each
    refined over every parameter): its cost, and every parameter the data determine within 1e-6 relative or a
    thousandth of its standard error."""
    from wbfriction.fit.targets import THESIS_TARGETS
    from wbfriction.friction.estimate import estimate_log
    from wbfriction.friction.noise import joint_noises
    from wbfriction.friction.options import EstimateOptions
    from wbfriction.sim.options import SensorNoise
    from wbfriction.sim.sensors import apply_sensor_noise
    from wbfriction.studies.common import ENCODER_BITS, TORQUE_STD, leg_joints

    log = apply_sensor_noise(combined_walk.log, SensorNoise(position_std=1e-4, encoder_bits=ENCODER_BITS,
                                                            torque_std=TORQUE_STD, seed=3))
    est = estimate_log(talos, log, EstimateOptions())
    noises = joint_noises(est.metadata.get("noise"), est.estimation_route)
    checked, worst, worst_se = 0, 0.0, 0.0
    for joint, _, group in leg_joints(talos):
        i = est.joints.index(joint)
        qd, tau_f = est.qd[:, i], est.tau_f[:, i]
        sigma = noises[joint].velocity
        kwargs = dict(mask=est.valid[:, i], smoother=est.smoother, velocity_noise=sigma, stick=stick_speed(sigma),
                      stick_margin=stick_margin(est), joint=joint)
        fit = fit_friction(qd, tau_f, **kwargs)
        if fit.params is None or fit.speed < 0.02:
            continue
        use = np.isfinite(qd) & est.valid[:, i]
        A = np.column_stack([qd[use], np.sign(qd[use]), np.ones(use.sum())])
        F_v, F_c, tau_os = np.linalg.lstsq(A, -tau_f[use], rcond=None)[0]
        scale = float(np.percentile(np.abs(qd[use]), 90))
        starts = [np.array([max(F_v, 0.0), max(F_c, 1e-3), S, f * scale, tau_os, m / scale])
                  for S in (0.2, 1.0) for f in (0.05, 0.2, 0.5) for m in (5.0, 50.0)]
        starts.append(THESIS_TARGETS[group].as_vector())
        others = [fit_friction(qd, tau_f, x0=s, **kwargs) for s in starts]
        best = min(others, key=lambda r: r.rms_residual)
        assert fit.rms_residual <= best.rms_residual * (1 + 1e-9), joint
        x, reference = fit.params.as_vector(), best.params.as_vector()
        se = np.array([fit.stderr[n] for n in fit.params.names])
        # parameters the data determine (an infinite standard error: a valley of equal cost, e.g. F_c and tau_os of
        # a joint that turns one way only); the solver's own tolerance (1e-10) along the flat directions of a noisy
        # fit: a thousandth of a standard error
        known = np.isfinite(se)
        assert np.all(np.abs(x - reference)[known] <= (1e-6 * np.abs(reference) + 1e-3 * se)[known]), (
            joint, x, reference, se)
        relative = np.abs(x - reference)[known] / np.maximum(np.abs(reference)[known], 1e-12)
        worst = max(worst, float(np.max(relative)))
        worst_se = max(worst_se, float(np.max((np.abs(x - reference) / se)[known])))
        checked += 1
    assert checked >= 8
    print(f"{checked} joints; worst difference {worst:.1e} relative, {worst_se:.1e} standard errors")
