"""The robot model and its stance-rooted versions."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.estimate import stance_model
from wbfriction.exceptions import InputError
from wbfriction.robot import build_robot


def test_talos_builtin(talos):
    assert talos.n_act == 32 and len(talos.torque_controlled) == 30
    assert talos.position_controlled == ("head_1_joint", "head_2_joint")
    assert talos.contact_frames == ("left_sole_link", "right_sole_link")
    assert talos.limb("right_sole_link") == tuple(f"leg_right_{i}_joint" for i in range(1, 7))
    assert abs(sum(i.mass for i in talos.model.inertias) - 90.272192) < 1e-6


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


def test_config_errors(talos):
    with pytest.raises(InputError, match="both torque- and position-controlled"):
        build_robot(talos.urdf, {"contact_frames": ["left_sole_link"], "position_controlled": ["head_1_joint"],
                                 "torque_controlled": ["head_1_joint"]})
    with pytest.raises(InputError, match="unknown contact frame 'foot'"):
        build_robot(talos.urdf, {"contact_frames": ["foot"]})
    with pytest.raises(InputError, match="'contact_frames' is missing"):
        build_robot(talos.urdf, {})


def test_angles_invert_configuration(talos):
    rng = np.random.default_rng(0)
    angles = rng.uniform(*talos.angle_limits, size=(5, talos.n_act))
    np.testing.assert_array_equal(talos.angles(talos.configuration(angles)), angles)
    assert talos.reference_angles[talos.actuated.index("leg_left_4_joint")] > 0.8  # half-sitting knee
