"""The URDF with the identified friction: read back by Pinocchio and MuJoCo, the rest of the file kept."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from lxml import etree as ET

from wbfriction.exceptions import InputError
from wbfriction.export.urdf import write_friction_urdf
from wbfriction.friction.models import FrictionParams
from wbfriction.inertia.regressor import body_parameters
from wbfriction.model.robot import Robot


def v_index(model: pin.Model, joint: str) -> int:
    return model.idx_vs[model.getJointId(joint)]


def test_pinocchio_reads_back_friction_and_inertias(kuka, tmp_path, random_friction, identified):
    """Ground truth: Pinocchio's parser gives ``model.damping = F_v`` and ``model.friction = F_c``
    exactly, and the identified bodies (to 1e-9), with and without its free-flyer root."""
    rng = np.random.default_rng(0)
    friction = random_friction(kuka.actuated, rng)
    inertias = identified(kuka.model, rng)
    path = tmp_path / "kuka_identified.urdf"
    write_friction_urdf(kuka, friction, path, armature={"lwr_0_joint": 0.2}, inertias=inertias)
    back = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    assert np.allclose(body_parameters(back), body_parameters(inertias), rtol=1e-9, atol=1e-12)
    fixed = pin.buildModelFromUrdf(str(path))
    for model in (back, fixed):
        for name, p in friction.items():
            assert model.damping[v_index(model, name)] == p.F_v
            assert model.friction[v_index(model, name)] == p.F_c
        assert not np.any(model.armature)  # URDF has no armature field


def test_only_the_exported_joints_change(kuka, kuka_urdf, tmp_path):
    """Without inertias: the inertias, comments and transmissions are the given URDF's; the other actuated joints'
    <dynamics> hold no friction (issue 67: as the MJCF), the joints not actuated keep theirs."""
    friction = {"lwr_2_joint": FrictionParams(F_v=0.125, F_c=2.5)}
    path = tmp_path / "kuka.urdf"
    assert write_friction_urdf(kuka, friction, path) == ()
    given = pin.buildModelFromUrdf(str(kuka_urdf))
    back = pin.buildModelFromUrdf(str(path))
    assert np.array_equal(body_parameters(back), body_parameters(given))
    i = v_index(back, "lwr_2_joint")
    assert (back.damping[i], back.friction[i]) == (0.125, 2.5)
    others = np.arange(back.nv) != i
    assert not np.any(back.damping[others]) and not np.any(back.friction[others])
    assert np.any(given.damping[others]) and np.any(given.friction[others])  # the given URDF had some
    text, original = path.read_text(), Path(kuka_urdf).read_text()
    assert "Transmissions: KUKA LWR4+ uses harmonic drive gears" in text
    assert text.count("<transmission") == original.count("<transmission") == 7
    assert text.count("<dynamics") == original.count("<dynamics")


def test_mujoco_reads_the_written_dynamics(kuka, tmp_path, random_friction):
    """A second reader: MuJoCo's own URDF import maps <dynamics damping friction> to damping and
    frictionloss; read from the written file they are the exported F_v and F_c."""
    friction = random_friction(kuka.actuated, np.random.default_rng(1))
    path = tmp_path / "kuka.urdf"
    write_friction_urdf(kuka, friction, path)
    root = ET.parse(str(path)).getroot()
    for link in root.findall("link"):
        for e in [*link.findall("visual"), *link.findall("collision")]:
            link.remove(e)
    base_joint = root.find("joint[@name='box_lwr_base_joint']")
    base_joint.remove(base_joint.findall("origin")[1])  # the file repeats this origin; MuJoCo refuses that
    ET.SubElement(ET.SubElement(root, "mujoco"), "compiler", discardvisual="true")
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    for name, p in friction.items():
        dof = model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)]
        assert (model.dof_damping[dof], model.dof_frictionloss[dof]) == (p.F_v, p.F_c)


TWO_LINKS = """<?xml version="1.0"?>
<robot name="two">
  <!-- a comment that must stay -->
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <axis xyz="0 0 1"/>
    <limit effort="10" lower="-1" upper="1" velocity="3"/>
  </joint>
  <link name="arm">
    <inertial>
      <origin xyz="0.1 0 0"/><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/>
    </inertial>
  </link>
</robot>
"""


def two_link_robot(folder: Path) -> Robot:
    urdf = folder / "two.urdf"
    urdf.write_text(TWO_LINKS)
    model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    return Robot(name="two", model=model, urdf=urdf, actuated=("hinge",), torque_controlled=("hinge",),
                 position_controlled=(), contact_frames=("base",), floating_base=False)


def test_a_joint_without_dynamics_gets_one(tmp_path):
    robot = two_link_robot(tmp_path)
    path = tmp_path / "out.urdf"
    write_friction_urdf(robot, {"hinge": FrictionParams(F_v=0.3, F_c=0.7)}, path)
    back = pin.buildModelFromUrdf(str(path))
    assert (back.damping[0], back.friction[0]) == (0.3, 0.7)
    lines = path.read_text().splitlines()
    assert '    <dynamics damping="0.3" friction="0.7"/>' in lines  # indented as the joint's other children
    assert lines[lines.index('    <dynamics damping="0.3" friction="0.7"/>') + 1] == "  </joint>"
    assert "<!-- a comment that must stay -->" in path.read_text()


def test_refused_input_writes_nothing(kuka, tmp_path, talos):
    """(d) non-dissipative friction, and inertias of another robot: an InputError, no file."""
    path = tmp_path / "out.urdf"
    with pytest.raises(InputError, match="joint 'lwr_1_joint': F_v = -0.1"):
        write_friction_urdf(kuka, {"lwr_1_joint": FrictionParams(F_v=-0.1, F_c=1.0)}, path)
    with pytest.raises(InputError, match="inertias: the model's joints are not those of robot 'kuka_lwr4'"):
        write_friction_urdf(kuka, {}, path, inertias=talos.model)
    assert list(tmp_path.iterdir()) == []
