"""The walking reference and the controller's feed-forward, each against an independent route."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import constrained_forward
from wbfriction.sim.control import feedforward, foot_shares
from wbfriction.walking import GaitOptions, walking_reference
from wbfriction.walking.com import GRAVITY, lipm_com, zmp_reference
from wbfriction.walking.footsteps import plan_footsteps
from wbfriction.walking.swing import foot_placement

DT = 1e-3


@pytest.fixture(scope="module")
def turn(talos):
    """Two turning steps: single and double support, yaw, lift, every task moving."""
    return walking_reference(talos, GaitOptions(gait="turning", steps=2))


@given(x=st.floats(-1, 1), y=st.floats(-1, 1), height=st.floats(0.5, 1.2))
@settings(max_examples=20, deadline=None)
def test_lipm_at_rest_over_a_constant_zmp(x, y, height):
    c, cd, cdd = lipm_com(np.tile([x, y], (500, 1)), DT, height)
    assert np.allclose(c, [x, y], atol=1e-9) and np.allclose(cd, 0, atol=1e-5) and np.allclose(cdd, 0, atol=1e-4)


def test_lipm_tracks_the_zmp_of_a_walk():
    """p = c - c_dd / w^2 (Kajita's cart-table model) holds away from the ends, where the
    pendulum must start and stop; the CoM starts and ends at rest."""
    feet0 = np.array([[0.0, 0.1, 0.0], [0.0, -0.1, 0.0]])
    plan = plan_footsteps(feet0, GaitOptions(gait="forward", steps=6))
    time = np.arange(int(plan.duration / DT) + 1) * DT
    zmp = zmp_reference(plan, time)
    height = 0.8
    c, cd, cdd = lipm_com(zmp, DT, height)
    p = c - cdd * height / GRAVITY
    inner = (time > 1.0) & (time < time[-1] - 1.0)
    assert np.abs(p - zmp)[inner].max() < 1e-3
    assert np.abs(cd[[0, -1]]).max() < 1e-3
    # the CoM moves between the feet: it never leaves the support polygon's hull in y
    assert np.abs(c[:, 1]).max() < 0.1


def test_reference_puts_the_feet_and_com_on_plan(talos, turn):
    model, data = talos.model, talos.model.createData()
    for k in range(0, len(turn), 97):
        pin.framesForwardKinematics(model, data, turn.q[k])
        for c, f in enumerate(talos.contact_frame_ids):
            target = foot_placement(turn.feet[k, c])
            assert np.abs(pin.log6(target.actInv(data.oMf[f])).vector).max() < 1e-9
        assert np.allclose(pin.centerOfMass(model, data, turn.q[k]), turn.com[k], atol=1e-9)


def test_reference_velocity_and_acceleration_are_the_time_derivatives_of_q(talos, turn):
    """v and a, from the IK's differential relations, agree with central differences of q
    and v: to O(dt^2) everywhere but at the few samples where the jerk jumps (the ZMP
    reference's corners, mid-swing), where a central difference is O(dt) off."""
    model = talos.model
    k = np.arange(1, len(turn) - 1)
    v_fd = np.array([pin.difference(model, turn.q[i - 1], turn.q[i + 1]) for i in k]) / (2 * DT)
    a_fd = (turn.v[k + 1] - turn.v[k - 1]) / (2 * DT)
    err_v = np.abs(v_fd - turn.v[k]).max(axis=1)
    err_a = np.abs(a_fd - turn.a[k]).max(axis=1)
    assert err_v.max() < 1e-4 and np.percentile(err_a, 99) < 2e-3 and err_a.max() < 0.2


def test_stance_soles_are_at_rest_in_the_reference(talos, turn):
    model, data = talos.model, talos.model.createData()
    for k in range(0, len(turn), 53):
        pin.forwardKinematics(model, data, turn.q[k], turn.v[k], turn.a[k])
        pin.updateFramePlacements(model, data)
        for c, f in enumerate(talos.contact_frame_ids):
            if turn.contact[k, c]:
                assert np.abs(pin.getFrameVelocity(model, data, f, pin.LOCAL).vector).max() < 1e-9
                assert np.abs(pin.getFrameClassicalAcceleration(model, data, f, pin.LOCAL).vector).max() < 1e-7


def test_feedforward_reproduces_the_reference_through_constrained_dynamics(talos, turn):
    """The feed-forward torques, applied to the robot with its soles welded where they are,
    give back the reference acceleration and the wrenches it planned (single and double
    support: the constrained dynamics have one solution, so the sharing must be exact)."""
    rows = np.r_[0:len(turn):211]
    rows = np.union1d(rows, np.flatnonzero(turn.contact.sum(1) == 1)[::300])
    tau, wrench = feedforward(talos, turn.q[rows], turn.v[rows], turn.a[rows], turn.contact[rows],
                              foot_shares(turn.zmp[rows], turn.feet[rows, :, :2]))
    assert turn.contact[rows].sum(1).min() == 1 and turn.contact[rows].sum(1).max() == 2
    for i, k in enumerate(rows):
        tau_full = np.zeros(talos.model.nv)
        tau_full[talos.act_v_index] = tau[i]
        active = list(np.flatnonzero(turn.contact[k]))
        a, lam = constrained_forward(talos, turn.q[k], turn.v[k], tau_full, active, with_wrench=True)
        assert np.abs(a - turn.a[k]).max() < 1e-6, k
        assert np.abs(lam - wrench[i, active].ravel()).max() < 1e-5 * (1 + np.abs(lam).max()), k
