"""The generalized momentum and its rate (issue 38) against Pinocchio's own terms, on random states."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from helpers import chain_urdf
from wbfriction.model import momentum
from wbfriction.model.force_torque import above_sensors_model
from wbfriction.model.measured_dynamics import measured_momentum
from wbfriction.model.momentum import momentum_and_drift, tree_momentum_and_drift
from wbfriction.model.rerooted import stance_model


def _states(model: pin.Model, rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)) for _ in range(n)])
    return q, rng.standard_normal((n, model.nv))


def test_momentum_and_its_rate_are_pinocchios_terms(talos):
    """``p = M v`` (``crba``) and ``b = C^T v - g`` (``computeCoriolisMatrix``, ``computeGeneralizedGravity``) on the
    whole floating robot, at random states."""
    model, rng = talos.model, np.random.default_rng(0)
    q, v = _states(model, rng, 5)
    p, b, _ = momentum_and_drift(model, q, v)
    data = model.createData()
    for k in range(5):
        M = pin.crba(model, data, q[k])
        C = pin.computeCoriolisMatrix(model, data, q[k], v[k]).copy()
        g = pin.computeGeneralizedGravity(model, data, q[k])
        np.testing.assert_allclose(p[k], M @ v[k], atol=1e-10)
        np.testing.assert_allclose(b[k], C.T @ v[k] - g, atol=1e-9)


def test_the_momentum_rate_along_a_motion_is_the_torques_plus_the_drift(talos):
    """``d/dt (M(q) v) = tau + C^T v - g`` with ``tau = rnea(q, v, a)``: the derivative of the momentum along
    ``q + s v``, ``v + s a`` (central differences, step 1e-6) against the identity, at random states."""
    model, rng = talos.model, np.random.default_rng(1)
    data = model.createData()
    q, v = _states(model, rng, 4)
    for k in range(4):
        a = rng.standard_normal(model.nv)
        h = 1e-6
        plus = pin.crba(model, data, pin.integrate(model, q[k], h * v[k])) @ (v[k] + h * a)
        minus = pin.crba(model, data, pin.integrate(model, q[k], -h * v[k])) @ (v[k] - h * a)
        tau = pin.rnea(model, data, q[k], v[k], a)
        _, b, _ = momentum_and_drift(model, q[k:k + 1], v[k:k + 1])
        # the free flyer's momentum is in its own moving frame: only the joints' rows are a plain derivative
        np.testing.assert_allclose(((plus - minus) / (2 * h))[6:], (tau + b[0])[6:], rtol=1e-6, atol=1e-5)


def test_external_wrenches_enter_as_their_jacobians_transpose(talos):
    """With the sensors' wrenches, ``b`` gains ``sum_s J_s^T f_s`` (the sensor frames' LOCAL Jacobians)."""
    robot, rng = talos, np.random.default_rng(2)
    model = above_sensors_model(robot.model, robot.ft_sensors)
    data = model.createData()
    q, v = _states(model, rng, 3)
    wrench = rng.standard_normal((3, len(robot.ft_sensors), 6)) * 50
    p, b, e = measured_momentum(robot, q, v, wrench)
    for k in range(3):
        _, free, _ = momentum_and_drift(model, q[k:k + 1], v[k:k + 1])
        pin.computeJointJacobians(model, data, q[k])
        JTf = np.zeros(model.nv)
        for s, w in zip(robot.ft_sensors, wrench[k]):
            J = pin.getJointJacobian(model, data, s.joint, pin.LOCAL)
            JTf += J.T @ s.placement.act(pin.Force(w)).vector
        np.testing.assert_allclose(b[k], free[0][robot.act_v_index], atol=1e-8)
        np.testing.assert_allclose(e[k], JTf[robot.act_v_index], atol=1e-8)
        np.testing.assert_allclose(p[k], (pin.crba(model, data, q[k]) @ v[k])[robot.act_v_index], atol=1e-10)


@pytest.mark.parametrize("contact", [0, 1])
def test_a_stance_trees_momentum_is_the_floating_robots_with_the_foot_still(talos, contact):
    """Along a motion of the joints with the sole welded flat, ``dp/dt = tau + b`` row by row, ``tau`` the joint
    torques the rooted tree's inverse dynamics gives (the sole's wrench acts on its root alone)."""
    robot, rng = talos, np.random.default_rng(3 + contact)
    stance = stance_model(robot, contact)
    angles = rng.uniform(*robot.angle_limits, size=(1, robot.n_act))
    qd, qdd = rng.standard_normal((1, robot.n_act)), rng.standard_normal((1, robot.n_act))
    h = 1e-6
    p_plus, _ = stance.momentum(angles + h * qd, qd + h * qdd)
    p_minus, _ = stance.momentum(angles - h * qd, qd - h * qdd)
    _, b = stance.momentum(angles, qd)
    pose = np.r_[np.zeros(6), 1.0][None]
    tau, _ = stance.inverse_dynamics(pose, angles, qd, qdd)
    np.testing.assert_allclose((p_plus - p_minus) / (2 * h), tau + b, rtol=1e-6, atol=1e-5)


def test_a_tilted_foot_sees_gravity_tilted(talos):
    """The welded sole turned upside down: gravity's torques change sign (``b = -g`` at rest)."""
    stance = stance_model(talos, 0)
    angles = np.zeros((1, talos.n_act))
    zero = np.zeros((1, talos.n_act))
    _, flat = stance.momentum(angles, zero)
    upside_down = np.r_[np.zeros(3), 1.0, 0.0, 0.0, 0.0][None]  # half a turn about x
    _, turned = stance.momentum(angles, zero, upside_down)
    moved = np.abs(flat) > 1e-6
    assert moved.sum() > 5
    np.testing.assert_allclose(turned[moved], -flat[moved], rtol=1e-9)


def _tree_cases(talos) -> list[tuple[str, pin.Model]]:
    """Fixed-base trees: TALOS's stance tree with its root locked (reversed joints, continuous joints none), and a
    chain of every 1-DoF joint type Pinocchio makes of a URDF (tests/model/test_rerooted.py)."""
    stance = stance_model(talos, 1)
    rooted = pin.buildReducedModel(stance.model, [1], pin.neutral(stance.model))
    chain = pin.buildModelFromXML(chain_urdf(np.random.default_rng(7)))
    return [("talos", rooted), ("chain", chain)]


@pytest.mark.parametrize("case", [0, 1])
def test_the_batched_tree_terms_are_pinocchios(talos, case, monkeypatch):
    """Issue 41: :func:`tree_momentum_and_drift` (all samples at once) gives ``p = M v`` and ``b = C^T v - g`` of
    the per-sample Pinocchio route to 1e-12 relative, with armature on every joint and gravity tilted sample by
    sample, on TALOS's stance tree and on a chain of every 1-DoF joint type; in blocks, the same bytes."""
    name, model = _tree_cases(talos)[case]
    rng = np.random.default_rng(41 + case)
    model = pin.Model(model)
    model.armature[:] = rng.uniform(0.0, 0.3, model.nv)
    q, v = _states(model, rng, 50)
    gravity = rng.normal(0.0, 9.81, (50, 3))
    p, b = tree_momentum_and_drift(model, q, v, gravity)
    p_ref, b_ref, _ = momentum_and_drift(model, q, v, gravity=gravity)
    for got, ref in ((p, p_ref), (b, b_ref)):
        relative = np.abs(got - ref).max(axis=1) / np.abs(ref).max(axis=1)
        assert relative.max() < 1e-12, name
    monkeypatch.setattr(momentum, "BLOCK", 16)
    blocked = tree_momentum_and_drift(model, q, v, gravity)
    assert blocked[0].tobytes() == p.tobytes() and blocked[1].tobytes() == b.tobytes()
