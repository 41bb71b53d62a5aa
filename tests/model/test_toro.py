"""The TORO-like built-in robot (issue 6): thesis ch. 4 numbers, both simulators."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.model.robots.toro import toro_urdf, toro_urdf_path
from wbfriction.sim import simulate_ideal, simulate_mujoco
from wbfriction.sim.mujoco_model import build_mujoco_robot
from wbfriction.studies.common import leg_joints
from wbfriction.walking import GaitOptions, walking_reference

# Thesis Table 4.1, typed from the thesis: joint -> (max velocity [deg/s], max torque [N·m],
# range [deg]); hip roll and knee ranges as read (robots/toro.py docstring)
TABLE_4_1 = {
    "hip_roll": (110, 176, -45, 90), "hip_pitch": (157, 100, -115, 90), "hip_yaw": (157, 100, -120, 120),
    "knee": (176, 130, -105, 105), "ankle_roll": (120, 40, -19.5, 19.5), "ankle_pitch": (176, 130, -45, 45),
    "waist": (157, 100, -120, 120), "shoulder_1": (157, 100, -120, 120), "shoulder_2": (157, 100, -15, 180),
    "shoulder_3": (120, 40, -105, 105), "elbow": (120, 40, 0, 148), "wrist_1": (120, 40, -145, 118),
    "wrist_2": (120, 40, -105, 105), "neck_yaw": (270, 8.4, -90, 90), "neck_pitch": (270, 8.4, -30, 90),
}


def test_joints_are_table_4_1(toro):
    """25 torque-controlled revolute joints (6 per limb and the waist), 2 position-controlled
    neck joints (eq. 5.3), each with Table 4.1's limits."""
    assert len(toro.torque_controlled) == 25 and toro.position_controlled == ("neck_yaw", "neck_pitch")
    model = toro.model
    seen = set()
    for name in toro.actuated:
        kind = name.removeprefix("right_").removeprefix("left_")
        velocity, torque, lower, upper = TABLE_4_1[kind]
        jid = model.getJointId(name)
        iq, iv = model.joints[jid].idx_q, model.joints[jid].idx_v
        assert model.joints[jid].shortname().startswith("JointModelR")  # revolute
        assert model.velocityLimit[iv] == pytest.approx(np.radians(velocity), rel=1e-8)
        assert model.effortLimit[iv] == pytest.approx(torque, rel=1e-8)
        assert model.lowerPositionLimit[iq] == pytest.approx(np.radians(lower), rel=1e-8)
        assert model.upperPositionLimit[iq] == pytest.approx(np.radians(upper), rel=1e-8)
        seen.add(kind)
    assert seen == set(TABLE_4_1)
    # thesis numbering of the leg joints: 1-6 right leg A-F, 7-12 left leg
    legs = leg_joints(toro)
    assert [j for j, _, _ in legs] == [f"{side}_{k}" for side in ("right", "left") for k in
                                       ("hip_roll", "hip_pitch", "hip_yaw", "knee", "ankle_roll", "ankle_pitch")]


def test_leg_chain_order_is_a_to_f(toro):
    """From the pelvis to the foot: hip roll, hip pitch, hip yaw, knee, ankle roll, ankle pitch."""
    for side, frame in (("right", "right_sole"), ("left", "left_sole")):
        assert toro.limb(frame) == tuple(f"{side}_{k}" for k in
                                         ("hip_roll", "hip_pitch", "hip_yaw", "knee", "ankle_roll", "ankle_pitch"))


def test_mass_and_height_are_the_thesis(toro):
    """79.2 kg and 1.74 m (thesis 4.1): the height measured on the URDF's collision boxes,
    standing straight, from the lowest sole corner to the top of the head."""
    assert pin.computeTotalMass(toro.model) == pytest.approx(79.2, abs=1e-9)
    geom = pin.buildGeomFromUrdf(toro.model, str(toro.urdf), pin.GeometryType.COLLISION)
    data, gdata = toro.model.createData(), pin.GeometryData(geom)
    pin.updateGeometryPlacements(toro.model, data, geom, gdata, pin.neutral(toro.model))
    z = []
    for obj, placement in zip(geom.geometryObjects, gdata.oMg):
        half = obj.geometry.halfSide
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
        z.extend((corners @ placement.rotation.T + placement.translation)[:, 2])
    assert max(z) - min(z) == pytest.approx(1.74, abs=1e-9)


def test_urdf_is_generated_reproducibly():
    """The same text every time, cached under a name that depends on it."""
    assert toro_urdf() == toro_urdf()
    path = toro_urdf_path()
    assert path.read_text() == toro_urdf() and path == toro_urdf_path()
    assert "TORO-like" in toro_urdf()


@pytest.mark.parametrize("simulator", ["ideal", "mujoco"])
def test_toro_walks_ten_steps(toro, simulator):
    """Ten forward steps of 0.3 m in both simulators: no fall, every step taken."""
    ref = walking_reference(toro, GaitOptions(gait="forward", steps=10))
    if simulator == "ideal":
        res = simulate_ideal(toro, ref)
    else:
        res = simulate_mujoco(toro, ref, mjr=build_mujoco_robot(toro))
        # the measured contacts show the plan's 10 single supports (of 0.8 s; brief flickers
        # of a landing foot's contact aside)
        single = np.r_[False, res.log.contact.sum(axis=1) == 1, False].astype(int)
        starts, ends = np.flatnonzero(np.diff(single) == 1), np.flatnonzero(np.diff(single) == -1)
        assert np.sum((ends - starts) * ref.dt > 0.5) == 10
    np.testing.assert_allclose(res.q[-1, 0] - res.q[0, 0], ref.q[-1, 0] - ref.q[0, 0], atol=0.05)
    assert res.q[-1, 2] == pytest.approx(ref.q[-1, 2], abs=0.03)
    assert np.abs(res.q[:, 7:] - ref.q[:, 7:]).max() < 0.1
