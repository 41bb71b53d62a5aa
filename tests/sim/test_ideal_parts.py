"""Parts of the ideal simulator's per-sample loop, each against the route it replaces."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from wbfriction.sim.ideal import contact_constraints, unstack_wrenches
from wbfriction.walking import standing_configuration
from wbfriction.walking.indexing import as_slice
from wbfriction.walking.reference import yaw_rotations
from wbfriction.walking.swing import foot_placement


def test_baumgarte_term_is_minus_the_contact_acceleration_error(talos):
    """The loop reads the Baumgarte term ``Kp e_p + Kd e_v`` of each welded sole from
    Pinocchio's ``contact_acceleration_error``: bit for bit its negative, off the anchors and
    moving, single and double support; the constraints held in Pinocchio's vectors give the
    acceleration a Python list gives."""
    model = talos.model
    rng = np.random.default_rng(3)
    q = standing_configuration(talos)
    q[7:] += rng.normal(0, 0.01, model.nq - 7)
    v = rng.normal(0, 0.1, model.nv)
    tau = np.r_[np.zeros(6), rng.normal(0, 5, model.nv - 6)]
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    anchors = {c: foot_placement(np.array([*data.oMf[f].translation[:2] + 0.001, 0.0, 0.01]))
               for c, f in enumerate(talos.contact_frame_ids)}
    settings = pin.ProximalSettings(1e-12, 1e-10, 50)
    for active in ([True, True], [False, True]):
        models, datas = contact_constraints(talos, data, np.array(active), anchors, (400.0, 40.0))
        a = pin.constraintDynamics(model, data, q, v, tau, models, datas, settings).copy()
        for cd in datas:
            term = 400.0 * cd.contact_placement_error.vector + 40.0 * cd.contact_velocity_error.vector
            assert np.abs(term).max() > 1e-3
            assert np.array_equal(-cd.contact_acceleration_error.np, term)
        as_list = ([models[i] for i in range(len(models))], [m.createData() for m in models])
        pin.initConstraintDynamics(model, data, *as_list)
        assert np.array_equal(pin.constraintDynamics(model, data, q, v, tau, *as_list, settings), a)


def test_wrenches_unstack_to_their_feet():
    contact = np.array([[True, True], [False, True], [True, False], [True, True]])
    stacked = np.arange(4 * 12, dtype=float).reshape(4, 12)
    wrench = np.zeros((4, 2, 6))
    unstack_wrenches(stacked, contact, wrench)
    for k in range(4):  # the per-sample assignment it replaces
        expected = np.zeros((2, 6))
        expected[contact[k]] = stacked[k, :6 * contact[k].sum()].reshape(-1, 6)
        assert np.array_equal(wrench[k], expected)


def test_yaw_rotations_are_the_foot_placements_rotations():
    yaw = np.linspace(-4.0, 4.0, 101)
    R = yaw_rotations(yaw)
    assert all(np.array_equal(R[k], foot_placement(np.array([0.0, 0.0, 0.0, y])).rotation) for k, y in enumerate(yaw))


def test_as_slice_only_for_runs():
    x = np.arange(20.0)
    for index in ([3, 4, 5], [7], [2, 4], [5, 4], []):
        s = as_slice(index)
        assert isinstance(s, slice) == (len(index) > 0 and index == list(range(index[0], index[0] + len(index))))
        assert np.array_equal(x[s], x[np.asarray(index, dtype=int)])
