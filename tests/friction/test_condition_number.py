"""The condition number the estimator reports (``--cond``): ``numpy.linalg.cond`` of ``M_mod^{-1}`` (5.12), with
the operator built in the test by another formula than the estimator's KKT inverse: the null-space
projection ``S_tc M^{-1} (I - Jc^T (Jc M^{-1} Jc^T)^{-1} Jc M^{-1}) S_tc^T`` (thesis 5.12)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from conftest import truth_samples
from wbfriction.friction.estimate import estimate_friction
from wbfriction.friction.options import EstimateOptions

NO_MARGIN = dict(lift_off_skip=0.0, touch_down_skip=0.0)


def _index(model: pin.Model, joints, attr: str) -> np.ndarray:
    return np.array([getattr(model.joints[model.getJointId(j)], attr) for j in joints])


def projected_operator(robot, angles: np.ndarray, active: list[int]) -> np.ndarray:
    """``M_mod^{-1}`` (n_tc, n_tc) of one sample by the null-space projection of the constraints: the
    ``active`` soles (LOCAL 6D Jacobians) and the position-controlled joints' selection rows (5.4c). The
    free-flyer mass matrix and LOCAL Jacobians do not depend on the base pose."""
    model = robot.model
    data = model.createData()
    q = pin.neutral(model)
    q[_index(model, robot.actuated, "idx_q")] = angles
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    pc = _index(model, robot.position_controlled, "idx_v")
    S_pc = np.eye(model.nv)[pc]
    Jc = np.vstack([pin.computeFrameJacobian(model, data, q, model.getFrameId(robot.contact_frames[c]), pin.LOCAL)
                    for c in active] + [S_pc])
    Minv = np.linalg.inv(M)
    P = Minv - Minv @ Jc.T @ np.linalg.solve(Jc @ Minv @ Jc.T, Jc @ Minv)
    tc = _index(model, robot.torque_controlled, "idx_v")
    return P[np.ix_(tc, tc)]


@pytest.mark.parametrize("method", ["rnea", "kkt"])
def test_condition_number_is_numpy_cond_of_the_operator(talos, method):
    kin, _ = truth_samples(talos, 6, "single", seed=7, friction_joints=list(talos.torque_controlled))
    est = estimate_friction(talos, kin, EstimateOptions(method=method, condition_number=True, **NO_MARGIN))
    assert est.cond is not None and np.all(est.unique)
    ref = np.array([np.linalg.cond(projected_operator(talos, kin.q[k], list(np.flatnonzero(kin.contact[k]))))
                    for k in range(len(kin.q))])
    assert np.all(ref > 10.0)  # far from 1: a norm, a trace or a largest eigenvalue would not match it
    np.testing.assert_allclose(est.cond, ref, rtol=1e-9)


def test_condition_number_is_absent_unless_asked_and_huge_in_double_support(talos):
    kin, _ = truth_samples(talos, 3, "double", seed=8, friction_joints=[])
    ss, _ = truth_samples(talos, 2, "single", seed=9, friction_joints=[])
    for name in ("q", "qd", "qdd", "tau", "contact"):
        setattr(kin, name, np.concatenate([getattr(kin, name), getattr(ss, name)]))
    kin.time = np.arange(len(kin.q)) * 1e-3
    kin.valid = np.ones(len(kin.q), dtype=bool)
    assert estimate_friction(talos, kin, EstimateOptions(**NO_MARGIN)).cond is None
    est = estimate_friction(talos, kin, EstimateOptions(condition_number=True, **NO_MARGIN))
    assert est.cond is not None
    # both soles welded: M_mod^{-1} has 6 zero eigenvalues (6.1), so its condition number is huge
    assert np.all(est.cond[:3] > 1e8)
    for k in (3, 4):
        ref = np.linalg.cond(projected_operator(talos, kin.q[k], list(np.flatnonzero(kin.contact[k]))))
        assert est.cond[k] == pytest.approx(ref, rel=1e-9)
