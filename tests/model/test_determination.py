"""The rank decision of wbfriction.model.determination on constructed configurations: which joints' torques the
contacts leave determined, against the full stacked matrix [S^T  J_u^T] and against exact data."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import consistent_motion
from wbfriction.model.determination import COND_MAX, contact_jacobian, determine, joint_torques
from wbfriction.model.loading import load_robot

LEGS = ("FL", "FR", "RL", "RR")


@pytest.fixture(scope="module")
def go2():
    return load_robot("go2_walking")


def _leg(robot, prefix: str) -> np.ndarray:
    return np.array([n.startswith(prefix + "_") for n in robot.actuated])


def _state(robot, seed: int, spread: float = 0.1, n: int = 3):
    """Configurations near standing (the base tilted a little), velocities and accelerations, drawn with ``seed``."""
    rng = np.random.default_rng(seed)
    q = np.tile(robot.q_reference, (n, 1))
    q[:, 7:] += rng.normal(0.0, spread, (n, robot.n_act))
    q[:, 3:7] = [pin.SE3ToXYZQUAT(pin.SE3(pin.rpy.rpyToMatrix(*rng.normal(0, 0.1, 3)), np.zeros(3)))[3:]
                 for _ in range(n)]
    return q, rng.normal(0, 0.5, (n, robot.model.nv)), rng.normal(0, 1.0, (n, robot.model.nv))


def _stacked_decision(robot, q, flags, free_rows=None):
    """The decision made on the whole stacked matrix [S^T  J_u^T] (nv x (n_act + m)) by its own SVD: joint j is
    determined when no null vector has a component on its torque."""
    model, data = robot.model, robot.model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J = np.vstack([np.zeros((0, model.nv))] + [contact_jacobian(robot, data, c) for c in np.flatnonzero(flags)])
    if free_rows is not None:
        J = J[free_rows]
    S_T = np.zeros((model.nv, robot.n_act))
    S_T[robot.act_v_index, np.arange(robot.n_act)] = 1.0
    A = np.hstack([S_T, J.T])
    _, s, Vt = np.linalg.svd(A)
    rank = int((s > 1e-9 * s[0]).sum())
    null = Vt[rank:]
    return np.linalg.norm(null[:, :robot.n_act], axis=0) < 1e-9, A.shape[1] - rank


@pytest.mark.parametrize("feet, determined_legs, nullity", [
    ((1, 0, 0, 1), ("FR", "RL"), 1),   # a trot's stance: the swing legs only
    ((0, 1, 1, 0), ("FL", "RR"), 1),
    ((1, 1, 1, 0), ("RR",), 3),        # a walk's stance: the swinging leg
    ((1, 1, 1, 1), (), 6),             # standing: no joint
    ((1, 0, 0, 0), LEGS, 0),           # one foot: every joint
    ((0, 0, 0, 0), LEGS, 0),           # flight
])
def test_point_feet_decision(go2, feet, determined_legs, nullity):
    q, v, a = _state(go2, 0)
    flags = np.tile(np.array(feet, dtype=bool), (len(q), 1))
    det = joint_torques(go2, q, v, a, flags).determination
    expected = np.zeros(go2.n_act, dtype=bool)
    for leg in determined_legs:
        expected |= _leg(go2, leg)
    assert (det.determined == expected).all()
    assert (det.nullity == nullity).all()
    for k in range(len(q)):  # the same decision as the whole stacked matrix's
        stacked, stacked_nullity = _stacked_decision(go2, q[k], np.array(feet, dtype=bool))
        assert (stacked == expected).all() and stacked_nullity == nullity
    if any(feet):
        assert (det.cond < 30).all()  # a regular stance is well conditioned


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), feet=st.sampled_from([(1, 0, 0, 1), (0, 1, 1, 0), (1, 1, 1, 0), (0, 1, 1, 1),
                                                            (1, 1, 1, 1), (0, 0, 1, 0), (0, 0, 0, 0)]),
       forces=st.sampled_from(["none", "normal", "3d"]))
def test_determined_torques_are_exact(go2, seed, feet, forces):
    """On exact data, every joint called determined gets the true torque (1e-8 relative); with 3-D foot forces,
    every joint is determined."""
    rng = np.random.default_rng(seed)
    q, v, _ = _state(go2, seed, n=2)
    flags = np.tile(np.array(feet, dtype=bool), (2, 1))
    force = rng.normal(0, 40, (2, 4, 3)) + [0, 0, 60]
    tau_f = rng.normal(0, 1, (2, go2.n_act))
    a, tau = consistent_motion(go2, q, v, rng.normal(0, 2, (2, go2.n_act)), flags, force, tau_f)
    measured = {"none": None, "3d": force,
                "normal": np.where(np.arange(3) == 2, force, np.nan)}[forces]
    sol = joint_torques(go2, q, v, a, flags, measured)
    d = sol.determination.determined
    truth = tau + tau_f
    assert np.allclose(sol.tau[d], truth[d], rtol=1e-8, atol=1e-8 * np.abs(truth).max())
    assert np.isnan(sol.tau[~d]).all()
    assert np.abs(sol.determination.residual).max() < 1e-8 * np.abs(truth).max()
    if forces == "3d":
        assert d.all()


def test_normal_forces_leave_flat_stance_legs_undetermined(go2):
    """Feet on flat ground push against each other horizontally: their normal forces do not remove that, so a
    stance leg stays not determined with normal forces alone, and is determined with 3-D forces."""
    q = go2.q_reference[None].copy()  # standing: the four feet at one height
    v, a = np.zeros((1, go2.model.nv)), np.zeros((1, go2.model.nv))
    flags = np.array([[1, 0, 0, 1]], dtype=bool)
    normal = np.full((1, 4, 3), np.nan)
    normal[..., 2] = 40.0
    det = joint_torques(go2, q, v, a, flags, normal).determination
    assert not det.determined[0, _leg(go2, "FL")].any() and det.determined[0, _leg(go2, "FR")].all()
    free_rows = [0, 1, 3, 4]  # the tangential rows of the two feet
    stacked, _ = _stacked_decision(go2, q[0], flags[0], free_rows)
    assert (stacked == det.determined[0]).all()


def test_ill_conditioned_direction_leaves_only_the_joints_it_moves_undetermined():
    """A contact map with a singular value just above round-off (three feet nearly on a line): the internal force
    along it counts as free, so the joints it moves are not determined and those the contacts do not reach are
    (issue 63: a badly conditioned stance dropped the swinging legs too); well conditioned, the rank is full."""
    rng = np.random.default_rng(1)
    U, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    V, _ = np.linalg.qr(rng.normal(size=(9, 9)))
    s = np.array([1.0, 0.8, 0.5, 0.4, 0.3, 0.3 / (10 * COND_MAX)])
    base_map = (U[:, :6] * s) @ V[:6]
    joint_map = rng.normal(size=(1, 12, 9))
    joint_map[0, :3] = 0.0  # a joint the contacts do not reach
    r_base, r_joint = rng.normal(size=(1, 6)), rng.normal(size=(1, 12))
    tau, _, det = determine(base_map[None], joint_map, r_base, r_joint)
    assert det.nullity[0] == 4 and det.cond[0] == pytest.approx(1.0 / 0.3)
    assert det.determined[0, :3].all() and not det.determined[0, 3:].any()
    assert np.array_equal(tau[0, :3], r_joint[0, :3])  # no contact force on their rows
    well = (U[:, :6] * s[[0, 1, 2, 3, 4, 4]]) @ V[:6]
    _, _, det = determine(well[None], joint_map, r_base, r_joint)
    assert det.nullity[0] == 3 and det.cond[0] == pytest.approx(1.0 / 0.3)
    assert det.determined[0, :3].all() and not det.determined[0, 3:].any()


def test_stance_a_few_micrometres_off_flat_keeps_the_swinging_legs(go2):
    """Normal forces measured on a trot's stance whose feet stand 1e-6 m apart in height (a simulator's drift): the
    horizontal forces' moments nearly repeat their sum's, a singular value 1e-6 of the largest. The swinging legs
    stay determined and exact, the stance legs not (before issue 63 the whole sample was dropped)."""
    rng = np.random.default_rng(3)
    q = np.tile(go2.q_reference, (2, 1))
    calf = [i for i, n in enumerate(go2.actuated) if n == "FL_calf_joint"][0]
    q[1, 7 + calf] += 1e-5  # the FL foot about a micrometre lower
    v, flags = rng.normal(0, 0.3, (2, go2.model.nv)), np.tile(np.array([1, 0, 0, 1], dtype=bool), (2, 1))
    force = rng.normal(0, 20, (2, 4, 3)) + [0, 0, 70]
    tau_f = rng.normal(0, 1, (2, go2.n_act))
    a, tau = consistent_motion(go2, q, v, rng.normal(0, 2, (2, go2.n_act)), flags, force, tau_f)
    normal = np.where(np.arange(3) == 2, force, np.nan)
    sol = joint_torques(go2, q, v, a, flags, normal)
    swing = _leg(go2, "FR") | _leg(go2, "RL")
    assert (sol.determination.determined == swing).all()
    assert np.allclose(sol.tau[:, swing], (tau + tau_f)[:, swing], rtol=1e-8, atol=1e-8)
    assert (sol.determination.cond <= COND_MAX).all()


def test_soles_single_and_double_support():
    """A humanoid's soles in the same terms: single support determines every joint (thesis 5.13); double support
    the joints off the legs' closed chain (torso, arms, head), not the legs."""
    robot = load_robot("talos")
    q = robot.q_reference[None]
    v, a = np.zeros((1, robot.model.nv)), np.zeros((1, robot.model.nv))
    single = joint_torques(robot, q, v, a, np.array([[1, 0]], dtype=bool)).determination
    assert single.determined.all() and single.nullity[0] == 0
    double = joint_torques(robot, q, v, a, np.array([[1, 1]], dtype=bool)).determination
    legs = np.array([n.startswith("leg_") for n in robot.actuated])
    assert double.nullity[0] == 6
    assert not double.determined[0, legs].any() and double.determined[0, ~legs].all()
