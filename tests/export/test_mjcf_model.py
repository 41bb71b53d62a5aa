"""Issue 67, item 5: the exported MJCF is the robot's whole model, loadable and steppable in MuJoCo as it is: the
collision geometry (a floor under a floating base), actuators as the robot is driven (motors; position actuators
with the PD gains), the keyframe ``stance``; over 2 s TALOS and the Go2 stand on the floor and the Panda follows
designed set-points. The friction read back from the compiled file is the exported one."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from wbfriction.export.mjcf import write_mjcf
from wbfriction.friction.models import FrictionParams
from wbfriction.model import load_robot


def export(name: str, tmp_path, friction=None):
    robot = load_robot(name)
    path = tmp_path / f"{name}.xml"
    write_mjcf(robot, friction or {}, path)
    model = mujoco.MjModel.from_xml_path(str(path))  # the file as it is
    return robot, model


def actuated(model: mujoco.MjModel):
    """Each actuator's joint's qpos and dof addresses."""
    joint = model.actuator_trnid[:, 0]
    return model.jnt_qposadr[joint], model.jnt_dofadr[joint]


def at_stance(model: mujoco.MjModel) -> mujoco.MjData:
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "stance"))
    for a in range(model.nu):  # a delayed driver's history holds the first set-point
        if model.actuator_history[a, 0]:
            mujoco.mj_initCtrlHistory(model, data, a, None,
                                      np.full((int(model.actuator_history[a, 0]), 1), data.ctrl[a]))
    mujoco.mj_forward(model, data)
    return data


def standing_torques(model: mujoco.MjModel, data: mujoco.MjData, feet, rotation: bool) -> np.ndarray:
    """The joint torques (nv,) that hold the robot still on its feet: gravity, the contact forces at the ``feet``
    sites (forces, and moments for soles) the least-norm ones that carry the base."""
    jac = []
    for foot in feet:
        jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        mujoco.mj_jacSite(model, data, jp, jr, model.site(foot).id)
        jac += [jp, jr] if rotation else [jp]
    J = np.vstack(jac)
    f = np.linalg.lstsq(J[:, :6].T, data.qfrc_bias[:6], rcond=None)[0]
    return data.qfrc_bias - J.T @ f


def test_whole_models_load_with_geometry_actuators_and_a_floor(tmp_path):
    """Each robot's file has the URDF's collision geometry (meshes by absolute path, no self-collision) and one
    actuator per actuated joint, named as it; a floating base has a free joint and a floor it stands on at its
    ``stance`` keyframe (lowest geometry at z = 0, both feet in contact), a fixed base none."""
    for name, n_act, floating, biastype in [("talos", 32, True, mujoco.mjtBias.mjBIAS_NONE),
                                              ("go2_walking", 12, True, mujoco.mjtBias.mjBIAS_AFFINE),
                                              ("go2", 12, False, mujoco.mjtBias.mjBIAS_AFFINE),
                                              ("panda", 7, False, mujoco.mjtBias.mjBIAS_NONE)]:
        robot, model = export(name, tmp_path)
        mesh = model.geom_type == mujoco.mjtGeom.mjGEOM_MESH
        assert model.ngeom > 10 and mesh.sum() > 5 and model.nmesh > 5, name
        assert model.nu == robot.n_act == n_act, name
        assert [model.actuator(a).name for a in range(model.nu)] == [model.joint(j).name
                                                                      for j in model.actuator_trnid[:, 0]]
        assert sorted(model.actuator(a).name for a in range(model.nu)) == sorted(robot.actuated)
        assert np.all(model.actuator_biastype == biastype), name
        robot_geoms = model.geom_bodyid != 0
        assert np.all(model.geom_conaffinity[robot_geoms] == 0) and np.all(model.geom_contype[robot_geoms] == 1)
        floors = np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
        assert len(floors) == int(floating) and (model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE) == floating
        data = at_stance(model)
        qpos, _ = actuated(model)
        names = [model.joint(j).name for j in model.actuator_trnid[:, 0]]
        lo, hi = robot.angle_limits
        want = dict(zip(robot.actuated, np.clip(robot.reference_angles, lo, hi)))
        assert np.allclose(data.qpos[qpos], [want[n] for n in names], atol=1e-12)
        if floating:
            geoms = np.flatnonzero(robot_geoms)
            gaps = np.array([mujoco.mj_geomDistance(model, data, floors[0], g, 10.0, None) for g in geoms])
            assert abs(gaps.min()) < 1e-6, name  # the lowest geometry on the floor
            assert len(set(model.geom_bodyid[geoms[gaps < 1e-3]])) >= 2, name  # both soles, or the feet


def test_talos_stands_on_its_motors(tmp_path):
    """TALOS, torque-controlled: the file's motors with the torques that carry its weight on both soles plus a joint
    PD hold the stance for 2 s at 2 ms steps: the base stays within 1 cm of its height, the joints within 0.02
    rad; the exported friction is on the joints."""
    friction = {n: FrictionParams(F_v=0.5, F_c=1.0) for n in load_robot("talos").actuated}
    _, model = export("talos", tmp_path, friction)
    data = at_stance(model)
    qpos, dof = actuated(model)
    q0, z0 = data.qpos[qpos].copy(), data.qpos[2]
    tau0 = standing_torques(model, data, ["left_sole_link", "right_sole_link"], rotation=True)[dof]
    legs = np.array([model.actuator(a).name.startswith(("leg_", "torso_")) for a in range(model.nu)])
    inertia = model.dof_M0[dof]
    kp, kd = np.where(legs, 1000.0, 400 * inertia), np.where(legs, 20.0, 40 * inertia)
    heights = []
    while data.time < 2.0:
        data.ctrl[:] = tau0 + kp * (q0 - data.qpos[qpos]) - kd * data.qvel[dof]
        mujoco.mj_step(model, data)
        heights.append(data.qpos[2])
    assert np.max(np.abs(np.array(heights) - z0)) < 0.01
    assert np.max(np.abs(data.qpos[qpos] - q0)) < 0.02 and np.all(np.abs(data.qpos[:2]) < 0.02)


def test_go2_stands_on_its_pd_drivers(tmp_path):
    """The walking Go2, PD-driven (kp 30, kd 1): its position actuators, sent the stance set-points offset by the
    torques that carry its weight on the four feet (the set-point offset tau / kp that applies them), hold the
    stance for 2 s: the base within 1 cm of its height."""
    _, model = export("go2_walking", tmp_path)
    data = at_stance(model)
    qpos, dof = actuated(model)
    z0, kp = data.qpos[2], model.actuator_gainprm[:, 0]
    tau0 = standing_torques(model, data, ["FL_foot", "FR_foot", "RL_foot", "RR_foot"], rotation=False)[dof]
    data.ctrl[:] = data.ctrl + tau0 / kp
    heights = []
    while data.time < 2.0:
        mujoco.mj_step(model, data)
        heights.append(data.qpos[2])
    assert np.max(np.abs(np.array(heights) - z0)) < 0.01


def test_panda_follows_set_points_with_its_friction(tmp_path):
    """The Panda, torque-controlled: its motors under computed torque (MuJoCo's own mass matrix and bias of the
    file) and the exported friction as feed-forward follow a designed motion of every joint (0.3 rad, 0.5 Hz) for 2
    s within 5 mrad; without the friction feed-forward the error is larger (the friction acts). The compiled
    file's damping, frictionloss and armature are the exported ones."""
    robot = load_robot("panda")
    rng = np.random.default_rng(2)
    friction = {n: FrictionParams(F_v=rng.uniform(0.5, 2.0), F_c=rng.uniform(1.0, 3.0)) for n in robot.actuated}
    _, model = export("panda", tmp_path, friction)
    names = [model.actuator(a).name for a in range(model.nu)]
    qpos, dof = actuated(model)
    assert np.array_equal(model.dof_damping[dof], [friction[n].F_v for n in names])
    assert np.array_equal(model.dof_frictionloss[dof], [friction[n].F_c for n in names])
    assert np.array_equal(model.dof_armature[dof], robot.model.armature[[robot.act_v_index[robot.actuated.index(n)]
                                                                          for n in names]])
    F_v, F_c = model.dof_damping[dof], model.dof_frictionloss[dof]

    def run(compensate: bool) -> float:
        data = at_stance(model)
        lo, hi = model.jnt_range[model.actuator_trnid[:, 0]].T
        q0, worst = (lo + hi) / 2, 0.0  # mid-range: the motion stays inside the joints' limits
        data.qpos[qpos], data.qvel[dof] = q0, 0.3 * np.pi  # on the motion from its start
        mass = np.zeros((model.nv, model.nv))
        while data.time < 2.0:
            w = 2 * np.pi * 0.5 * data.time
            q_d, qd_d, qdd_d = q0 + 0.3 * np.sin(w), 0.3 * np.pi * np.cos(w), -0.3 * np.pi ** 2 * np.sin(w)
            mujoco.mj_fullM(model, data, mass)
            acc = qdd_d + 400 * (q_d - data.qpos[qpos]) + 40 * (qd_d - data.qvel[dof])
            tau = mass[np.ix_(dof, dof)] @ acc + data.qfrc_bias[dof]
            data.ctrl[:] = tau + (F_v * qd_d + F_c * np.tanh(qd_d / 1e-2) if compensate else 0.0)
            mujoco.mj_step(model, data)
            worst = max(worst, float(np.max(np.abs(data.qpos[qpos] - q_d))))
        return worst

    with_friction = run(True)
    assert with_friction < 5e-3
    assert run(False) > 2 * with_friction


@pytest.mark.parametrize("name", ["talos", "panda"])
def test_joints_not_exported_hold_no_friction_in_both_files(tmp_path, name):
    """A joint whose friction is not exported holds none in the .urdf and the .xml alike (the URDF's own
    <dynamics> set to 0, where TALOS's say 1.0 N·m); the exported joint holds the fit's."""
    import pinocchio as pin

    from wbfriction.export.urdf import write_friction_urdf

    robot = load_robot(name)
    first = robot.actuated[0]
    friction = {first: FrictionParams(F_v=0.25, F_c=1.5)}
    write_mjcf(robot, friction, tmp_path / "r.xml")
    write_friction_urdf(robot, friction, tmp_path / "r.urdf")
    mj = mujoco.MjModel.from_xml_path(str(tmp_path / "r.xml"))
    source = pin.buildModelFromUrdf(str(robot.urdf))  # a second reader of the given URDF
    written = pin.buildModelFromUrdf(str(tmp_path / "r.urdf"))
    for joint in robot.actuated:
        dof = mj.jnt_dofadr[mj.joint(joint).id]
        v_out = written.idx_vs[written.getJointId(joint)]
        want = (0.25, 1.5) if joint == first else (0.0, 0.0)
        assert (mj.dof_damping[dof], mj.dof_frictionloss[dof]) == want, joint
        assert (written.damping[v_out], written.friction[v_out]) == want, joint
    assert np.any(source.damping[[source.idx_vs[source.getJointId(j)] for j in robot.actuated[1:]]])


def test_a_mesh_not_found_is_left_out_with_a_warning(kuka, tmp_path):
    """The real KUKA LWR4+'s URDF names a wrist mesh its folder does not hold: the file is written without it, the
    other geometry kept, and the warning names the link in one line within 100 columns."""
    from wbfriction.export.mjcf import MjcfTarget

    path = tmp_path / "kuka_friction.xml"
    report = MjcfTarget().write(path, kuka, {})
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.ngeom > 10 and model.nu == 7
    assert report.warnings == ("kuka_friction.xml: left out 1 collision mesh(es) MuJoCo cannot load: lwr_6_link",)
    assert len("warning: " + report.warnings[0]) <= 100
