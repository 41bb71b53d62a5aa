"""The MuJoCo model with the identified friction: mj_inverse against Pinocchio's rnea plus the
exported terms, the friction loss as documented, fixed and floating bases, the written file."""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from wbfriction.exceptions import InputError, ModelError
from wbfriction.export.mjcf import compile_spec, mujoco_model, write_mjcf
from wbfriction.friction.models import FrictionParams
from wbfriction.model import load_robot

B_DEFAULT = 2.0 / (0.95 * 0.02)
"""The friction rows' reference damping with MuJoCo's default solref (0.02, 1) and solimp[1] = 0.95 [1/s]."""


def dofs(model: mujoco.MjModel, joints) -> np.ndarray:
    return np.array([model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)] for n in joints])


def qpos_index(model: mujoco.MjModel, joints) -> np.ndarray:
    return np.array([model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)] for n in joints])


def inverse(model: mujoco.MjModel, joints, q, qd, qdd):
    """mj_inverse at joint angles/velocities/accelerations given in ``joints`` order (fixed base):
    qfrc_inverse and the friction-loss constraint force per joint, in that order."""
    data = mujoco.MjData(model)
    d = dofs(model, joints)
    data.qpos[qpos_index(model, joints)], data.qvel[d], data.qacc[d] = q, qd, qdd
    mujoco.mj_inverse(model, data)
    f_loss = np.zeros(model.nv)
    rows = data.efc_type == mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF
    assert np.all(data.efc_type[~rows] != mujoco.mjtConstraint.mjCNSTR_CONTACT_PYRAMIDAL)  # no contact
    np.add.at(f_loss, data.efc_id[rows], data.efc_force[rows])
    return data.qfrc_inverse[d], f_loss[d]


def random_state(robot, rng):
    lo, hi = robot.angle_limits
    q = rng.uniform(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo))  # inside the limits: no limit constraint
    return q, rng.normal(0, 1.0, robot.n_act), rng.normal(0, 3.0, robot.n_act)


def test_mj_inverse_is_rnea_plus_armature_damping_and_friction_loss(kuka, kuka_urdf, random_friction):
    """(a) Ground truth on the fixed-base LWR4+: qfrc_inverse = rnea (Pinocchio's own URDF parse,
    no armature) + armature qdd + F_v qd - f_loss, and f_loss is the documented closed form
    clip(-(qdd + b qd) / R, +-F_c) with b = 2 / (0.95 * 0.02), R = (1 - 0.9) / 0.9 * dof_invweight0."""
    rng = np.random.default_rng(3)
    friction = random_friction(kuka.actuated, rng)
    armature = {n: rng.uniform(0.01, 0.5) for n in kuka.actuated}
    mj = mujoco_model(kuka, friction, armature)
    assert mj.nq == mj.nv == 7 and np.all(mj.jnt_type == mujoco.mjtJoint.mjJNT_HINGE)  # welded base: no free joint
    pm = pin.buildModelFromUrdf(str(kuka_urdf))
    assert list(pm.names[1:]) == list(kuka.actuated)
    F_v, F_c = (np.array([getattr(friction[n], k) for n in kuka.actuated]) for k in ("F_v", "F_c"))
    arm = np.array([armature[n] for n in kuka.actuated])
    R = (1 - 0.9) / 0.9 * mj.dof_invweight0[dofs(mj, kuka.actuated)]
    inside = 0
    for _ in range(30):
        q, qd, qdd = random_state(kuka, rng)
        qd[:2] *= 1e-3  # some joints near rest: inside the friction loss's linear band
        tau, f_loss = inverse(mj, kuka.actuated, q, qd, qdd)
        expected = pin.rnea(pm, pm.createData(), q, qd, qdd) + arm * qdd + F_v * qd
        assert np.allclose(tau, expected - f_loss, rtol=1e-12, atol=1e-11)
        assert np.allclose(f_loss, np.clip(-(qdd + B_DEFAULT * qd) / R, -F_c, F_c), rtol=1e-12, atol=1e-12)
        inside += int(np.sum(np.abs(f_loss) < F_c * (1 - 1e-9)))
    assert inside > 0  # both branches of the clip were seen


def test_friction_loss_in_mj_inverse_as_documented(kuka):
    """Coulomb F_c sgn(qd) in steady motion; nothing at rest; and a sign that follows qdd + b qd,
    i.e. reverses before the velocity does (slowing down at 0.02 rad/s with qdd = -10 rad/s^2)."""
    F_c = 0.3  # F_c R < 7.9 on every joint: the cases below lie outside the linear band
    mj0 = mujoco_model(kuka, {})
    mj = mujoco_model(kuka, {n: FrictionParams(F_v=0.0, F_c=F_c) for n in kuka.actuated})
    q = kuka.reference_angles + 0.2
    n = kuka.n_act

    def friction_term(qd, qdd):
        return inverse(mj, kuka.actuated, q, qd, qdd)[0] - inverse(mj0, kuka.actuated, q, qd, qdd)[0]

    assert np.allclose(friction_term(np.full(n, 0.5), np.zeros(n)), F_c, rtol=1e-12)
    assert np.allclose(friction_term(np.full(n, -0.5), np.zeros(n)), -F_c, rtol=1e-12)
    assert np.array_equal(friction_term(np.zeros(n), np.zeros(n)), np.zeros(n))
    assert np.allclose(friction_term(np.full(n, 0.02), np.full(n, -10.0)), -F_c, rtol=1e-12)


def test_without_friction_nothing_of_the_urdf_dynamics_is_kept(kuka):
    """The URDF's own <dynamics> (simulator values, not measurements) are not carried over."""
    mj = mujoco_model(kuka, {})
    assert not np.any(mj.dof_damping) and not np.any(mj.dof_frictionloss) and not np.any(mj.dof_armature)


def test_identified_inertias(kuka, random_friction, identified):
    """With a pin.Model of identified inertias: mj_inverse = that model's rnea (base welded) + the friction terms."""
    rng = np.random.default_rng(4)
    inertias = identified(kuka.model, rng)
    friction = random_friction(kuka.actuated[:3], rng)
    mj = mujoco_model(kuka, friction, inertias=inertias)
    F_v = np.array([friction[n].F_v if n in friction else 0.0 for n in kuka.actuated])
    for _ in range(5):
        q, qd, qdd = random_state(kuka, rng)
        tau, f_loss = inverse(mj, kuka.actuated, q, qd, qdd)
        v, a = np.concatenate([np.zeros(6), qd]), np.concatenate([np.zeros(6), qdd])
        rnea = pin.rnea(inertias, inertias.createData(), kuka.configuration(q), v, a)[6:]
        assert np.allclose(tau, rnea + F_v * qd - f_loss, rtol=1e-9, atol=1e-9)


def test_locked_joints_are_welded_where_the_robot_locks_them(make_kuka):
    robot = make_kuka({"lwr_3_joint": 0.7, "lwr_5_joint": -0.4})
    mj = mujoco_model(robot, {})
    assert mj.nv == 5
    rng = np.random.default_rng(5)
    for _ in range(5):
        q, qd, qdd = random_state(robot, rng)
        tau, _ = inverse(mj, robot.actuated, q, qd, qdd)
        v, a = np.concatenate([np.zeros(6), qd]), np.concatenate([np.zeros(6), qdd])
        expected = pin.rnea(robot.model, robot.model.createData(), robot.configuration(q), v, a)[6:]
        assert np.allclose(tau, expected, rtol=1e-10, atol=1e-10)


def test_floating_base(talos, random_friction):
    """TALOS gets a free joint: with the base at the identity orientation and no linear base
    velocity (where MuJoCo's world-frame and Pinocchio's base-frame base velocities agree), every
    row of mj_inverse is rnea (armature included) + F_v qd - f_loss."""
    rng = np.random.default_rng(6)
    friction = random_friction(talos.actuated[:12], rng)
    armature = {n: rng.uniform(0.01, 0.3) for n in talos.actuated[6:20]}
    mj = mujoco_model(talos, friction, armature)
    assert mj.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE and mj.nv == talos.model.nv
    model = pin.Model(talos.model)
    for name, value in armature.items():
        model.armature[model.idx_vs[model.getJointId(name)]] = value
    q_act, qd, qdd = random_state(talos, rng)
    q = talos.configuration(q_act)
    q[:3] = rng.normal(size=3)
    q[2] = 3.0 + abs(q[2])  # high above the floor: no contact
    v, a = rng.normal(size=model.nv), rng.normal(size=model.nv)
    v[:3] = 0.0
    v[talos.act_v_index], a[talos.act_v_index] = qd, qdd
    data = mujoco.MjData(mj)
    d = dofs(mj, talos.actuated)
    data.qpos[:7] = [*q[:3], 1.0, 0.0, 0.0, 0.0]
    data.qpos[qpos_index(mj, talos.actuated)] = q_act
    data.qvel[:6], data.qacc[:6] = v[:6], a[:6]
    data.qvel[d], data.qacc[d] = qd, qdd
    mujoco.mj_inverse(mj, data)
    expected = np.zeros(mj.nv)
    tau = pin.rnea(model, model.createData(), q, v, a)
    expected[:6], expected[d] = tau[:6], tau[talos.act_v_index]
    f_loss = np.zeros(mj.nv)
    np.add.at(f_loss, data.efc_id, data.efc_force)
    assert np.all(data.efc_type == mujoco.mjtConstraint.mjCNSTR_FRICTION_DOF) and data.nefc == len(friction)
    expected[dofs(mj, friction)] += [p.F_v * data.qvel[i] for p, i in zip(friction.values(), dofs(mj, friction))]
    assert np.allclose(data.qfrc_inverse, expected - f_loss, rtol=1e-10, atol=1e-10)


def test_written_mjcf_reloads_to_the_same_model(kuka, tmp_path, random_friction, identified):
    """The file's numbers are full precision: reloaded, every body, joint and dof array is the
    compiled model's, and mj_inverse agrees to rounding."""
    rng = np.random.default_rng(7)
    friction = random_friction(kuka.actuated, rng)
    armature = {n: rng.uniform(0.01, 0.5) / 3 for n in kuka.actuated}
    path = tmp_path / "kuka.xml"
    compiled = write_mjcf(kuka, friction, path, armature, inertias=identified(kuka.model, rng))
    back = mujoco.MjModel.from_xml_path(str(path))
    for name in ("body_pos", "body_quat", "body_ipos", "body_iquat", "body_mass", "body_inertia", "jnt_axis",
                 "jnt_pos", "jnt_range", "dof_damping", "dof_frictionloss", "dof_armature", "dof_invweight0"):
        assert np.allclose(getattr(back, name), getattr(compiled, name), rtol=1e-15, atol=1e-15), name
    for _ in range(3):
        q, qd, qdd = random_state(kuka, rng)
        a, b = inverse(compiled, kuka.actuated, q, qd, qdd), inverse(back, kuka.actuated, q, qd, qdd)
        assert np.allclose(a, b, rtol=1e-12, atol=1e-12)


def test_panda_with_its_mimic_finger_locked(tmp_path, random_friction):
    """Issue 37: the Panda's URDF couples panda_finger_joint2 to panda_finger_joint1 (<mimic>, an equality
    constraint in MuJoCo's import) and the robot locks both fingers: the constraint goes with the welded
    joint. The file reloads in MuJoCo with the 7 arm joints, no constraint, the exported damping and
    frictionloss, the robot's armature, and mj_inverse = the robot model's rnea (armature included) + F_v qd
    - f_loss."""
    panda = load_robot("panda")
    rng = np.random.default_rng(9)
    friction = random_friction(panda.actuated, rng)
    path = tmp_path / "panda.xml"
    write_mjcf(panda, friction, path)
    mj = mujoco.MjModel.from_xml_path(str(path))
    assert mj.neq == 0 and mj.nv == panda.n_act == 7
    d = dofs(mj, panda.actuated)
    assert np.array_equal(mj.dof_damping[d], [friction[n].F_v for n in panda.actuated])
    assert np.array_equal(mj.dof_frictionloss[d], [friction[n].F_c for n in panda.actuated])
    assert np.array_equal(mj.dof_armature[d], panda.model.armature[panda.act_v_index])
    for _ in range(3):
        q, qd, qdd = random_state(panda, rng)
        tau, f_loss = inverse(mj, panda.actuated, q, qd, qdd)
        v, a = np.zeros(panda.model.nv), np.zeros(panda.model.nv)
        v[panda.act_v_index], a[panda.act_v_index] = qd, qdd
        rnea = pin.rnea(panda.model, panda.model.createData(), panda.configuration(q), v, a)[panda.act_v_index]
        F_v = np.array([friction[n].F_v for n in panda.actuated])
        assert np.allclose(tau, rnea + F_v * qd - f_loss, rtol=1e-9, atol=1e-9)


def test_what_refers_to_a_locked_joint_goes_with_it(tmp_path):
    """A robot from an MJCF whose locked joint is coupled (joint equality), driven (motor) and read (sensor):
    those go with the welded joint, the ones on the other gripper stay."""
    path = tmp_path / "talos.xml"
    write_mjcf(load_robot("talos"), {}, path)
    extra = ('<equality><joint joint1="gripper_right_joint" joint2="gripper_left_joint"/></equality>'
             '<actuator><motor joint="gripper_left_joint"/><motor joint="gripper_right_joint"/></actuator>'
             '<sensor><jointpos joint="gripper_left_joint"/><jointvel joint="gripper_right_joint"/></sensor>')
    path.write_text(path.read_text().replace("</mujoco>", extra + "</mujoco>"))
    config = tmp_path / "locked.toml"
    config.write_text('name = "talos_locked"\ncontact_frames = ["left_sole_link", "right_sole_link"]\n'
                      "[locked_joints]\ngripper_left_joint = 0.0\n")
    robot = load_robot(mjcf=path, config=config)
    mj = mujoco_model(robot, {})
    assert (mj.neq, mj.nu, mj.nsensor) == (0, 31 + 1, 1)  # the export's motors on the 31 joints left, the extra one
    driven = [mj.joint(mj.actuator_trnid[a, 0]).name for a in range(mj.nu)]
    assert driven.count("gripper_right_joint") == 2 and "gripper_left_joint" not in driven
    assert mj.joint(mj.sensor_objid[0]).name == "gripper_right_joint"
    assert mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, "gripper_left_joint") == -1


def test_mujoco_errors_are_one_line():
    """MuJoCo's compiler adds a line ("Element name '', id 0"): the error is one line."""
    spec = mujoco.MjSpec.from_string("<mujoco><worldbody><body><joint name='a'/><geom size='.1'/></body></worldbody>"
                                     "<equality><joint joint1='a' joint2='gone'/></equality></mujoco>")
    with pytest.raises(ModelError) as err:
        compile_spec(spec, "x.xml")
    assert str(err.value).startswith("x.xml: MuJoCo cannot compile the model: Error: unknown element 'gone'")
    assert "\n" not in str(err.value) and "Element name '', id 0" in str(err.value)


def test_refused_input(kuka, tmp_path):
    """(d) non-dissipative friction is refused before anything is built or written."""
    with pytest.raises(InputError, match="joint 'lwr_4_joint': F_c = -0.5 N·m < 0"):
        mujoco_model(kuka, {"lwr_4_joint": FrictionParams(F_v=0.1, F_c=-0.5)})
    with pytest.raises(InputError, match="joint 'lwr_4_joint': F_v = -0.1"):
        write_mjcf(kuka, {"lwr_4_joint": FrictionParams(F_v=-0.1, F_c=0.5)}, tmp_path / "x.xml")
    with pytest.raises(InputError, match="output directory"):
        write_mjcf(kuka, {}, tmp_path / "missing" / "x.xml")
    assert list(tmp_path.iterdir()) == []
