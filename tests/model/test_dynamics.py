"""Constrained floating-base dynamics (thesis 5.4-5.12) against independent routes: Pinocchio's proximal
constrained forward dynamics, the stance-rooted mass matrix, and the rank the constraints leave."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from conftest import constrained_forward, random_state
from wbfriction.model.dynamics import constrained_dynamics, floating_base_state
from wbfriction.model.rerooted import stance_model


def _samples(robot, support: str, n: int, seed: int):
    """n random states (q, v), torques, and their true accelerations through pin.constraintDynamics."""
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(n):
        active = [int(rng.integers(2))] if support == "single" else [0, 1]
        q, v = random_state(robot, rng, active, base_random=False)
        tau = np.zeros(robot.model.nv)
        tau[robot.act_v_index] = rng.normal(0.0, 20.0, robot.n_act)  # the head's too: pc torques unknown
        a = constrained_forward(robot, q, v, tau, active)
        contact = np.zeros(2, dtype=bool)
        contact[active] = True
        rows.append((robot.angles(q), v[robot.act_v_index], a[robot.act_v_index], tau[robot.act_v_index], contact))
    angles, qd, qdd, tau, contact = (np.array(x) for x in zip(*rows))
    return angles, qd, qdd, tau[:, robot.tc_index], contact


@pytest.mark.parametrize("support", ["single", "double"])
def test_acceleration_estimate_is_the_constrained_forward_dynamics(talos, support):
    """(5.10) with the measured head accelerations as constraints (5.4c) gives back the accelerations that
    Pinocchio's proximal solver computed from the same torques: no friction, no difference."""
    angles, qd, qdd, tau_tc, contact = _samples(talos, support, 4, seed=3)
    dyn = constrained_dynamics(talos, angles, qd, qdd, tau_tc, contact, with_Mmod_inv=False)
    np.testing.assert_allclose(dyn.qdd_est, qdd, atol=1e-7 * (1 + np.abs(qdd).max()))
    assert dyn.Mmod_inv is None


def test_Mmod_inv_is_the_inverse_of_the_stance_mass_matrix(talos):
    """In single support, (5.12)'s operator from the KKT inverse and the mass matrix of the tree rooted at
    the stance sole (the route of 5.13) are inverses of each other."""
    angles, qd, qdd, tau_tc, contact = _samples(talos, "single", 3, seed=5)
    dyn = constrained_dynamics(talos, angles, qd, qdd, tau_tc, contact)
    for k in range(len(angles)):
        c = int(np.flatnonzero(contact[k])[0])
        M_mod = stance_model(talos, c).joint_mass_matrix(angles[k:k + 1], talos.tc_index)[0]
        np.testing.assert_allclose(dyn.Mmod_inv[k] @ M_mod, np.eye(len(talos.tc_index)), atol=1e-8)


def test_double_support_leaves_rank_n_tc_minus_6(talos):
    """Both soles welded: the closed chain takes 6 degrees of freedom, so M_mod^{-1} (n_tc, n_tc) is
    symmetric positive semi-definite with exactly 6 zero eigenvalues (the estimate is not unique, 6.1)."""
    angles, qd, qdd, tau_tc, contact = _samples(talos, "double", 2, seed=9)
    dyn = constrained_dynamics(talos, angles, qd, qdd, tau_tc, contact)
    for A in dyn.Mmod_inv:
        np.testing.assert_allclose(A, A.T, atol=1e-10 * np.abs(A).max())
        ev = np.linalg.eigvalsh(A)
        assert np.sum(np.abs(ev) < 1e-9 * ev.max()) == 6
        assert ev.min() > -1e-9 * ev.max()


def test_floating_base_state_meets_the_contacts(talos):
    """The reconstructed base: the stance sole flat at the origin, the base twist such that J v = 0 for
    every contact on the ground (single support exactly, double support in least squares of a state that
    meets both)."""
    rng = np.random.default_rng(2)
    data = talos.model.createData()
    for active in ([0], [1], [0, 1]):
        q_true, v_true = random_state(talos, rng, active, base_random=False)
        q, v, J = floating_base_state(talos, data, talos.angles(q_true), v_true[talos.act_v_index], active, None)
        pin.framesForwardKinematics(talos.model, data, q)
        sole = data.oMf[talos.contact_frame_ids[active[0]]]
        np.testing.assert_allclose(sole.homogeneous, np.eye(4), atol=1e-12)
        np.testing.assert_allclose(J @ v, 0.0, atol=1e-10)
        np.testing.assert_allclose(v, v_true, atol=1e-9)


def test_batched_schur_route_equals_pinocchio_kkt_per_sample(talos):
    """Rows of both supports mixed in one call, each with a logged base pose: qdd_est and M_mod^{-1} equal
    pin.forwardDynamics and the tc block of pin.computeKKTContactDynamicMatrixInverse, sample by sample."""
    single = _samples(talos, "single", 3, seed=4)
    double = _samples(talos, "double", 3, seed=5)
    angles, qd, qdd, tau_tc, contact = (np.concatenate([s, d])[[0, 3, 1, 4, 2, 5]] for s, d in zip(single, double))
    base = np.array([pin.SE3ToXYZQUAT(pin.SE3.Random()) for _ in range(len(angles))])
    dyn = constrained_dynamics(talos, angles, qd, qdd, tau_tc, contact, base)
    model, data = talos.model, talos.model.createData()
    iv_tc, iv_pc = talos.act_v_index[talos.tc_index], talos.act_v_index[talos.pc_index]
    for k in range(len(angles)):
        active = list(np.flatnonzero(contact[k]))
        q, v, J = floating_base_state(talos, data, angles[k], qd[k], active, base[k])
        np.testing.assert_allclose(dyn.q[k], q, atol=1e-15)
        np.testing.assert_allclose(dyn.v[k], v, atol=1e-12)
        pin.forwardKinematics(model, data, q, v, np.zeros(model.nv))
        drift = [pin.getFrameAcceleration(model, data, talos.contact_frame_ids[c], pin.LOCAL).vector for c in active]
        Jc = np.vstack([J, np.eye(model.nv)[iv_pc]])
        gamma = np.concatenate(drift + [-qdd[k, talos.pc_index]])
        tau = np.zeros(model.nv)
        tau[iv_tc] = tau_tc[k]
        a = pin.forwardDynamics(model, data, q, v, tau, Jc, gamma)
        np.testing.assert_allclose(dyn.qdd_est[k], a[talos.act_v_index], rtol=1e-9, atol=1e-9 * np.abs(a).max())
        expected = pin.computeKKTContactDynamicMatrixInverse(model, data, q, Jc)[np.ix_(iv_tc, iv_tc)]
        np.testing.assert_allclose(dyn.Mmod_inv[k], expected, atol=1e-9 * np.abs(expected).max())
