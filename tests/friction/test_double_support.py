"""Double support (thesis 6.1) against an independent reference: the operator A = M_mod^{-1} built in the
test from Pinocchio's mass matrix and contact Jacobians (the KKT matrix written out and inverted with
numpy), the acceleration difference of the injected friction, and the weighted, regularised least squares
(6.1) solved by ``numpy.linalg.lstsq`` with per-joint W and Lambda."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import truth_samples
from wbfriction.friction.estimate import estimate_friction, regularised_least_squares
from wbfriction.friction.options import EstimateOptions

NO_MARGIN = dict(lift_off_skip=0.0, touch_down_skip=0.0)


def _v_index(model: pin.Model, joints) -> np.ndarray:
    return np.array([model.joints[model.getJointId(j)].idx_v for j in joints])


def _q_index(model: pin.Model, joints) -> np.ndarray:
    return np.array([model.joints[model.getJointId(j)].idx_q for j in joints])


def reference_operator(robot, angles: np.ndarray, active: list[int]) -> np.ndarray:
    """``A = M_mod^{-1}`` (n_tc, n_tc) of one sample: the torque-controlled block of the upper-left block of
    ``[[M, Jc^T], [Jc, 0]]^{-1}``, with ``Jc`` the LOCAL 6D Jacobians of the ``active`` soles stacked on the
    selection rows of the position-controlled joints (their accelerations are measured, 5.4c). The mass
    matrix of a free-flyer model and LOCAL Jacobians do not depend on the base pose: any base will do."""
    model = robot.model
    data = model.createData()
    q = pin.neutral(model)
    q[_q_index(model, robot.actuated)] = angles
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    rows = [pin.computeFrameJacobian(model, data, q, model.getFrameId(robot.contact_frames[c]), pin.LOCAL)
            for c in active]
    pc = _v_index(model, robot.position_controlled)
    S_pc = np.zeros((len(pc), model.nv))
    S_pc[np.arange(len(pc)), pc] = 1.0
    Jc = np.vstack(rows + [S_pc])
    m = Jc.shape[0]
    kkt = np.block([[M, Jc.T], [Jc, np.zeros((m, m))]])
    inv = np.linalg.inv(kkt)
    tc = _v_index(model, robot.torque_controlled)
    return inv[np.ix_(tc, tc)]


def weighted_regularised_lstsq(A: np.ndarray, delta: np.ndarray, w: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """argmin_x 1/2 |delta - A x|_W^2 + 1/2 x^T Lambda x (W, Lambda diagonal), as the stacked least squares
    ``[sqrt(W) A; sqrt(Lambda)] x = [sqrt(W) delta; 0]``."""
    lhs = np.vstack([np.sqrt(w)[:, None] * A, np.diag(np.sqrt(lam))])
    rhs = np.concatenate([np.sqrt(w) * delta, np.zeros(len(lam))])
    return np.linalg.lstsq(lhs, rhs, rcond=None)[0]


def _double_support_log(robot, n: int, seed: int, base_random: bool):
    """n double-support samples with friction on every torque-controlled joint, then one single-support
    sample (an estimate needs one)."""
    kin, tau_f_true = truth_samples(robot, n, "double", seed=seed, friction_joints=list(robot.torque_controlled),
                                    base_random=base_random)
    ss, _ = truth_samples(robot, 1, "single", seed=seed + 100, friction_joints=[], base_random=base_random)
    for name in ("q", "qd", "qdd", "tau", "contact") + (("base",) if base_random else ()):
        setattr(kin, name, np.concatenate([getattr(kin, name), getattr(ss, name)]))
    kin.time = np.arange(len(kin.q)) * 1e-3
    kin.valid = np.ones(len(kin.q), dtype=bool)
    return kin, tau_f_true


@pytest.mark.parametrize("base_random", [False, True])
def test_double_support_against_an_independent_kkt(talos, base_random):
    """Both soles welded, friction injected on every torque-controlled joint through Pinocchio's proximal
    constrained dynamics: the estimator's acceleration difference is ``A tau_f_true`` (5.12) with ``A``
    built here, and its friction is the lstsq solution of (6.1) with per-joint W and Lambda. Without a
    logged base the estimator rebuilds it from the first sole (the truth's is flat); with one, it uses it."""
    n = 4
    kin, tau_f_true = _double_support_log(talos, n, seed=11, base_random=base_random)
    n_tc = len(talos.torque_controlled)
    rng = np.random.default_rng(5)
    w = np.exp(rng.uniform(np.log(0.2), np.log(5.0), n_tc))  # per-joint weights, a factor 25 apart
    lam = np.exp(rng.uniform(np.log(1e-4), np.log(1e-2), n_tc))
    est = estimate_friction(talos, kin, EstimateOptions(ds_weight=tuple(w), ds_regularization=tuple(lam),
                                                        **NO_MARGIN))
    assert not est.unique[:n].any() and list(est.phase[:n]) == ["double"] * n
    for k in range(n):
        A = reference_operator(talos, kin.q[k], [0, 1])
        assert np.linalg.matrix_rank(A, tol=1e-8 * np.linalg.norm(A, 2)) == n_tc - 6
        delta = A @ tau_f_true[k]
        np.testing.assert_allclose(est.delta_qdd[k], delta, rtol=0, atol=1e-10 * np.abs(delta).max())
        ref = weighted_regularised_lstsq(A, delta, w, lam)
        np.testing.assert_allclose(est.tau_f[k], ref, rtol=0, atol=1e-6 * np.abs(ref).max())
        # the regularised solution is not the injected friction, and the weights matter
        assert np.abs(ref - tau_f_true[k]).max() > 1e-2
        unweighted = weighted_regularised_lstsq(A, delta, np.ones(n_tc), lam)
        assert np.abs(unweighted - ref).max() > 1e3 * 1e-6 * np.abs(ref).max()


def test_per_joint_weight_and_regularisation_of_a_measured_difference(talos):
    """Accelerations perturbed away from any friction (as measured ones are): (6.1) is still the lstsq
    solution for the measured difference ``qdd_msr - qdd_est``, with ``qdd_est`` the friction-free
    acceleration: ``Delta = A tau_f_true + (perturbation of the torque-controlled joints)``."""
    n = 3
    kin, tau_f_true = _double_support_log(talos, n, seed=21, base_random=False)
    tc = talos.tc_index
    noise = np.random.default_rng(8).normal(0.0, 0.5, (n, len(tc)))
    kin.qdd = kin.qdd.copy()
    kin.qdd[:n, tc] += noise  # only the torque-controlled joints: the head's are constraints (5.4c)
    w = np.linspace(0.3, 3.0, len(tc))
    lam = np.linspace(5e-3, 5e-4, len(tc))
    est = estimate_friction(talos, kin, EstimateOptions(ds_weight=tuple(w), ds_regularization=tuple(lam),
                                                        **NO_MARGIN))
    for k in range(n):
        A = reference_operator(talos, kin.q[k], [0, 1])
        delta = A @ tau_f_true[k] + noise[k]
        np.testing.assert_allclose(est.delta_qdd[k], delta, rtol=0, atol=1e-10 * np.abs(delta).max())
        ref = weighted_regularised_lstsq(A, delta, w, lam)
        np.testing.assert_allclose(est.tau_f[k], ref, rtol=0, atol=1e-6 * np.abs(ref).max())


@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 8), rank_loss=st.integers(0, 3))
@settings(max_examples=40, deadline=None)
def test_regularised_least_squares_is_the_stacked_lstsq(seed, n, rank_loss):
    """(6.1) on random symmetric positive semi-definite operators (rank deficient like double support's),
    per-joint W and Lambda, against numpy.linalg.lstsq of the stacked problem."""
    rng = np.random.default_rng(seed)
    m = 3
    B = rng.standard_normal((m, n, n - min(rank_loss, n - 1)))
    A = B @ np.swapaxes(B, 1, 2)
    delta = rng.standard_normal((m, n))
    w = np.exp(rng.uniform(-2, 2, n))
    lam = np.exp(rng.uniform(-6, 0, n))
    got = regularised_least_squares(A, delta, w, lam)
    for k in range(m):
        ref = weighted_regularised_lstsq(A[k], delta[k], w, lam)
        np.testing.assert_allclose(got[k], ref, rtol=0, atol=1e-8 * (1 + np.abs(ref).max()))
