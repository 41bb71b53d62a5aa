"""The Unitree Aliengo dataset (issue 55): the PyTorch zip-pickle read without torch (a restricted unpickler), the
log split 60/40 as recorded, the robot's TOML with its PD drivers and continuous thighs, the peer's identification
read as data (``ast.literal_eval``, never executed) with its sign and delay conventions."""

from __future__ import annotations

import io
import pickle
import sys
import tomllib
import types
import xml.etree.ElementTree as ET
import zipfile
from collections import OrderedDict

import numpy as np
import pinocchio as pin
import pyarrow.parquet as pq
import pytest

from helpers import REAL_DATA, needs_data, run_cli_printed
from wbfriction import datasets
from wbfriction.datasets import aliengo
from wbfriction.exceptions import InputError
from wbfriction.logs.source import read_log
from wbfriction.model import load_robot
from wbfriction.model.loading import build_robot

FOLDER = REAL_DATA / "unitree_aliengo"
LOG = FOLDER / aliengo.LOG_FILE
needs_aliengo = needs_data("unitree_aliengo")
SAMPLES = 4700


# ------------------------------------------------------------------------------ a zip-pickle built without torch
class _Storage:
    """A storage as torch pickles it: by a persistent id naming its type, key and size."""

    def __init__(self, kind: type, key: str, values: np.ndarray) -> None:
        self.kind, self.key, self.values = kind, key, values


class _Tensor:
    def __init__(self, storage: _Storage, offset: int, size: tuple, stride: tuple) -> None:
        self.args = (storage, offset, size, stride, False, OrderedDict())

    def __reduce__(self):
        return sys.modules["torch._utils"]._rebuild_tensor_v2, self.args


class _Pickler(pickle.Pickler):
    def persistent_id(self, obj):
        if isinstance(obj, _Storage):
            return "storage", obj.kind, obj.key, "cpu", obj.values.size
        return None


@pytest.fixture
def fake_torch(monkeypatch):
    """Modules ``torch`` and ``torch._utils`` holding the names a .pt pickles (so pickle writes those globals);
    their functions are never called: the reader must not import them."""
    torch = types.ModuleType("torch")
    utils = types.ModuleType("torch._utils")

    def _rebuild_tensor_v2(*args):
        raise AssertionError("the reader called torch")

    utils._rebuild_tensor_v2 = _rebuild_tensor_v2
    _rebuild_tensor_v2.__module__, _rebuild_tensor_v2.__qualname__ = "torch._utils", "_rebuild_tensor_v2"
    for name in ("FloatStorage", "DoubleStorage", "LongStorage"):
        setattr(torch, name, type(name, (), {"__module__": "torch"}))
    torch._utils = utils
    monkeypatch.setitem(sys.modules, "torch", torch)
    monkeypatch.setitem(sys.modules, "torch._utils", utils)
    return torch


def write_pt(path, doc: dict, storages: list[_Storage], order: str = "little", root: str = "traj_0") -> None:
    """``doc`` as ``torch.save`` lays it out: ``<root>/data.pkl`` (protocol 2), ``<root>/byteorder``, each storage's
    raw elements in ``<root>/data/<key>``."""
    buffer = io.BytesIO()
    _Pickler(buffer, protocol=2).dump(doc)
    code = "<" if order == "little" else ">"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr(f"{root}/data.pkl", buffer.getvalue())
        archive.writestr(f"{root}/byteorder", order)
        for s in storages:
            archive.writestr(f"{root}/data/{s.key}", s.values.astype(s.values.dtype.newbyteorder(code)).tobytes())


@pytest.mark.parametrize("order", ["little", "big"])
def test_the_reader_honours_views_offsets_types_and_byte_order(tmp_path, fake_torch, order):
    """Tensors that are views (an offset, a transposed stride, a shared storage), of three types, and NumPy arrays
    pickled by NumPy itself, read back as NumPy computes the same views."""
    rng = np.random.default_rng(55)
    flat = rng.normal(size=30)
    doubles = _Storage(fake_torch.DoubleStorage, "0", flat)
    floats = _Storage(fake_torch.FloatStorage, "1", rng.normal(size=8).astype(np.float32))
    longs = _Storage(fake_torch.LongStorage, "2", np.arange(-3, 9, dtype=np.int64))
    gains = np.array([[25.0, 0.5, -1.25]])
    doc = {"block": _Tensor(doubles, 2, (4, 3), (3, 1)),       # rows 2.. of the storage, row-major
           "transposed": _Tensor(doubles, 0, (3, 5), (1, 3)),  # the first 15 values, column-major
           "floats": _Tensor(floats, 1, (3,), (2,)),           # every other value from the second
           "longs": _Tensor(longs, 0, (12,), (1,)), "gains": gains}
    path = tmp_path / "traj.pt"
    write_pt(path, doc, [doubles, floats, longs], order)
    out = datasets.read_pt(path)
    assert set(out) == set(doc)
    np.testing.assert_array_equal(out["block"], flat[2:14].reshape(4, 3))
    np.testing.assert_array_equal(out["transposed"], flat[:15].reshape(5, 3).T)
    np.testing.assert_array_equal(out["floats"], floats.values[1:7:2])
    assert out["floats"].dtype == np.float32 and out["longs"].dtype == np.int64
    np.testing.assert_array_equal(out["longs"], np.arange(-3, 9))
    np.testing.assert_array_equal(out["gains"], gains)


def refused(path) -> str:
    with pytest.raises(InputError) as info:
        datasets.read_pt(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    return message


class _Call:
    """An object whose unpickling would call ``os.getcwd``: a global the reader must refuse."""

    def __reduce__(self):
        import os
        return os.getcwd, ()


def test_the_reader_refuses_other_globals_and_views_beyond_their_storage(tmp_path, fake_torch):
    path = tmp_path / "call.pt"
    write_pt(path, {"time": _Call()}, [])
    assert "names posix.getcwd" in refused(path) or "names os.getcwd" in refused(path)
    values = _Storage(fake_torch.DoubleStorage, "0", np.arange(6.0))
    path = tmp_path / "beyond.pt"
    write_pt(path, {"time": _Tensor(values, 2, (2, 3), (3, 1))}, [values])  # reaches element 7 of 6
    assert "beyond its storage of 6 elements" in refused(path)
    path = tmp_path / "missing.pt"
    write_pt(path, {"time": _Tensor(values, 0, (6,), (1,))}, [])  # no data/0 in the archive
    assert "KeyError" in refused(path)
    path = tmp_path / "list.pt"
    write_pt(path, [1.0], [])
    assert "a PyTorch zip-pickle of a list" in refused(path)


@needs_aliengo
@pytest.mark.parametrize("damage", ["truncated", "pickle byte", "storage byte"])
def test_a_damaged_log_is_refused_naming_it(tmp_path, damage):
    data = bytearray(LOG.read_bytes())
    if damage == "truncated":
        data = data[: len(data) // 2]
    else:  # a byte of the pickle or of a storage: the archive's CRC no longer matches
        with zipfile.ZipFile(LOG) as archive:
            entry = archive.getinfo("traj_0/data.pkl" if damage == "pickle byte" else "traj_0/data/1")
        data[entry.header_offset + 30 + len(entry.filename) + len(entry.extra) + 100] ^= 0x01
    path = tmp_path / "traj_0.pt"
    path.write_bytes(bytes(data))
    message = refused(path)
    assert "not a readable PyTorch zip-pickle" in message
    assert "BadZipFile" in message


# ------------------------------------------------------------------------------------------------ the real log
@pytest.fixture(scope="module")
def trajectory():
    if not FOLDER.is_dir():
        pytest.skip(f"no {FOLDER}")
    return aliengo.read_trajectory(LOG)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    if not FOLDER.is_dir():
        pytest.skip(f"no {FOLDER}")
    files = {f.name: FOLDER / f.name for f in aliengo.ALIENGO_FILES}
    return aliengo.AliengoDataset().write(tmp_path_factory.mktemp("aliengo"), files)


@pytest.fixture(scope="module")
def robot(written):
    return load_robot(config=written.config)


def test_the_real_log_has_its_shape_and_clock(trajectory):
    """4700 samples of 12 joints, 23.5 s: a linspace stored in float32, steps of 23.5/4699 s (5 ms within 0.03 %)."""
    t = trajectory["time"]
    assert t.shape == (SAMPLES,) and t[0] == 0.0 and t[-1] == pytest.approx(23.5, abs=1e-6)
    assert np.diff(t) == pytest.approx(0.005, rel=5e-4)
    for key in ("dof_pos", "dof_vel", "des_dof_pos", "des_dof_vel"):
        assert trajectory[key].shape == (SAMPLES, 12)
    assert np.all(trajectory["des_dof_vel"] == 0.0)
    np.testing.assert_array_equal(trajectory["kp"], np.full(12, 25.0))
    np.testing.assert_array_equal(trajectory["kd"], np.full(12, 0.5))


def test_the_angles_are_in_the_urdf_limits(trajectory, robot):
    """Measured and commanded angles [rad] inside the URDF's limits (hips ±1.22, calves -2.78..-0.65); the
    continuous thighs (no limit) within their half turn."""
    for k, joint in enumerate(aliengo.ALIENGO_JOINTS):
        angles = trajectory["dof_pos"][:, k], trajectory["des_dof_pos"][:, k]
        jid = robot.model.getJointId(joint)
        if joint.endswith("_thigh_joint"):
            assert robot.model.joints[jid].nq == 2  # continuous: (cos, sin)
            assert all(np.all(np.abs(a) < np.pi / 2) for a in angles)
            continue
        i = robot.model.joints[jid].idx_q
        low, high = robot.model.lowerPositionLimit[i], robot.model.upperPositionLimit[i]
        assert high - low > 1.0 and all(np.all((a >= low) & (a <= high)) for a in angles), joint


def test_the_drivers_velocity_is_the_derivative_of_its_angle_to_its_noise(trajectory):
    """Two routes to the joint's motion: the driver's velocity integrated over 0.1 s windows (trapezoid) against
    the angle's change over the same windows (no differentiation). Hips and thighs agree in scale within 1.5 %;
    the calves' driver velocity is 6.8-8.2 % larger than their angle's rate (measured; PACE fits on the angle
    alone). Scale aside, what remains is what the driver velocity's own sample noise predicts: sigma (0.09-0.17
    rad/s, from its second difference, sigma^2 = var/6 for white noise) x sqrt(20) x T = 2-4 mrad per window; the
    residual is 0.8-1.5 times that."""
    t, q, v = trajectory["time"], trajectory["dof_pos"], trajectory["dof_vel"]
    step = float(np.median(np.diff(t)))
    window = 20
    integral = np.concatenate([np.zeros((1, 12)), np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t)[:, None], axis=0)])
    edges = np.arange(0, len(t), window)
    moved, change = np.diff(integral[edges], axis=0), np.diff(q[edges], axis=0)
    scale = (moved * change).sum(0) / (change * change).sum(0)
    calf = np.array([j.endswith("_calf_joint") for j in aliengo.ALIENGO_JOINTS])
    assert np.all(np.abs(scale[~calf] - 1.0) < 0.015), scale
    assert np.all((scale[calf] > 1.06) & (scale[calf] < 1.09)), scale
    residual = np.sqrt(np.mean((moved - scale * change) ** 2, axis=0))
    d2 = v[2:] - 2 * v[1:-1] + v[:-2]
    sigma = 1.4826 * np.median(np.abs(d2), axis=0) / np.sqrt(6)
    ratio = residual / (sigma * np.sqrt(window) * step)
    assert np.all((ratio > 0.5) & (ratio < 2.0)), ratio


def test_the_set_points_are_triangle_ramps_reversing_together(trajectory):
    """Every joint's set-point is a staircase (49 steps a half ramp) between two fixed angles, all joints reversing
    at the same samples; the half periods shrink from 1.5 s to 0.3 s, two of each."""
    q_des, t = trajectory["des_dof_pos"], trajectory["time"]
    steps = np.diff(q_des, axis=0)
    moving = steps != 0
    assert np.all(moving.any(axis=1) == moving.all(axis=1))  # all joints step at the same samples
    direction = np.sign(steps[moving.all(axis=1), 0])
    at = np.flatnonzero(moving.all(axis=1)) + 1
    starts = np.concatenate([[at[0]], at[np.flatnonzero(np.diff(direction)) + 1]])
    halves = np.diff(np.append(t[starts], t[-1]))  # the last half ramp ends with the log
    expected = np.repeat(np.arange(15, 2, -1) / 10, 2)
    np.testing.assert_allclose(halves, expected, atol=0.02)
    assert len(at) == 49 * len(expected)


# ---------------------------------------------------------------------------------------- the logs and the TOML
def test_the_split_is_60_40_with_no_sample_lost_or_repeated(trajectory, written):
    train, held = (pq.read_table(written.logs[r]) for r in ("train", "held_out"))
    assert (train.num_rows, held.num_rows) == (2820, 1880) and written.rows == {"train": 2820, "held_out": 1880}
    for column, key in (("q", "dof_pos"), ("qd", "dof_vel"), ("q_des", "des_dof_pos"), ("qd_des", "des_dof_vel")):
        for k, joint in enumerate(aliengo.ALIENGO_JOINTS):
            both = np.concatenate([train[f"{column}.{joint}"].to_numpy(), held[f"{column}.{joint}"].to_numpy()])
            np.testing.assert_array_equal(both, trajectory[key][:, k])
    np.testing.assert_array_equal(np.concatenate([train["time"].to_numpy(), held["time"].to_numpy()]),
                                  trajectory["time"])
    assert set(train.column_names) == {"time"} | {f"{c}.{j}" for c in ("q", "qd", "q_des", "qd_des")
                                                  for j in aliengo.ALIENGO_JOINTS}


def urdf_inertia_about_y(urdf, link: str, at: np.ndarray) -> float:
    """A link's inertia about the y axis through ``at`` (its frame) [kg·m²], from the URDF's numbers (parallel
    axes)."""
    inertial = ET.parse(urdf).getroot().find(f"link[@name='{link}']/inertial")
    mass = float(inertial.find("mass").get("value"))
    origin = inertial.find("origin")
    com = np.array([float(x) for x in origin.get("xyz").split()]) if origin is not None else np.zeros(3)
    d = com - at
    return float(inertial.find("inertia").get("iyy")) + mass * (d[0] ** 2 + d[2] ** 2)


def test_the_configuration_loads_the_robot_by_name(written, robot, trajectory):
    """12 actuated joints by name, a fixed base, the log's gains; at the log's postures, the calf's mass-matrix
    diagonal is its link's and foot's inertia about its axis as the URDF gives them (the foot 0.25 m down), and a
    hip's, which carries the whole leg, is larger."""
    assert not robot.floating_base and set(robot.actuated) == set(aliengo.ALIENGO_JOINTS)
    assert robot.pd is not None and robot.pd.delay == 0.0
    np.testing.assert_array_equal(robot.pd.kp, np.full(12, 25.0))
    np.testing.assert_array_equal(robot.pd.kd, np.full(12, 0.5))
    assert robot.labels["RR_calf_joint"] == "rear right calf"
    urdf = written.config.parent / aliengo.URDF_FILE
    calf = urdf_inertia_about_y(urdf, "FL_calf", np.zeros(3)) + urdf_inertia_about_y(urdf, "FL_foot",
                                                                                      np.array([0.0, 0.0, 0.25]))
    order = [aliengo.ALIENGO_JOINTS.index(j) for j in robot.actuated]  # the log's columns in the model's order
    model = robot.model
    data = model.createData()
    v = {j: model.joints[model.getJointId(j)].idx_v for j in ("FL_hip_joint", "FL_calf_joint")}
    for row in (0, 1234, 4321):
        M = pin.crba(model, data, robot.configuration(trajectory["dof_pos"][row, order]))
        assert M[v["FL_hip_joint"], v["FL_hip_joint"]] > M[v["FL_calf_joint"], v["FL_calf_joint"]] > 0
        assert M[v["FL_calf_joint"], v["FL_calf_joint"]] == pytest.approx(calf, rel=1e-9)
    log = read_log(written.logs["train"], robot)
    for k, joint in enumerate(aliengo.ALIENGO_JOINTS):
        np.testing.assert_array_equal(log.q[:, robot.actuated.index(joint)], trajectory["dof_pos"][:2820, k])


# --------------------------------------------------------------------------------------------------- the peer
@needs_aliengo
def test_the_peers_file_reads_by_joint_name_with_its_conventions():
    peer = aliengo.aliengo_peer({aliengo.PEER_FILE: FOLDER / aliengo.PEER_FILE})
    for values in (peer.armature, peer.viscous_friction, peer.static_friction, peer.bias):
        assert tuple(values) == aliengo.ALIENGO_JOINTS and all(np.isfinite(list(values.values())))
    assert all(1e-5 <= a <= 1.0 for a in peer.armature.values())  # their search's bounds [kg·m²]
    assert all(abs(b) <= 0.1 for b in peer.bias.values())  # their bounds: ±0.1 rad
    assert round(peer.delay_steps, 2) == 2.64 and peer.applied_delay_steps == 2
    assert peer.delay == pytest.approx(peer.delay_steps * 0.005) and peer.applied_delay == pytest.approx(0.010)
    assert peer.encoder_offset == {j: -b for j, b in peer.bias.items()}
    assert (peer.kp, peer.kd) == (25.0, 0.5)


def test_the_peer_parser_maps_its_order_comment_and_executes_nothing(tmp_path):
    order = list(reversed(aliengo.ALIENGO_JOINTS))
    values = {j: float(i) for i, j in enumerate(order)}
    listed = "[" + ", ".join(str(values[j]) for j in order) + "]"
    body = "".join(f"{key} = {listed}\n" for key in ("armature", "viscous_friction", "static_friction", "bias"))
    path = tmp_path / "params.py"
    path.write_text("# Order: " + ", ".join(j.removesuffix("_joint") for j in order) + "\n\n" + body
                    + "delay = 1.5\nKp = 20\nKd = 1.5\n")
    peer = aliengo.read_peer(path)
    assert peer.armature == values and peer.bias == values and peer.delay_steps == 1.5 and peer.kp == 20.0
    scalars = "delay = 1.5\nKp = 20\nKd = 1.5\n"
    for text, message in (("import os\n" + body + scalars, "line 1 is not 'name = value'"),
                          (body + "delay = __import__('os').getcwd()\n", "line 5: delay is not a literal"),
                          (body.replace(listed, "[1.0, 2.0]", 1) + scalars, "'armature' must be a list of 12 numbers"),
                          (body + "delay = 'two'\nKp = 20\nKd = 1.5\n", "'delay' must be a number")):
        path.write_text(text)
        with pytest.raises(InputError, match=message) as info:
            aliengo.read_peer(path)
        assert str(info.value).startswith(f"{path}: ")


def test_the_peer_fragment_loads_with_the_robot(written, robot):
    """``peer.toml``'s tables over ``aliengo.toml``'s: the armature lands on the mass matrix's diagonal, the encoder
    offsets are minus the peer's bias, the delay the steps its simulation applied."""
    peer = aliengo.read_peer(FOLDER / aliengo.PEER_FILE)
    config = tomllib.loads(written.config.read_text()) | tomllib.loads((written.config.parent / "peer.toml")
                                                                       .read_text())
    with_peer = build_robot(written.config.parent / aliengo.URDF_FILE, config, "peer.toml")
    assert with_peer.encoder_offset == peer.encoder_offset
    assert with_peer.pd.delay == pytest.approx(0.010)
    q = pin.neutral(robot.model)
    bare, armed = (pin.crba(r.model, r.model.createData(), q) for r in (robot, with_peer))
    for joint, armature in peer.armature.items():
        i = robot.model.joints[robot.model.getJointId(joint)].idx_v
        assert armed[i, i] - bare[i, i] == pytest.approx(armature, rel=1e-9)


# ---------------------------------------------------------------------------------------------- the command
@needs_aliengo
def test_the_command_writes_the_logs_and_prints_the_pd_route(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv(datasets.DATA_ENV, str(REAL_DATA))
    out = tmp_path / "aliengo"
    code, printed, err = run_cli_printed(capsys, "dataset", "aliengo", "-o", out)
    assert code == 0, err
    assert {p.name for p in out.iterdir()} == {"train.parquet", "held_out.parquet", "aliengo.toml", "aliengo.urdf",
                                               "peer.toml"}
    assert (out / "aliengo.urdf").read_bytes() == (FOLDER / aliengo.URDF_FILE).read_bytes()
    lines = [line.strip() for line in printed.splitlines() if line.strip().startswith("wbfriction ")]
    assert [line.split()[1] for line in lines] == ["identify", "estimate", "fit", "estimate", "predict", "export",
                                                  "refine"]
    assert f"--config {out / 'aliengo.toml'} --actuator pd" in lines[0]
    assert "aliengo" in datasets.DATASETS and datasets.dataset("aliengo").folder == "unitree_aliengo"
