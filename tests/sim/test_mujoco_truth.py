"""The MuJoCo simulator's logged true friction is the generalised force that moved the robot.

With the robot in the air (the walking reference lifted 1 m: no contact), each logged sample's friction
must equal ``M qacc + c - actuator force`` on its joint, with ``M`` from ``mujoco.mj_fullM`` and ``c`` =
``qfrc_bias`` at the logged state, ``qacc`` the logged joint accelerations (the free joint's from its own
rows, which no force but gravity and inertia acts on), the actuator force the motors' torque. Joints held by
a limit constraint at a sample (the grippers) are left out there. The motors' torques are the truth
(``tau_motor``): the logged ``tau`` is what a torque sensor read of them
(:func:`~wbfriction.sim.mujoco_sim.matched_weights`).
"""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

from wbfriction.sim import MujocoOptions, simulate_mujoco
from wbfriction.sim.mujoco_model import build_mujoco_robot
from wbfriction.walking import GaitOptions, walking_reference

SAMPLES = 150


@pytest.fixture(scope="module")
def in_the_air(talos):
    """The MuJoCo robot and the first 150 ms of a walking reference lifted by 1 m."""
    mjr = build_mujoco_robot(talos)
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=1, initial=0.2, final=0.2))
    cut = {f: getattr(ref, f)[:SAMPLES] for f in ("time", "v", "a", "contact", "feet", "com", "zmp")}
    q = ref.q[:SAMPLES].copy()
    q[:, 2] += 1.0
    return mjr, dataclasses.replace(ref, q=q, **cut)


def friction_from_the_dynamics(talos, mjr, res) -> tuple[np.ndarray, np.ndarray]:
    """``(M qacc + c - actuator force)`` on the torque-controlled joints at every logged sample (N, n_tc)
    [N·m], and where no limit constraint acts on the joint (N, n_tc)."""
    m = mjr.model
    d = mujoco.MjData(m)
    M = np.zeros((m.nv, m.nv))
    dofs = mjr.dof_index[talos.tc_index]
    joints = np.setdiff1d(np.arange(m.nv), np.arange(6))
    log = res.log
    out, free = np.empty((len(log.time), len(dofs))), np.ones((len(log.time), len(dofs)), dtype=bool)
    for k in range(len(log.time)):
        d.qpos[:] = mjr.qpos(res.q[k])
        d.qvel[:] = mjr.velocity_map(res.q[k]) @ res.v[k]
        mujoco.mj_forward(m, d)
        assert d.ncon == 0  # in the air
        mujoco.mj_fullM(m, d, M)
        qacc = np.zeros(m.nv)
        qacc[mjr.dof_index] = log.qdd_true[k]
        qacc[:6] = np.linalg.solve(M[:6, :6], -d.qfrc_bias[:6] - M[:6, joints] @ qacc[joints])
        out[k] = (M @ qacc + d.qfrc_bias)[dofs] - res.tau_motor[k]
        limited = d.efc_id[:d.nefc][d.efc_type[:d.nefc] == mujoco.mjtConstraint.mjCNSTR_LIMIT_JOINT]
        free[k] = ~np.isin(dofs, m.jnt_dofadr[limited])
    return out, free


def _check(talos, res, tau_f, free, tol: float) -> None:
    log = res.log
    assert not log.contact.any()
    injected = [talos.torque_controlled.index(j) for j in log.metadata["friction_true"]]
    assert len(injected) == 12 and free[:, injected].all()  # every leg joint checked at every sample
    assert np.abs(log.tau_f_true[:, injected]).max() > 0.5  # friction there to be checked
    err = np.abs(tau_f - log.tau_f_true)[free]
    assert err.max() < tol, f"logged truth off the dynamics by {err.max():.3g} N·m"


def test_model_friction_logged_is_the_friction_applied(talos, in_the_air):
    """Friction (3.5) applied by the simulator as a generalised force: logged exactly."""
    mjr, ref = in_the_air
    res = simulate_mujoco(talos, ref, None, MujocoOptions(friction="model"), mjr=mjr)
    tau_f, free = friction_from_the_dynamics(talos, mjr, res)
    _check(talos, res, tau_f, free, 1e-9)


def test_model_friction_is_eq_3_5_of_each_joints_own_velocity(talos, in_the_air):
    """The friction applied (and logged) at a sample is (3.5) of that joint's parameters at its velocity at
    the sample's physics step (the logged true velocity), ``tau_f = -f(qd)``, written out here:
    ``f = F_v qd + F_c (1 + S exp(-|qd / v_s|^delta_s)) tanh(a qd) + tau_os``; zero on the other joints."""
    mjr, ref = in_the_air
    log = simulate_mujoco(talos, ref, None, MujocoOptions(friction="model"), mjr=mjr).log
    qd = log.qd_true[:, talos.tc_index]
    expected = np.zeros_like(log.tau_f_true)
    for joint, p in log.metadata["friction_true"].items():
        i = talos.torque_controlled.index(joint)
        v = qd[:, i]
        f = (p["F_v"] * v + p["F_c"] * (1 + p["S"] * np.exp(-np.abs(v / p["v_s"]) ** p["delta_s"]))
             * np.tanh(p["a"] * v) + p["tau_os"])
        expected[:, i] = -f
    assert len(set(np.round(expected.std(axis=0), 6))) > 6  # distinct curves per joint
    np.testing.assert_allclose(log.tau_f_true, expected, rtol=0, atol=1e-12)


def test_mujoco_friction_logged_is_the_friction_applied(talos, in_the_air):
    """MuJoCo's own frictionloss and damping: the logged constraint and damper forces close the equation of
    motion to MuJoCo's solver tolerance (measured: 1.1e-3 N·m at ``opt.tolerance = 1e-8``, 1e-13 at 1e-12),
    far below a 5 % scale or a 0.05 N·m offset of the friction (0.04-0.05 N·m here)."""
    mjr, ref = in_the_air
    res = simulate_mujoco(talos, ref, None, MujocoOptions(friction="mujoco"), mjr=mjr)
    tau_f, free = friction_from_the_dynamics(talos, mjr, res)
    _check(talos, res, tau_f, free, 5e-3)


@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="MuJoCo's Newton solver stops at opt.tolerance = 1e-8: the logged frictionloss force "
                          "differs from M qacc + c - actuator by up to 1.1e-3 N·m")
def test_mujoco_friction_logged_is_the_friction_applied_exactly(talos, in_the_air):
    mjr, ref = in_the_air
    res = simulate_mujoco(talos, ref, None, MujocoOptions(friction="mujoco"), mjr=mjr)
    tau_f, free = friction_from_the_dynamics(talos, mjr, res)
    _check(talos, res, tau_f, free, 1e-9)
