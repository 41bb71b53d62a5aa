"""Ground truth: friction injected through the constrained forward dynamics is recovered.

Thesis Fig. 6.1: in single support the estimate equals the injected friction and is zero
where none was injected; in double support it is not unique.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import truth_samples
from wbfriction.friction.estimate import estimate_friction, regularised_least_squares
from wbfriction.friction.options import EstimateOptions
from wbfriction.model.dynamics import constrained_dynamics

NO_MARGIN = dict(lift_off_skip=0.0, touch_down_skip=0.0)
KNEE_AND_ARM = ["leg_right_4_joint", "leg_left_3_joint", "arm_left_2_joint", "torso_1_joint"]


@pytest.mark.parametrize("method", ["rnea", "kkt"])
@pytest.mark.parametrize("base_random", [False, True])
def test_single_support_recovers_injected_friction(talos, method, base_random):
    kin, tau_f_true = truth_samples(talos, 24, "single", seed=1, friction_joints=KNEE_AND_ARM,
                                    base_random=base_random)
    est = estimate_friction(talos, kin, EstimateOptions(method=method, **NO_MARGIN))
    assert np.all(est.unique)
    err = np.abs(est.tau_f - tau_f_true)
    assert err.max() < 1e-6, f"max error {err.max():.3g} N·m"
    others = [i for i, j in enumerate(talos.torque_controlled) if j not in KNEE_AND_ARM]
    assert np.abs(est.tau_f[:, others]).max() < 1e-6


@pytest.mark.parametrize("method", ["rnea", "kkt"])
def test_contact_frame_turned_against_its_joint(talos_tilted_sole, method):
    """The stance tree's root is the contact frame itself, whatever its axes (logged base:
    the frame's pose is taken as it is)."""
    robot = talos_tilted_sole
    kin, tau_f_true = truth_samples(robot, 12, "single", seed=4, friction_joints=KNEE_AND_ARM, base_random=True)
    assert kin.contact[:, 1].any()
    est = estimate_friction(robot, kin, EstimateOptions(method=method, **NO_MARGIN))
    assert np.abs(est.tau_f - tau_f_true).max() < 1e-6


def test_rnea_route_equals_kkt_route(talos):
    """(5.13) through inverse dynamics on the stance-rooted tree equals (5.10)-(5.13)."""
    kin, _ = truth_samples(talos, 16, "single", seed=2, friction_joints=list(talos.torque_controlled))
    # perturb the accelerations so that they are not consistent with any torque: both
    # routes must still agree exactly, as the same linear map of the measurement
    kin.qdd = kin.qdd + np.random.default_rng(3).normal(0.0, 0.5, kin.qdd.shape)
    a = estimate_friction(talos, kin, EstimateOptions(method="rnea", **NO_MARGIN))
    b = estimate_friction(talos, kin, EstimateOptions(method="kkt", **NO_MARGIN))
    assert np.abs(a.tau_f - b.tau_f).max() < 1e-9
    # the acceleration difference (5.12): M_mod^-1 tau_f of the stance tree = qdd_msr - qdd_est
    assert np.abs(a.delta_qdd - b.delta_qdd).max() < 1e-8 * np.abs(b.delta_qdd).max()
    assert np.abs(b.delta_qdd).max() > 0.1



def test_double_support_is_flagged_and_solves_the_regularised_problem(talos):
    kin, tau_f_true = truth_samples(talos, 6, "double", seed=4, friction_joints=["leg_right_4_joint"])
    # add one single-support sample: a log needs one
    ss, _ = truth_samples(talos, 1, "single", seed=5, friction_joints=[])
    for name in ("q", "qd", "qdd", "tau", "contact"):
        setattr(kin, name, np.concatenate([getattr(kin, name), getattr(ss, name)]))
    kin.time = np.arange(len(kin.q)) * 1e-3
    kin.valid = np.ones(len(kin.q), dtype=bool)
    opts = EstimateOptions(ds_regularization=1e-6, **NO_MARGIN)
    est = estimate_friction(talos, kin, opts)
    ds = slice(0, 6)
    assert not est.unique[ds].any() and est.unique[6]
    assert not est.valid[ds].any()
    assert list(est.phase[:7]) == ["double"] * 6 + ["single"]
    # the estimate reproduces the acceleration difference (5.12) nearly exactly...
    dyn = constrained_dynamics(talos, kin.q[ds], kin.qd[ds], kin.qdd[ds], kin.tau[ds], kin.contact[ds])
    tc = talos.tc_index
    delta = kin.qdd[ds][:, tc] - dyn.qdd_est[:, tc]
    reproduced = np.einsum("nij,nj->ni", dyn.Mmod_inv, est.tau_f[ds])
    assert np.abs(reproduced - delta).max() < 1e-3 * np.abs(delta).max()
    # ...but is not the injected friction: the map is singular (rank n_tc - 6)
    assert np.abs(est.tau_f[ds] - tau_f_true).max() > 1e-2
    ranks = [np.linalg.matrix_rank(A, tol=1e-8 * np.linalg.norm(A, 2)) for A in dyn.Mmod_inv]
    assert ranks == [len(tc) - 6] * 6
    # and it is the minimiser of (6.1): the gradient vanishes
    W, L = 1.0, 1e-6
    grad = np.einsum("nji,nj->ni", dyn.Mmod_inv, W * (reproduced - delta)) + L * est.tau_f[ds]
    assert np.abs(grad).max() < 1e-8 * max(1.0, np.abs(delta).max())


def test_regularised_least_squares_limits():
    rng = np.random.default_rng(0)
    A = rng.standard_normal((5, 4, 4))
    A = A @ np.swapaxes(A, 1, 2) + 4 * np.eye(4)
    x = rng.standard_normal((5, 4))
    d = np.einsum("nij,nj->ni", A, x)
    np.testing.assert_allclose(regularised_least_squares(A, d, 1.0, 0.0), x, atol=1e-10)
    # heavy regularisation drives the estimate to zero
    assert np.abs(regularised_least_squares(A, d, 1.0, 1e12)).max() < 1e-6
