"""The Unitree Go2 dataset: the iit-DLSLab's hung Go2 (``wbfriction dataset go2``), read as the Aliengo's is (the
PyTorch zip-pickle without torch, the 60/40 split), its robot the installed example-robot-data's Go2 named by the
TOML (never copied), its peer's PACE identification read as data with its ``dynamic_friction`` (Coulomb) and its own
gains and delay. The numbers asserted are the files' own (the log's gains, the peer's values as its text gives
them), read here without the package's readers where that can be done."""

from __future__ import annotations

import re
import tomllib
import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pyarrow.parquet as pq
import pytest

from helpers import REAL_DATA, needs_data, run_cli_printed
from wbfriction import datasets
from wbfriction.datasets import go2
from wbfriction.datasets.hung_quadruped import read_trajectory
from wbfriction.datasets.pace_peer import read_peer
from wbfriction.exceptions import InputError
from wbfriction.logs.source import read_log
from wbfriction.model import load_robot
from wbfriction.model.loading import example_robot_data_dir
from wbfriction.studies.pd_peer import peer_robot

FOLDER = REAL_DATA / "unitree_go2"
LOG, PEER = FOLDER / go2.LOG_FILE, FOLDER / go2.PEER_FILE
needs_go2 = needs_data("unitree_go2")
SAMPLES = 4779
JOINTS = tuple(f"{leg}_{part}_joint" for leg in ("FL", "FR", "RL", "RR") for part in ("hip", "thigh", "calf"))
INSTALLED = example_robot_data_dir() / "go2_description" / "urdf" / "go2.urdf"


def test_the_files_are_the_labs_at_the_pinned_commit():
    """The log and the peer's file from iit-DLSLab/simple-robot-identification-isaaclab at 5b3aa99; the URDF is no
    file of the dataset (the installed one)."""
    by_path = {f.path: f for f in go2.GO2_FILES}
    assert set(by_path) == {"datasets/go2/traj_0.pt", "robot_model/go2/isaaclab_identified_parameters.py"}
    for f in go2.GO2_FILES:
        assert f.repository == "iit-DLSLab/simple-robot-identification-isaaclab"
        assert f.commit == "5b3aa99460562bc042640c599ed08ed3272131f4"
    assert datasets.dataset("go2") is datasets.DATASETS["go2"] and datasets.DATASETS["go2"].folder == "unitree_go2"
    assert go2.GO2_JOINTS == JOINTS


# ------------------------------------------------------------------------------------------------ the real log
@pytest.fixture(scope="module")
def trajectory():
    if not FOLDER.is_dir():
        pytest.skip(f"no {FOLDER}")
    return read_trajectory(LOG)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    if not FOLDER.is_dir():
        pytest.skip(f"no {FOLDER}")
    files = {f.name: FOLDER / f.name for f in go2.GO2_FILES}
    return go2.Go2Dataset().write(tmp_path_factory.mktemp("go2"), files)


@pytest.fixture(scope="module")
def robot(written):
    return load_robot(config=written.config)


def test_the_real_log_has_its_shape_clock_and_gains(trajectory):
    """4779 samples of 12 joints over 23.9 s (a linspace stored in float32, 5 ms steps within 0.1 %), the
    set-points' velocity zeros, the drivers' gains kp 20 N·m/rad and kd 1.5 N·m·s/rad on every joint."""
    t = trajectory["time"]
    assert t.shape == (SAMPLES,) and t[0] == 0.0 and t[-1] == pytest.approx(23.9, abs=0.01)
    assert np.diff(t) == pytest.approx(0.005, rel=1e-3)
    for key in ("dof_pos", "dof_vel", "des_dof_pos", "des_dof_vel"):
        assert trajectory[key].shape == (SAMPLES, 12)
    assert np.all(trajectory["des_dof_vel"] == 0.0)
    np.testing.assert_array_equal(trajectory["kp"], np.full(12, 20.0))
    np.testing.assert_array_equal(trajectory["kd"], np.full(12, 1.5))


def test_the_angles_are_in_the_installed_urdfs_limits(trajectory):
    """Measured and commanded angles [rad] inside the limits the URDF's text gives each joint (every joint revolute
    with limits: none continuous); that URDF is the file the data's README names (example-robot-data 6.0.0's)."""
    assert INSTALLED.read_bytes() == (FOLDER / "go2.urdf").read_bytes()
    root = ET.parse(INSTALLED).getroot()
    for k, joint in enumerate(JOINTS):
        element = root.find(f"joint[@name='{joint}']")
        assert element.get("type") == "revolute", joint
        low, high = (float(element.find("limit").get(side)) for side in ("lower", "upper"))
        for angles in (trajectory["dof_pos"][:, k], trajectory["des_dof_pos"][:, k]):
            assert np.all((angles >= low) & (angles <= high)), joint


def test_the_set_points_are_triangle_ramps_reversing_together(trajectory):
    """Every joint's set-point steps at the same samples, all reversing together; the half periods shrink from
    1.5 s to 0.2 s by 0.1 s, two of each (the Aliengo's schedule, one pair longer)."""
    q_des, t = trajectory["des_dof_pos"], trajectory["time"]
    moving = np.diff(q_des, axis=0) != 0
    assert np.all(moving.any(axis=1) == moving.all(axis=1))
    direction = np.sign(np.diff(q_des, axis=0)[moving.all(axis=1), 0])
    at = np.flatnonzero(moving.all(axis=1)) + 1
    starts = np.concatenate([[at[0]], at[np.flatnonzero(np.diff(direction)) + 1]])
    halves = np.diff(np.append(t[starts], t[-1]))
    np.testing.assert_allclose(halves, np.repeat(np.arange(15, 1, -1) / 10, 2), atol=0.02)


# ---------------------------------------------------------------------------------------- the logs and the TOML
def test_the_split_is_60_40_with_no_sample_lost_or_repeated(trajectory, written):
    """4779 samples: the first 2867 (60 %, rounded down) to train, the other 1912 held out, as logged."""
    train, held = (pq.read_table(written.logs[r]) for r in ("train", "held_out"))
    assert (train.num_rows, held.num_rows) == (2867, 1912) and written.rows == {"train": 2867, "held_out": 1912}
    for column, key in (("q", "dof_pos"), ("qd", "dof_vel"), ("q_des", "des_dof_pos"), ("qd_des", "des_dof_vel")):
        for k, joint in enumerate(JOINTS):
            both = np.concatenate([train[f"{column}.{joint}"].to_numpy(), held[f"{column}.{joint}"].to_numpy()])
            np.testing.assert_array_equal(both, trajectory[key][:, k])
    np.testing.assert_array_equal(np.concatenate([train["time"].to_numpy(), held["time"].to_numpy()]),
                                  trajectory["time"])


def test_the_configuration_names_the_installed_urdf_and_the_logs_gains(written, robot, trajectory):
    """The TOML names example-robot-data's Go2 (the built-in ``go2``'s file, nothing copied), a fixed base, the log's
    gains and no delay; the robot it loads is the built-in's model (the same masses) with the log's joints, and
    reads the training log's angles as logged."""
    config = tomllib.loads(written.config.read_text())
    builtin = load_robot("go2")
    assert config["urdf"] == "example-robot-data:go2_description/urdf/go2.urdf" == go2.INSTALLED_URDF
    assert robot.urdf == builtin.urdf == INSTALLED
    assert not robot.floating_base and robot.actuated == JOINTS
    assert robot.pd is not None and robot.pd.delay == 0.0
    np.testing.assert_array_equal(robot.pd.kp, np.full(12, 20.0))
    np.testing.assert_array_equal(robot.pd.kd, np.full(12, 1.5))
    assert robot.labels["RR_calf_joint"] == "rear right calf"
    np.testing.assert_array_equal([i.mass for i in robot.model.inertias], [i.mass for i in builtin.model.inertias])
    log = read_log(written.logs["train"], robot)
    for k, joint in enumerate(JOINTS):
        np.testing.assert_array_equal(log.q[:, robot.actuated.index(joint)], trajectory["dof_pos"][:2867, k])


# --------------------------------------------------------------------------------------------------- the peer
def listed(text: str, key: str) -> list[float]:
    """The numbers of the file's line ``key = [...]``, read with a regular expression (not the package's reader)."""
    found = re.search(rf"^{key} = \[(.*)\]$", text, re.M)
    return [float(x) for x in found.group(1).split(",")]


@needs_go2
def test_the_peers_values_are_the_files_numbers():
    """Every list by joint name in the file's ``# Order:`` (the log's), its Coulomb friction the file's
    ``dynamic_friction``; the delay 1 step of 5 ms (applied as 1), the gains 20 and 1.5, as the file says."""
    text = PEER.read_text()
    order = [f"{name.strip()}_joint" for name in re.search(r"^# Order: (.*)$", text, re.M).group(1).split(",")]
    assert tuple(order) == JOINTS
    peer = go2.go2_peer({go2.PEER_FILE: PEER})
    assert peer.friction_key == "dynamic_friction" and "static_friction" not in text
    for values, key in ((peer.armature, "armature"), (peer.viscous_friction, "viscous_friction"),
                        (peer.coulomb_friction, "dynamic_friction"), (peer.bias, "bias")):
        assert values == dict(zip(order, listed(text, key)))
    assert peer.coulomb_friction["RL_calf_joint"] == 0.9999995827674866  # at PACE's bound of 1 N·m
    assert peer.delay_steps == 1.0 and peer.applied_delay_steps == 1
    assert peer.delay == peer.applied_delay == 0.005
    assert (peer.kp, peer.kd) == (20.0, 1.5)
    assert peer.encoder_offset == {j: -b for j, b in peer.bias.items()}


@pytest.mark.parametrize(("keys", "message"), [(("static_friction", "dynamic_friction"),
                                                "found 'static_friction' and 'dynamic_friction'"),
                                               ((), "found neither")])
def test_the_peers_coulomb_friction_has_one_name(tmp_path, keys, message):
    listing = "[" + ", ".join(["0.1"] * 12) + "]"
    body = "".join(f"{key} = {listing}\n" for key in ("armature", "viscous_friction", *keys, "bias"))
    path = tmp_path / "params.py"
    path.write_text(body + "delay = 1.0\nKp = 20.0\nKd = 1.5\n")
    with pytest.raises(InputError, match=message) as info:
        read_peer(path, JOINTS)
    assert str(info.value).startswith(f"{path}: ") and "\n" not in str(info.value)


def test_the_peer_fragment_loads_with_the_robot(written, robot):
    """``peer.toml``'s tables over ``go2.toml``'s: the armature on the mass matrix's diagonal, the encoder offsets
    minus the file's bias, the delay its 1 step of 5 ms holding back the whole torque; its header names its source
    and its friction the file's ``dynamic_friction``."""
    text = PEER.read_text()
    fragment = (written.config.parent / "peer.toml").read_text()
    assert "robot_model/go2/isaaclab_identified_parameters.py" in fragment and "# dynamic (Coulomb) [N·m]:" in fragment
    config = tomllib.loads(written.config.read_text()) | tomllib.loads(fragment)
    with_peer = peer_robot(written.config, written.config.parent / "peer.toml")  # the URDF the TOML names, installed
    assert with_peer.urdf == INSTALLED
    assert with_peer.encoder_offset == {j: -b for j, b in zip(JOINTS, listed(text, "bias"))}
    assert with_peer.pd.delay == 0.005 and with_peer.pd.delayed == "torque"
    assert (config["pd"]["kp"], config["pd"]["kd"]) == (20.0, 1.5)
    q = pin.neutral(robot.model)
    bare, armed = (pin.crba(r.model, r.model.createData(), q) for r in (robot, with_peer))
    for joint, armature in zip(JOINTS, listed(text, "armature")):
        i = robot.model.joints[robot.model.getJointId(joint)].idx_v
        assert armed[i, i] - bare[i, i] == pytest.approx(armature, rel=1e-9)


# ---------------------------------------------------------------------------------------------- the command
@needs_go2
def test_the_command_writes_the_logs_and_prints_the_pd_route(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv(datasets.DATA_ENV, str(REAL_DATA))
    out = tmp_path / "go2"
    code, printed, err = run_cli_printed(capsys, "dataset", "go2", "-o", out)
    assert code == 0, err
    assert {p.name for p in out.iterdir()} == {"train.parquet", "held_out.parquet", "go2.toml", "peer.toml"}
    lines = [line.strip() for line in printed.splitlines() if line.strip().startswith("wbfriction ")]
    assert [line.split()[1] for line in lines] == ["identify", "estimate", "fit", "estimate", "predict", "export",
                                                  "refine"]
    assert f"--config {out / 'go2.toml'} --actuator pd --config-output go2_identified.toml" in lines[0]
    assert all("--route momentum" in lines[i] for i in (1, 3))
    assert "-o go2_isaac.yaml -o go2.xml" in lines[5] and f"--held-out {out / 'held_out.parquet'}" in lines[6]
