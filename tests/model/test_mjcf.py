"""Robots from MJCF: TALOS written as MJCF by the project's exporter and read back through Pinocchio's MJCF
parser has the URDF model's joints in the same order, frames, mass matrix and nonlinear terms."""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.exceptions import InputError
from wbfriction.export.mjcf import write_mjcf
from wbfriction.model.loading import load_robot
from wbfriction.pipeline.export_step import export_files


@pytest.fixture(scope="module")
def talos_mjcf(tmp_path_factory):
    """TALOS's MJCF (the exporter, no friction), written at test time (never committed)."""
    path = tmp_path_factory.mktemp("mjcf") / "talos.xml"
    write_mjcf(load_robot("talos"), {}, path)
    return path


def random_configuration(model: pin.Model, rng: np.random.Generator) -> np.ndarray:
    q = pin.neutral(model)
    q[:3] = rng.normal(size=3)
    quat = rng.normal(size=4)
    q[3:7] = quat / np.linalg.norm(quat)
    q[7:] = rng.uniform(model.lowerPositionLimit[7:], model.upperPositionLimit[7:])
    return q


def symmetric(m: np.ndarray) -> np.ndarray:
    return np.triu(m) + np.triu(m, 1).T


def test_mjcf_model_equals_urdf_model(talos, talos_mjcf):
    mj = load_robot("talos", mjcf=talos_mjcf)
    assert mj.model_format == "mjcf" and talos.model_format == "urdf"
    assert list(mj.model.names) == list(talos.model.names)  # same joints, same order, root named root_joint
    assert mj.actuated == talos.actuated and mj.torque_controlled == talos.torque_controlled
    assert mj.model.joints[1].shortname() == "JointModelFreeFlyer"
    links = {f.name for f in talos.model.frames if f.type == pin.FrameType.BODY}
    assert links <= {f.name for f in mj.model.frames}  # fused links (soles, imu_link) kept as sites
    np.testing.assert_array_equal(mj.q_reference, talos.q_reference)
    a, b = talos.model, mj.model
    da, db = a.createData(), b.createData()
    rng = np.random.default_rng(24)
    worst = {"M": 0.0, "g": 0.0, "h": 0.0, "frames": 0.0}
    for _ in range(6):
        q, v = random_configuration(a, rng), rng.normal(size=a.nv)
        ma, mb = symmetric(pin.crba(a, da, q)), symmetric(pin.crba(b, db, q))
        worst["M"] = max(worst["M"], np.linalg.norm(ma - mb) / np.linalg.norm(ma))
        ga, gb = pin.computeGeneralizedGravity(a, da, q), pin.computeGeneralizedGravity(b, db, q)
        worst["g"] = max(worst["g"], np.linalg.norm(ga - gb) / np.linalg.norm(ga))
        ha, hb = pin.rnea(a, da, q, v, np.zeros(a.nv)), pin.rnea(b, db, q, v, np.zeros(b.nv))
        worst["h"] = max(worst["h"], np.linalg.norm(ha - hb) / np.linalg.norm(ha))
        pin.framesForwardKinematics(a, da, q)
        pin.framesForwardKinematics(b, db, q)
        for frame in (*talos.contact_frames, "imu_link", "leg_left_6_link"):
            d = da.oMf[a.getFrameId(frame)].inverse() * db.oMf[b.getFrameId(frame)]
            worst["frames"] = max(worst["frames"], float(np.linalg.norm(pin.log6(d).vector)))
    assert max(worst.values()) < 1e-9, worst


def test_mjcf_from_the_robot_toml_and_options(talos, talos_mjcf, tmp_path):
    cfg = tmp_path / "robot.toml"
    cfg.write_text(f'name = "mine"\nmjcf = "{talos_mjcf}"\ncontact_frames = ["left_sole_link", "right_sole_link"]\n'
                   '[armature]\nleg_left_4_joint = 0.25\n')
    robot = load_robot(config=cfg)
    assert robot.model_format == "mjcf" and robot.urdf == talos_mjcf
    assert robot.model.armature[robot.model.idx_vs[robot.model.getJointId("leg_left_4_joint")]] == 0.25
    with pytest.raises(InputError, match="--urdf or its --mjcf, not both"):
        load_robot("talos", urdf=talos.urdf, mjcf=talos_mjcf)
    cfg.write_text(f'mjcf = "{talos_mjcf}"\nurdf = "{talos.urdf}"\ncontact_frames = ["left_sole_link"]\n')
    with pytest.raises(InputError, match="names both 'urdf' and 'mjcf'"):
        load_robot(config=cfg)
    with pytest.raises(InputError, match="MJCF file not found"):
        load_robot("talos", mjcf=tmp_path / "missing.xml")
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body name='b'><joint name='j' type='hinge'/>"
                   "<inertial pos='0 0 0' mass='1' diaginertia='1 1 1'/></body></worldbody></mujoco>")
    with pytest.raises(InputError, match="bad.xml: MJCF does not load|root joint 'j' is not free"):
        load_robot("talos", mjcf=bad)


def test_mjcf_armature_is_read(talos_mjcf, tmp_path):
    """An MJCF's joint armature is the model's (Pinocchio reads it; crba includes it)."""
    text = re.sub(r'(<joint name="leg_left_4_joint"[^>]*?)armature="0\.0"', r'\1armature="0.5"',
                  talos_mjcf.read_text())
    path = tmp_path / "armature.xml"
    path.write_text(text)
    robot = load_robot("talos", mjcf=path)
    assert robot.model.armature[robot.model.idx_vs[robot.model.getJointId("leg_left_4_joint")]] == 0.5


def test_what_needs_a_urdf_says_so(talos_mjcf, tmp_path):
    robot = load_robot("talos", mjcf=talos_mjcf)
    params = tmp_path / "p.json"
    params.write_text("{}")
    with pytest.raises(InputError, match="a .urdf export .* needs the robot's URDF"):
        export_files(robot, params, [tmp_path / "x.xml", tmp_path / "x.urdf"])
    assert not (tmp_path / "x.xml").exists()  # refused before anything is written
