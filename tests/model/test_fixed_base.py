"""Robot configuration for real robots: a fixed base, locked joints, torque constants, armature."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.exceptions import InputError
from wbfriction.model import load_robot
from wbfriction.model.loading import example_robot_data_dir
from wbfriction.model.rerooted import stance_model

PANDA = "panda_description/urdf/panda.urdf"
FINGERS = ("panda_finger_joint1", "panda_finger_joint2")


def panda(tmp_path: Path, extra: str = "") -> object:
    cfg = tmp_path / "panda.toml"
    cfg.write_text('name = "panda"\nfloating_base = false\n[locked_joints]\n'
                   + "".join(f"{f} = 0.02\n" for f in FINGERS) + extra)
    return load_robot(urdf=example_robot_data_dir() / PANDA, config=cfg)


def test_fixed_base_is_welded_at_its_root_link(tmp_path):
    robot = panda(tmp_path)
    assert not robot.floating_base
    assert robot.contact_frames == ("panda_link0",)
    assert robot.actuated == tuple(f"panda_joint{i}" for i in range(1, 8))
    assert robot.limb(robot.contact_frames[0]) == ()  # no joint between the weld and the root: none masked
    stance = stance_model(robot, 0)
    assert np.all(stance.sign == 1.0)  # rooted at the root link: the same tree, no joint reversed


def test_locked_joints_leave_the_model_at_their_position(tmp_path):
    robot = panda(tmp_path)
    full = pin.buildModelFromUrdf(str(example_robot_data_dir() / PANDA))
    assert robot.locked_joints == {f: 0.02 for f in FINGERS}
    assert not any(robot.model.existJointName(f) for f in FINGERS)
    # the hand with its fingers at 0.02 m: the same dynamics for the joints that move (a fixed-base
    # Pinocchio model of the whole URDF as the independent route)
    rng = np.random.default_rng(3)
    q_full = pin.neutral(full)
    for f in FINGERS:
        q_full[full.idx_qs[full.getJointId(f)]] = 0.02
    for _ in range(5):
        angles, qd, qdd = rng.uniform(-1, 1, (3, 7))
        q_full[:7], v_full, a_full = angles, np.r_[qd, 0, 0], np.r_[qdd, 0, 0]
        tau_full = pin.rnea(full, full.createData(), q_full, v_full, a_full)[:7]
        v, a = np.zeros(robot.model.nv), np.zeros(robot.model.nv)
        v[robot.act_v_index], a[robot.act_v_index] = qd, qdd
        tau = pin.rnea(robot.model, robot.model.createData(), robot.configuration(angles), v, a)
        assert np.allclose(tau[robot.act_v_index], tau_full, rtol=1e-12, atol=1e-10)


def test_armature_and_torque_constants_are_read(tmp_path):
    robot = panda(tmp_path, "[armature]\npanda_joint4 = 0.1\n[torque_constants]\npanda_joint1 = 12.5\n")
    assert robot.model.armature[robot.act_v_index[3]] == 0.1
    assert robot.model.armature[robot.act_v_index[0]] == 0.0
    assert robot.torque_constants == {"panda_joint1": 12.5}


@pytest.mark.parametrize("extra, message", [
    ('contact_frames = ["panda_link0"]\n', "no meaning with floating_base = false"),
])
def test_fixed_base_refuses_contact_frames(tmp_path, extra, message):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(f'floating_base = false\n{extra}')
    with pytest.raises(InputError, match=message):
        load_robot(urdf=example_robot_data_dir() / "ur_description/urdf/ur5_robot.urdf", config=cfg)


@pytest.mark.parametrize("table, message", [
    ("[locked_joints]\nno_such_joint = 0.0\n", "unknown joint in \\[locked_joints\\] 'no_such_joint'"),
    ("[torque_constants]\npanda_joint1 = 0.0\n",
     re.escape("[torque_constants] panda_joint1: 0 N·m/A is outside (0, 1000]")),
    ("[armature]\npanda_joint1 = -0.1\n", re.escape("[armature] panda_joint1: -0.1 kg·m² is outside [0, 100] kg·m²")),
    ("[armature]\npanda_joint1 = 1e6\n", re.escape("[armature] panda_joint1: 1e+06 kg·m² is outside [0, 100] kg·m²")),
    ("[armature]\npanda_joint1 = \"big\"\n",
     re.escape("[armature] panda_joint1: must be a number in [0, 100] kg·m², got 'big'")),
    ("[encoder_offset]\npanda_joint1 = 100.0\n", re.escape("[encoder_offset] panda_joint1: 100 rad is outside "
                                                           "[-3.14159, 3.14159] rad")),
    ("[locked_joints]\npanda_finger_joint1 = 0.0\n[torque_constants]\npanda_finger_joint1 = 1.0\n",
     "unknown joint in \\[torque_constants\\] 'panda_finger_joint1'"),  # a locked joint is no longer in the model
])
def test_bad_tables_get_one_clear_line(tmp_path, table, message):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(f"floating_base = false\n{table}")
    with pytest.raises(InputError, match=message):
        load_robot(urdf=example_robot_data_dir() / PANDA, config=cfg)


def test_floating_base_must_be_a_boolean(tmp_path):
    cfg = tmp_path / "bad.toml"
    cfg.write_text('floating_base = "no"\n')
    with pytest.raises(InputError, match="'floating_base' must be true or false"):
        load_robot(urdf=example_robot_data_dir() / PANDA, config=cfg)


def test_floating_robots_are_unchanged(talos):
    assert talos.floating_base and talos.contact_frames == ("left_sole_link", "right_sole_link")
    assert talos.locked_joints == {} and talos.torque_constants == {}


@pytest.mark.parametrize("value", ["-0.5", "nan"])
def test_a_link_of_negative_or_no_number_mass_is_refused_naming_it(tmp_path, value):
    """Issue 53: a URDF whose link has a negative mass (a sign typo) estimated as if it were physics; refused at
    load, in one line naming the file and the link."""
    text = (example_robot_data_dir() / PANDA).read_text()
    start = text.index('<link name="panda_link3">')
    at = text.index('<mass value="', start) + len('<mass value="')
    end = text.index('"', at)
    urdf = tmp_path / "panda.urdf"
    urdf.write_text(text[:at] + value + text[end:])
    cfg = tmp_path / "panda.toml"
    cfg.write_text('name = "panda"\nfloating_base = false\n')
    with pytest.raises(InputError, match=re.escape(f"{urdf}: link 'panda_link3' has a mass of {value} kg")):
        load_robot(urdf=urdf, config=cfg)
