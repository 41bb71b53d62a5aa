"""Inertia-model identification (thesis 2.4, ch. 8): the regressor against inverse dynamics,
the compressed least squares, base parameters, physically consistent bodies (the exact conic solve), the model and
friction recovered from a simulated walk given a wrong model, and from a simulated arm's motor
currents its friction and rotor inertia (armature), known or identified, with the parameters its
motion does not excite kept at the prior and reported."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.consistency import (
    PHYSICAL,
    RegularisedProblem,
    fit_consistent,
    is_consistent,
    nearest_consistent,
    prior_model,
)
from wbfriction.inertia.identification import identify_inertia
from wbfriction.inertia.least_squares import CompressedLeastSquares, base_parameters
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.prior import residual_variance
from wbfriction.inertia.regressor import act_matrix, body_parameters, stance_regressor
from wbfriction.inertia.samples import log_samples
from wbfriction.inertia.sensitivity import scaled_robot
from wbfriction.model.rerooted import stance_model
from wbfriction.signals.options import FilterOptions
from wbfriction.studies.common import leg_joints


@pytest.mark.parametrize("contact", [0, 1])
def test_regressor_times_parameters_is_the_stance_inverse_dynamics(talos, contact):
    """Two routes: Y(q, qd, qdd) @ to_rooted @ pi (+ armature) equals the stance-rooted RNEA."""
    rng = np.random.default_rng(contact)
    n = 30
    lo, hi = talos.angle_limits
    angles = rng.uniform(lo, hi, (n, talos.n_act))
    qd, qdd = rng.normal(0, 1, (n, talos.n_act)), rng.normal(0, 5, (n, talos.n_act))
    pose = np.zeros((n, 7))
    pose[:, :3] = rng.normal(size=(n, 3))
    pose[:, 3:] = rng.normal(size=(n, 4))
    pose[:, 3:] /= np.linalg.norm(pose[:, 3:], axis=1, keepdims=True)
    reg = stance_regressor(talos, contact)
    Y = reg.joint_rows(pose, angles, qd, qdd)
    tau, _ = stance_model(talos, contact).inverse_dynamics(pose, angles, qd, qdd)
    pred = Y @ (reg.to_rooted @ body_parameters(talos.model).ravel()) + talos.model.armature[talos.act_v_index] * qdd
    assert np.abs(pred - tau).max() < 1e-9 * np.abs(tau).max()


def _physical_inertia(draw_values) -> pin.Inertia:
    m, a, b, c, x, y, z, rx, ry, rz = draw_values
    box = pin.Inertia.FromBox(m, a, b, c)  # a solid box: physically consistent
    placement = pin.SE3(pin.rpy.rpyToMatrix(rx, ry, rz), np.array([x, y, z]))
    return placement.act(box)


inertias = st.tuples(st.floats(0.05, 50), st.floats(0.01, 1), st.floats(0.01, 1), st.floats(0.01, 1),
                     *[st.floats(-1, 1)] * 3, *[st.floats(-3, 3)] * 3).map(_physical_inertia)


@settings(max_examples=60, deadline=None)
@given(inertia=inertias)
def test_consistency_and_the_nearest_consistent_body(inertia):
    pi = inertia.toDynamicParameters()
    assert is_consistent(pi[None])[0]
    # a body whose principal moments break the triangle inequality is not physical
    bad = pin.Inertia(inertia.mass, inertia.lever, np.diag([1.0, 1.0, 3.0]) * inertia.mass).toDynamicParameters()
    assert not is_consistent(bad[None])[0]
    # the nearest consistent body: a physical one unchanged, the other brought inside
    assert np.allclose(nearest_consistent(pi[None])[0], pi, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(pi).max()))
    assert is_consistent(nearest_consistent(bad[None]))[0]


@settings(max_examples=40, deadline=None)
@given(inertia=inertias, move=inertias)
def test_act_matrix_is_the_rigid_transform_of_the_parameters(inertia, move):
    placement = pin.SE3(pin.rpy.rpyToMatrix(*move.lever), move.lever[::-1].copy())
    A = act_matrix(placement)
    assert np.allclose(A @ inertia.toDynamicParameters(), placement.act(inertia).toDynamicParameters(),
                       rtol=1e-9, atol=1e-9 * max(1.0, inertia.mass))


def test_compressed_least_squares_and_base_parameters():
    """Rows added in blocks give the least-squares solution of all rows; a column that is a
    combination of others is found dependent and absorbed into their base parameters."""
    rng = np.random.default_rng(0)
    A = rng.normal(size=(900, 6))
    A[:, 4] = A[:, 0] + 2.0 * A[:, 1]  # parameter 4 only ever acts with 0 and 1
    A[:, 5] = 0.0  # parameter 5 never acts
    x = rng.normal(size=6)
    b = A @ x + rng.normal(0, 1e-3, 900)
    ls = CompressedLeastSquares(6)
    for k in range(0, 900, 128):
        ls.add(A[k:k + 128], b[k:k + 128])
    ref = np.linalg.lstsq(A, b, rcond=None)[0]
    sol = np.linalg.lstsq(ls.R, ls.z, rcond=None)[0]
    assert np.allclose(A @ sol, A @ ref, atol=1e-9)
    base = base_parameters(ls.R)
    assert base.count == 4 and list(base.independent) == [0, 1, 2, 3]
    expected = np.array([x[0] + x[4], x[1] + 2.0 * x[4], x[2], x[3]])
    assert np.allclose(base.combination @ x, expected, atol=1e-9)
    assert np.allclose(base.combination @ ref, expected, atol=1e-2)


def _dependent_rows(rng: np.random.Generator, n: int, p: int, dependent: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows (n, p) whose last ``dependent`` columns are combinations of the others, scaled over three
    orders of magnitude (as a body's mass, first moments and inertias), and noisy right-hand sides."""
    A = rng.normal(size=(n, p)) * np.logspace(0, -3, p)
    for k in range(dependent):
        A[:, p - 1 - k] = A[:, :p - dependent] @ rng.normal(size=p - dependent)
    return A, A @ rng.normal(size=p) + rng.normal(0.0, 0.1, n)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), block=st.integers(8, 500), dependent=st.integers(1, 4))
def test_residual_variance_is_the_base_parameters_whatever_the_blocks(seed, block, dependent):
    """Issue 37: the residual variance is that of the stacked rows' least squares over the base parameters
    (per row beyond them), however the rows were added. (The smallest residual over every column is not:
    each block hands a rounding-chosen share of its residual to the dependent columns.)"""
    rng = np.random.default_rng(seed)
    n, p = 1500, 9
    A, b = _dependent_rows(rng, n, p, dependent)
    ls = CompressedLeastSquares(p)
    for k in range(0, n, block):
        ls.add(A[k:k + block], b[k:k + block])
    base = ls.base_parameters()
    assert base.count == p - dependent
    independent = A[:, base.independent]
    r = b - independent @ np.linalg.lstsq(independent, b, rcond=None)[0]
    assert residual_variance(ls, base) == pytest.approx(float(r @ r) / (n - base.count), rel=1e-9)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), order=st.permutations(range(7)))
def test_condition_is_the_identifiable_parts_whichever_columns_are_chosen(seed, order):
    """The condition number does not depend on which columns the pivoting chooses among dependent ones
    (their order here): it is the identifiable part's, the scaled regressor's largest singular value over
    its rank-th."""
    rng = np.random.default_rng(seed)
    A, b = _dependent_rows(rng, 400, 7, 2)
    reference = base_parameters(CompressedLeastSquares(7).R)  # nothing added: rank 0
    assert reference.count == 0 and reference.condition == np.inf
    conditions = []
    for columns in (np.arange(7), np.array(order)):
        ls = CompressedLeastSquares(7)
        ls.add(A[:, columns], b)
        base = base_parameters(ls.R)
        assert base.count == 5
        conditions.append(base.condition)
    scaled = A / np.linalg.norm(A, axis=0)
    s = np.linalg.svd(scaled, compute_uv=False)
    assert conditions[0] == pytest.approx(s[0] / s[4], rel=1e-9)
    assert conditions[1] == pytest.approx(conditions[0], rel=1e-9)


def _slow_joint(body: pin.Inertia, seed: int, triangle: bool):
    """Rows of one body and one joint that never leaves the linear part of tanh (its viscous
    and Coulomb columns nearly collinear), with a true friction; with ``triangle`` the data
    ask for a rotational inertia beyond the triangle inequality."""
    rng = np.random.default_rng(seed)
    pi_true = body.toDynamicParameters()
    friction_true = np.array([[0.3, 0.2, -0.1]])  # F_v, F_c, tau_os
    n = 400
    qd = rng.uniform(-4e-3, 4e-3, n)
    F = np.column_stack([qd, np.tanh(40.0 * qd), np.ones(n)])
    Y = rng.normal(size=(n, 10)) * np.concatenate([[1.0], [0.1] * 3, [0.01] * 6])
    b = Y @ pi_true + F @ friction_true[0] + rng.normal(0, 1e-3, n)
    if triangle:
        bad = pin.Inertia(body.mass, body.lever, np.diag([1.0, 1.0, 3.0]) * body.mass).toDynamicParameters()
        b = b + Y @ (bad - pi_true)
    ls = CompressedLeastSquares(13)
    ls.add(np.column_stack([Y, F]), b)
    return ls, pi_true[None], friction_true


@settings(max_examples=25, deadline=None)
@given(body=inertias, seed=st.integers(0, 2**32 - 1), triangle=st.booleans())
def test_consistent_fit_keeps_friction_physical_and_beats_the_truth(body, seed, triangle):
    """The fit keeps F_v, F_c >= 0 and the body physical (through the conic solve with ``triangle``), and its
    objective is no worse than the truth's, a feasible point."""
    ls, pi_true, friction_true = _slow_joint(body, seed, triangle)
    prior = prior_model(pi_true * 1.05, np.zeros(3), np.full(3, 1e4))
    lower = np.concatenate([np.full(10, -np.inf), [0.0, 0.0, -np.inf]])
    fit = fit_consistent(ls.R, ls.z, prior, 1e-6, lower)
    assert fit.rest[0] >= 0 and fit.rest[1] >= 0
    assert is_consistent(fit.pi).all()
    problem = RegularisedProblem(ls.R, ls.z, prior, lower)

    def objective(pi, friction):
        return problem.objective(np.concatenate([pi.ravel(), friction.ravel()]), 1e-6)

    assert objective(fit.pi, fit.rest) <= objective(pi_true, friction_true) * (1 + 1e-6)
    assert fit.cost == pytest.approx(0.5 * objective(fit.pi, fit.rest), rel=1e-4)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), margin=st.sampled_from([0.0, 0.25, 0.6]))
def test_the_conic_solve_is_the_nearest_positive_semidefinite_pseudo_inertia(seed, margin):
    """An analytic case of the conic solve: data that measure a body's pseudo-inertia entries directly, in the
    Frobenius norm (``R pi = svec(J(pi))``), asking for an indefinite one ``M``: the minimum over physical
    bodies is ``M`` with its negative eigenvalues set to zero (the nearest positive-semidefinite matrix), with a
    prior weight too small to move it; over bodies that keep ``margin`` of the given one's ``J0``, it is
    ``margin J0`` plus the nearest positive-semidefinite matrix to ``M - margin J0``."""
    rng = np.random.default_rng(seed)
    iu = [(i, j) for j in range(4) for i in range(j + 1)]
    scale = np.array([1.0 if i == j else np.sqrt(2.0) for i, j in iu])

    def svec(J):
        return scale * np.array([J[i, j] for i, j in iu])

    R = np.column_stack([svec(pin.PseudoInertia.FromDynamicParameters(e).toMatrix()) for e in np.eye(10)])
    V = np.linalg.qr(rng.normal(size=(4, 4)))[0]
    ev = np.array([-rng.uniform(0.05, 1.0), *rng.uniform(0.1, 2.0, 3)])  # one negative eigenvalue
    M = (V * ev) @ V.T
    prior = prior_model(pin.Inertia.FromBox(1.0, 0.1, 0.2, 0.3).toDynamicParameters()[None], np.zeros(0),
                        np.zeros(0))
    fit = fit_consistent(R, svec(M), prior, 1e-12, np.full(10, -np.inf), margin)
    assert fit.solver is not None and fit.solver.converged and fit.unphysical == 1
    J = pin.PseudoInertia.FromDynamicParameters(fit.pi[0]).toMatrix()
    J0 = margin * pin.PseudoInertia.FromDynamicParameters(prior.x0).toMatrix()
    ev, V = np.linalg.eigh(M - J0)
    nearest = J0 + (V * np.maximum(ev, 0.0)) @ V.T
    assert np.abs(J - nearest).max() < 1e-6 * np.abs(M).max()


def test_unbounded_friction_of_a_slow_joint_cancels():
    """The premise of the test above: without the bounds, F_v and F_c take opposite signs."""
    ls, *_ = _slow_joint(pin.Inertia.FromBox(2.0, 0.2, 0.1, 0.3), 0, False)
    unbounded = np.linalg.lstsq(ls.R, ls.z, rcond=None)[0]
    assert min(unbounded[10], unbounded[11]) < 0


@pytest.mark.slow
def test_identification_recovers_model_and_friction_from_a_walk_with_a_wrong_model(talos, combined_walk):
    """The combined walk (Table 6.1 friction) seen through a model with every body's
    principal moments x1.1 and mass x1.05: identification gives back the total mass, the
    base parameters and the friction (the Stribeck velocity given), and predicts held-out
    torques far better than the given model, every body staying physical."""
    wrong = scaled_robot(scaled_robot(talos, 1.1, "rotational"), 1.05, "mass")
    res = identify_inertia(wrong, combined_walk.log, EstimateOptions(),
                           InertialOptions(stribeck_velocity=0.2, prior=1.0))
    true = body_parameters(talos.model)
    assert (abs(res.pi[:, 0].sum() - true[:, 0].sum()) < 0.01 * true[:, 0].sum()
            < abs(res.pi_given[:, 0].sum() - true[:, 0].sum()))
    assert is_consistent(res.pi).all()
    K = res.base.combination[:, :true.size]
    rel = lambda pi: np.linalg.norm(K @ (pi.ravel() - true.ravel())) / np.linalg.norm(K @ true.ravel())  # noqa: E731
    assert rel(res.pi) < 0.2 * rel(res.pi_given)
    legs = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(talos)}
    names = list(res.friction_names)
    for i, joint in enumerate(talos.torque_controlled):
        if joint in legs:
            t = legs[joint]
            f = dict(zip(names, res.friction[i]))
            assert abs(f["F_c"] - t.F_c) < 0.05 * t.F_c, (joint, f)
            assert abs(f["tau_os"] - t.tau_os) < 0.05 * max(t.tau_os, 0.2), (joint, f)
    assert np.all(res.holdout.identified < 0.2 * np.maximum(res.holdout.given, 0.05))
    assert np.median(res.holdout.identified) < 0.01


ARM_ESTIMATE = EstimateOptions(diff="butterworth", filtering=FilterOptions(cutoff=20.0))
"""Accelerations of 19-bit encoders at 1 kHz need a low-pass: central differences put 8.5 rad/s^2 of
noise in them (:func:`test_noisy_accelerations_are_flagged`)."""


def _relative(identified: np.ndarray, true: np.ndarray) -> np.ndarray:
    return np.abs(identified / true - 1.0)


def _options(friction, **kw) -> InertialOptions:
    """The injected Stribeck velocity given (one identification), the prior's weight fixed."""
    return InertialOptions(stribeck_velocity=next(iter(friction.values())).v_s, prior=100.0, **kw)


def test_arm_identification_recovers_friction_and_armature(panda, panda_friction, panda_log):
    """The simulated Panda (19-bit encoders, motor currents with 0.05 N·m of noise, the TOML's armature
    injected) seen through a wrong model (principal moments x1.1, masses x1.05, no armature): every
    joint's F_v, F_c and armature come back within 5 %, every body physical; the first joint's
    armature and its link's inertia about the vertical axis act alike, and are reported together."""
    wrong = scaled_robot(scaled_robot(panda, 1.1, "rotational"), 1.05, "mass")
    truth = panda.model.armature[panda.act_v_index].copy()
    wrong.model.armature = np.zeros(wrong.model.nv)
    res = identify_inertia(wrong, panda_log, ARM_ESTIMATE, _options(panda_friction, armature="identify"))
    F = {n: np.array([getattr(panda_friction[j], n) for j in panda.actuated]) for n in ("F_v", "F_c")}
    assert _relative(res.friction[:, 0], F["F_v"]).max() < 0.05, res.friction
    assert _relative(res.friction[:, 1], F["F_c"]).max() < 0.05, res.friction
    assert _relative(res.armature, truth).max() < 0.05, res.armature
    assert np.allclose(res.robot.model.armature[panda.act_v_index], res.armature)
    assert np.all(res.armature_given == 0.0) and res.armature_mode == "identify"
    assert is_consistent(res.pi).all() and np.all(res.pi[:, 0] > 0)
    # the gate keeps the identified arm (one limb: a fixed base's chain), which predicts held-out data far better
    assert res.validation.kept.all() and np.array_equal(res.pi, res.pi_fit)
    ratio = res.holdout.validated / res.holdout.given_with_friction
    assert np.all(ratio < 1.0) and np.median(ratio) < 0.5, ratio  # measured: 0.04-0.96 (the wrist), median 0.34
    pair = {"panda_joint1.armature", "panda_joint1.I_zz"}
    reported = [u for u in res.unexcited if u.parameter in pair]
    assert len(reported) == 1 and set(reported[0].partners) & pair, reported
    assert next(iter(reported[0].partners.values())) == pytest.approx(-1.0, rel=1e-6)


def test_shared_samples_give_the_same_identification(panda, panda_friction, panda_log):
    """The closed loop's passes share the log's kinematics and split (:func:`log_samples`): a second
    identification with another Stribeck velocity, from the samples the first used, is bit for bit the one
    made from scratch; samples split with other options are refused."""
    options = _options(panda_friction)
    shared = log_samples(panda, panda_log, ARM_ESTIMATE, options)
    identify_inertia(panda, panda_log, ARM_ESTIMATE, options, shared=shared)
    other = dataclasses.replace(options, stribeck_velocity=0.08)
    reused = identify_inertia(panda, panda_log, ARM_ESTIMATE, other, shared=shared)
    fresh = identify_inertia(panda, panda_log, ARM_ESTIMATE, other)
    for name in ("pi", "friction", "pi_fit", "friction_fit", "armature"):
        assert np.array_equal(getattr(reused, name), getattr(fresh, name)), name
    for name in ("given", "given_with_friction", "identified", "validated"):
        assert np.array_equal(getattr(reused.holdout, name), getattr(fresh.holdout, name)), name
    assert (reused.message, reused.residual_std, reused.prior) == (fresh.message, fresh.residual_std, fresh.prior)
    with pytest.raises(ValueError):
        identify_inertia(panda, panda_log, ARM_ESTIMATE, dataclasses.replace(options, stride=2), shared=shared)


def test_known_armature_reproduces_the_injected_friction(panda, panda_friction, panda_log):
    """With the armature known (the TOML's, the one injected) the friction comes back within 2 %;
    left out (``none``: as for link-side torque sensors) the currents cannot be explained: the held-out
    torques are predicted several times worse and the friction is off."""
    def run(mode):
        return identify_inertia(panda, panda_log, ARM_ESTIMATE, _options(panda_friction, armature=mode))

    known, none = run("known"), run("none")
    F = np.array([[panda_friction[j].F_v, panda_friction[j].F_c] for j in panda.actuated])
    assert _relative(known.friction[:, :2], F).max() < 0.02, known.friction
    assert np.array_equal(known.armature, panda.model.armature[panda.act_v_index])
    assert np.median(none.holdout.identified / known.holdout.identified) > 3.0
    assert _relative(none.friction[:, :2], F).max() > 0.1


def test_unexcited_parameters_stay_at_the_prior_and_are_reported(panda, panda_friction, panda_still_wrist_log):
    """The wrist held still, the first four joints excited, the given model wrong (principal moments
    x1.2, masses x1.05). Reported as not excited: the base link and the first link's parameters
    that act on no torque of a fixed base (all but the inertia about the first axis), which stay at
    the prior (to 1e-3 of its standard deviations); every mass (a fixed base's torques see masses
    only through their lever arms, with other bodies' moments), each within 5 % of the prior (the
    prior is 5 % off the truth: none runs away); the still joints' viscous friction. Every body
    physical. (The prior alone, without the link margin: the given first link is thin, its pseudo-inertia's
    eigenvalues 5e-4 apart, and its excited I_zz takes it to the margin's boundary, where the cone, not the
    prior, sets its other entries: 1.2e-3 standard deviations away.)"""
    wrong = scaled_robot(scaled_robot(panda, 1.2, "rotational"), 1.05, "mass")
    res = identify_inertia(wrong, panda_still_wrist_log, ARM_ESTIMATE, _options(panda_friction, link_margin=0.0))
    names = {u.parameter: u for u in res.unexcited}
    no_effect = [f"root_joint.{p}" for p in PHYSICAL] + [f"panda_joint1.{p}" for p in PHYSICAL if p != "I_zz"]
    assert all(n in names and not names[n].partners and names[n].information < 1e-6 for n in no_effect), names
    unc = InertialOptions().uncertainty
    for b in ("root_joint", "panda_joint1"):  # within 1e-3 of the prior's standard deviations
        k = res.bodies.index(b)
        given, found = (pin.Inertia.FromDynamicParameters(p[k]) for p in (res.pi_given, res.pi))
        assert abs(found.mass - given.mass) < 1e-3 * unc.mass * given.mass
        assert np.abs(found.lever - given.lever).max() < 1e-3 * unc.com
        dI = np.delete((found.inertia - given.inertia).ravel(), 8)  # but I_zz
        assert np.abs(dI).max() < 1e-3 * unc.inertia * np.linalg.eigvalsh(given.inertia)[-1]
    for k, b in enumerate(res.bodies):
        assert f"{b}.m" in names
        assert abs(res.pi[k, 0] / res.pi_given[k, 0] - 1.0) < 0.05, (b, res.pi[k, 0], res.pi_given[k, 0])
    assert {f"panda_joint{i}.F_v" for i in (5, 6, 7)} <= set(names)
    assert is_consistent(res.pi).all()


def test_noisy_accelerations_are_flagged(panda, panda_friction, panda_log):
    """Central differences of 19-bit encoders at 1 kHz: most of the accelerations' power is noise
    (above 250 Hz), which least squares turns into smaller inertias; the identification says so.
    Filtered (a given low-pass, or the one ``diff = "auto"`` chooses), none is."""
    res = identify_inertia(panda, panda_log, EstimateOptions(diff="central"), _options(panda_friction))
    assert np.all(res.acceleration_noise > 0.5) and "noisy accelerations" in res.message
    assert is_consistent(res.pi).all()
    for estimate in (ARM_ESTIMATE, EstimateOptions(diff="auto")):  # a low-pass given, or chosen from the log
        filtered = identify_inertia(panda, panda_log, estimate, _options(panda_friction))
        assert np.all(filtered.acceleration_noise < 0.01) and "noisy" not in filtered.message


@pytest.mark.slow
def test_the_gate_keeps_a_corrected_leg(talos, combined_walk):
    """Issue 24: the combined walk seen through a model whose left leg is wrong (masses x1.1, principal moments
    x1.3): the gate keeps the identified left leg, every joint's held-out torques are predicted no worse than
    by the given model with its best friction, and the leg joints' far better."""
    import dataclasses

    from wbfriction.inertia.sensitivity import scale_inertia
    model = pin.Model(talos.model)
    leg = [j for j in range(1, model.njoints) if model.names[j].startswith("leg_left")]
    for j in leg:
        model.inertias[j] = scale_inertia(scale_inertia(model.inertias[j], 1.3, "rotational"), 1.1, "mass")
    wrong = dataclasses.replace(talos, model=model, cache={})
    res = identify_inertia(wrong, combined_walk.log, EstimateOptions(), InertialOptions(stribeck_velocity=0.2))
    gate, h = res.validation, res.holdout
    kept = {g.name: g.kept for g in gate.groups}
    assert kept["leg_left_1_joint…leg_left_6_joint"], gate.groups
    np.testing.assert_array_equal(res.pi[[j - 1 for j in leg]], res.pi_fit[[j - 1 for j in leg]])
    assert np.all(h.validated <= h.given_with_friction * (1 + gate.tolerance) + gate.floor)
    legs = [i for i, j in enumerate(talos.torque_controlled) if j.startswith("leg_")]
    assert np.all(h.validated[legs] < 0.1 * h.given_with_friction[legs]), h


def test_held_out_rows_of_every_stance_are_predicted(talos, combined_walk):
    """The held-out samples of both soles' single support are stacked, each with its own stance's regressor: with
    the given model the stacked rows are its inverse dynamics, whichever foot is down (half the walk held out, so
    that both stances are in it)."""
    from wbfriction.inertia.held_out import held_out

    options = InertialOptions(holdout=0.5)
    samples = log_samples(talos, combined_walk.log, EstimateOptions(), options)
    held = held_out(talos, samples, body_parameters(talos.model), body_parameters(talos.model), [], options)
    stances = np.concatenate([part.stance[part.held] for part in samples.parts])
    assert set(stances) == {0, 1}, set(stances)  # both feet in the held-out rows
    assert held.samples == stances.size
    assert np.isfinite(held.measured).all() and np.isfinite(held.given).all()
