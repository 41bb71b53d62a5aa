"""The robot re-rooted at a stance sole: same dynamics as the floating-base model, its root wrench the
contact wrench, and the stance frame's pose."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from conftest import constrained_forward, random_state
from helpers import chain_urdf
from wbfriction.exceptions import ModelError
from wbfriction.model.dynamics import constrained_dynamics
from wbfriction.model.rerooted import body_frame, check_kinematics, stance_frame_pose, stance_model
from wbfriction.model.robot import Robot


@pytest.mark.parametrize("contact", [0, 1])
def test_stance_model_has_the_same_dynamics(talos, contact):
    """Re-rooted at a sole: same mass, same centre of mass and same centroidal inertia about it."""
    st = stance_model(talos, contact)
    rng = np.random.default_rng(contact)
    angles = rng.uniform(-0.5, 0.5, talos.n_act)
    m, d = talos.model, talos.model.createData()
    q = talos.configuration(angles)
    pin.framesForwardKinematics(m, d, q)
    q[:7] = pin.SE3ToXYZQUAT(d.oMf[talos.contact_frame_ids[contact]].inverse())  # sole at the origin
    r, dr = st.model, st.model.createData()
    q_r = st.layout.configuration(angles, None, st.sign)
    for model, data, config in ((m, d, q), (r, dr, q_r)):
        pin.ccrba(model, data, config, np.zeros(model.nv))
    np.testing.assert_allclose(pin.centerOfMass(r, dr, q_r), pin.centerOfMass(m, d, q), atol=1e-12)
    np.testing.assert_allclose(dr.Ig.matrix(), d.Ig.matrix(), atol=1e-10)


@pytest.mark.parametrize("robot_name", ["talos", "talos_tilted_sole"])
def test_stance_wrench_is_the_contact_wrench_in_the_contact_frame(robot_name, request):
    """Root rows of the stance RNEA = the wrench of pin.constraintDynamics (LOCAL), and the
    joint rows its joint torques, for a random base pose and a random state with J v = 0."""
    robot = request.getfixturevalue(robot_name)
    rng = np.random.default_rng(7)
    m = robot.model
    q, v = random_state(robot, rng, [1], base_random=True)
    tau = np.zeros(m.nv)
    tau[robot.act_v_index] = rng.normal(0.0, 10.0, robot.n_act)
    a, lam = constrained_forward(robot, q, v, tau, [1], with_wrench=True)
    d = m.createData()
    pin.framesForwardKinematics(m, d, q)
    pose = pin.SE3ToXYZQUAT(d.oMf[robot.contact_frame_ids[1]])[None]
    iv = robot.act_v_index
    tau_joint, wrench = stance_model(robot, 1).inverse_dynamics(pose, robot.angles(q)[None], v[iv][None], a[iv][None])
    np.testing.assert_allclose(tau_joint[0], tau[iv], atol=1e-8)
    np.testing.assert_allclose(wrench[0], lam, atol=1e-8 * (1 + np.abs(lam).max()))


def test_every_body_is_marked_and_the_leg_joints_reversed(talos):
    """Each original body has its frame in the rooted tree; the stance leg's joints turn the other way
    (the tree is walked from the foot), every other joint keeps its sign."""
    st = stance_model(talos, 1)
    for j in range(1, talos.model.njoints):
        assert st.model.existFrame(body_frame(j))
    leg = set(talos.limb(talos.contact_frames[1]))
    assert all((s < 0) == (name in leg) for name, s in zip(talos.actuated, st.sign))


@pytest.mark.parametrize("contact", [0, 1])
def test_stance_frame_pose(talos, contact):
    """Without a logged base the sole is flat at the origin; with one, the pose is the sole's by forward
    kinematics of the original model, to the last bit (issue 41: computed on the chain to the sole alone)."""
    st = stance_model(talos, contact)
    rng = np.random.default_rng(4)
    angles = rng.uniform(-0.3, 0.3, (3, talos.n_act))
    np.testing.assert_array_equal(stance_frame_pose(talos, st, angles, None), np.tile([0, 0, 0, 0, 0, 0, 1.0], (3, 1)))
    quat = pin.Quaternion(1, 0.2, -0.1, 0.3).normalized().coeffs()  # x, y, z, w
    base = np.column_stack([rng.normal(size=(3, 3)), np.tile(quat, (3, 1))])
    pose = stance_frame_pose(talos, st, angles, base)
    m, d = talos.model, talos.model.createData()
    for k in range(3):
        pin.framesForwardKinematics(m, d, talos.configuration(angles[k], base[k]))
        assert pose[k].tobytes() == pin.SE3ToXYZQUAT(d.oMf[talos.contact_frame_ids[contact]]).tobytes()



@pytest.mark.parametrize("contact", [0, 1])
@pytest.mark.parametrize("n_held", [0, 2, 5])
def test_acceleration_difference_is_the_kkt_operator(talos, contact, n_held):
    """Delta qdd of the stance-rooted tree equals M_mod^{-1} tau_f with M_mod^{-1} the joints' block of the
    floating-base KKT inverse (6D contact on the sole, the held joints' accelerations as constraints, 5.12),
    for any split of the joints into held and free, with armature on every joint."""
    rng = np.random.default_rng(10 * contact + n_held)
    model = pin.Model(talos.model)
    model.armature[6:] = rng.uniform(0.0, 0.3, model.nv - 6)
    robot = dataclasses.replace(talos, model=model, cache={})
    order = rng.permutation(robot.n_act)
    held, free = np.sort(order[:n_held]), np.sort(order[n_held:])
    angles = rng.uniform(*robot.angle_limits, (5, robot.n_act))
    tau_f = rng.normal(0.0, 5.0, (5, len(free)))
    got = stance_model(robot, contact).acceleration_difference(angles, tau_f, free)
    data = model.createData()
    iv = robot.act_v_index
    S = np.eye(model.nv)[iv[held]]
    for k in range(len(angles)):
        q = robot.configuration(angles[k])
        J = pin.computeFrameJacobian(model, data, q, robot.contact_frame_ids[contact], pin.LOCAL)
        kkt_inv = pin.computeKKTContactDynamicMatrixInverse(model, data, q, np.vstack([J, S]))
        expected = kkt_inv[np.ix_(iv[free], iv[free])] @ tau_f[k]
        np.testing.assert_allclose(got[k], expected, rtol=1e-8, atol=1e-9 * np.abs(expected).max())


def _crba_acceleration_difference(robot: Robot, contact: int, angles: np.ndarray, tau_f: np.ndarray) -> np.ndarray:
    """The crba route Delta qdd replaced (issue 41), as a reference: per sample, the locked-root tree's mass
    matrix factored (``crba``, sparse Cholesky), ``x = M^{-1} [tau_f; 0]`` and ``M^{-1} e_p`` for each held joint
    ``p``, the held joints removed by the block-inverse identity."""
    st = stance_model(robot, contact)
    model = pin.buildReducedModel(st.model, [1], pin.neutral(st.model))
    name_of_v = {int(st.model.idx_vs[j]): st.model.names[j] for j in range(2, st.model.njoints)}
    v_index = np.array([model.idx_vs[model.getJointId(name_of_v[int(v)])] for v in st.v_index])
    data, tc, pc = model.createData(), v_index[robot.tc_index], v_index[robot.pc_index]
    q = st.layout.configuration(angles, None, st.sign)[:, st.layout.root_nq:]
    out = np.empty_like(tau_f)
    for k in range(len(angles)):
        pin.crba(model, data, q[k])
        pin.cholesky.decompose(model, data)
        u = np.zeros(model.nv)
        u[tc] = tau_f[k] * st.sign[robot.tc_index]
        x = pin.cholesky.solve(model, data, u)
        X = np.column_stack([pin.cholesky.solve(model, data, e) for e in np.eye(model.nv)[pc]])
        out[k] = (x[tc] - X[tc] @ np.linalg.solve(X[pc], x[pc])) * st.sign[robot.tc_index]
    return out


@pytest.mark.parametrize("contact", [0, 1])
def test_acceleration_difference_equals_the_crba_route(talos, contact):
    """Issue 41: Delta qdd by the articulated-body algorithm on the locked tree (the head's position-controlled
    joints held by armature, at angles that change sample by sample) equals the crba route it replaced to 1e-9
    relative, on either sole."""
    assert len(talos.pc_index) == 2  # the premise: TALOS's head joints are position-controlled
    rng = np.random.default_rng(41 + contact)
    angles = rng.uniform(*talos.angle_limits, (200, talos.n_act))
    tau_f = rng.normal(0.0, 5.0, (200, len(talos.tc_index)))
    got = stance_model(talos, contact).acceleration_difference(angles, tau_f, talos.tc_index)
    expected = _crba_acceleration_difference(talos, contact, angles, tau_f)
    relative = np.abs(got - expected).max(axis=1) / np.abs(expected).max(axis=1)  # per sample
    assert relative.max() < 1e-9


def test_every_one_dof_joint_type_is_re_rooted():
    """Issue 37: a URDF continuous joint about an axis other than x, y, z (Pinocchio's
    RevoluteUnboundedUnaligned, whose bindings give no axis) stopped the stance model with an
    AttributeError. On a chain of all twelve 1-DoF joint types, the stance model's mass matrix is the
    inverse of M_mod^{-1} from the floating-base KKT system (an independent route), sample by sample."""
    model = pin.buildModelFromXML(chain_urdf(np.random.default_rng(5)), pin.JointModelFreeFlyer())
    names = tuple(model.names[j] for j in range(2, model.njoints))
    assert len({model.joints[j].shortname() for j in range(2, model.njoints)}) == 12  # the premise
    robot = Robot("chain", model, Path("chain.urdf"), names, names, (), ("sole",))
    st = stance_model(robot, 0)
    angles = np.random.default_rng(6).uniform(-1.0, 1.0, (3, robot.n_act))
    zeros = np.zeros_like(angles)
    dyn = constrained_dynamics(robot, angles, zeros, zeros, zeros, np.ones((3, 1), dtype=bool))
    M = st.joint_mass_matrix(angles, np.arange(robot.n_act))
    assert M.shape == (3, robot.n_act, robot.n_act)
    for k in range(3):
        np.testing.assert_allclose(dyn.Mmod_inv[k] @ M[k], np.eye(robot.n_act), atol=1e-9)


def test_a_re_rooted_model_that_misplaces_a_body_is_refused(talos):
    """The kinematic check behind every stance model: a joint placement off by 1 cm is named."""
    st = stance_model(talos, 0)
    broken = dataclasses.replace(st, model=pin.Model(st.model))
    j = broken.model.getJointId(talos.actuated[0])
    broken.model.jointPlacements[j] = broken.model.jointPlacements[j] * pin.SE3(np.eye(3), np.array([0.01, 0, 0]))
    with pytest.raises(ModelError, match=f"re-rooted model at '{st.frame}' disagrees with the original at body"):
        check_kinematics(talos, broken)
