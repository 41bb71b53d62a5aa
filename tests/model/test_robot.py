"""The robot model and its stance-rooted versions."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.exceptions import InputError
from wbfriction.model.loading import build_robot, load_robot
from wbfriction.model.stance import stance_model


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


@pytest.mark.parametrize("robot_name", ["talos", "talos_tilted_sole"])
def test_stance_wrench_is_the_contact_wrench_in_the_contact_frame(robot_name, request):
    """Root rows of the stance RNEA = the wrench of pin.constraintDynamics (LOCAL), and the
    joint rows its joint torques, for a random base pose and a random state with J v = 0."""
    from conftest import constrained_forward, random_state

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


def test_a_built_in_robot_on_another_urdf(talos, tmp_path):
    """``--robot talos --urdf FILE``: TALOS's configuration on another URDF of it (as an
    identified model is written); a URDF of another robot is refused by name."""
    other = load_robot("talos", urdf=talos.urdf)
    assert other.actuated == talos.actuated and other.torque_controlled == talos.torque_controlled
    assert other.contact_frames == talos.contact_frames and other.groups == talos.groups
    (tmp_path / "small.urdf").write_text("<robot name='x'><link name='a'/></robot>")
    with pytest.raises(InputError, match="unknown"):
        load_robot("talos", urdf=tmp_path / "small.urdf")
    with pytest.raises(InputError, match="--config needs the robot's --urdf"):
        load_robot("talos", config=tmp_path / "c.toml")
