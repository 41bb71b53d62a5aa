"""The real datasets as a pip user fetches them (issues 39, 52): from a local copy (``WBFRICTION_DATA``) or
downloaded with pooch (here from a local HTTP server: this machine has no network), every file from a fixed commit
and checked against its SHA-256, a damaged or missing file refused in one line naming it; ``wbfriction dataset NAME``
writes each dataset's logs as recorded, with the robot beside them, and the published references ship as data."""

from __future__ import annotations

import hashlib
import http.server
import re
import shlex
import shutil
import threading
import time
import typing
from functools import partial
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import wbfriction
from helpers import KUKA, REAL_DATA, REPO, assert_stages, needs_data, needs_kuka, run_cli_printed, said
from wbfriction import datasets
from wbfriction.cli.data import DatasetName
from wbfriction.datasets import panda, ur10e
from wbfriction.datasets.reference import CoulombViscous, HeldOutRms, Sigmoid
from wbfriction.exceptions import InputError
from wbfriction.logs.source import read_log
from wbfriction.model import load_robot

NAMES = ("measurements_1.npz", "measurements_2.npz", "measurements_3.npz", "kuka_lwr4.urdf",
         "kuka_lwr4_identified.urdf")
SAMPLES = 5027
"""Samples of each KUKA run (FloBaRoID's recordings, read with NumPy here)."""
KUKA_SET = datasets.dataset("kuka-lwr4")


def sha256(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def copy_of_the_data(tmp_path, leave_out: str | None = None, folder: str = "kuka_lwr4"):
    """A writable copy of the local data folder (``<root>/<folder>/<file>``), returning ``root``."""
    target = tmp_path / "data" / folder
    target.mkdir(parents=True)
    for f in datasets.dataset(folder.replace("_", "-")).files:
        if f.name != leave_out:
            shutil.copyfile(REAL_DATA / folder / f.name, target / f.name)
    return target.parent


def flip_a_byte(path, at: int = 1_000_000) -> None:
    data = bytearray(path.read_bytes())
    data[at] ^= 0x01
    path.write_bytes(bytes(data))


def refused(fetch=datasets.kuka_lwr4) -> str:
    with pytest.raises(InputError) as info:
        fetch()
    assert "\n" not in str(info.value)
    return str(info.value)


@pytest.fixture
def local_copy(monkeypatch):
    monkeypatch.setenv(datasets.DATA_ENV, str(REAL_DATA))


def test_the_command_names_every_registered_dataset():
    assert typing.get_args(DatasetName) == tuple(datasets.DATASETS) == ("aliengo", "go2", "kuka-lwr4", "panda", "ur10e")
    with pytest.raises(InputError, match="unknown dataset 'kuka'.*kuka-lwr4"):
        datasets.dataset("kuka")


@pytest.mark.parametrize("name", list(datasets.DATASETS))
def test_every_file_comes_from_a_fixed_commit(name):
    ds = datasets.dataset(name)
    assert len({f.name for f in ds.files}) == len(ds.files)
    for f in ds.files:
        found = re.fullmatch(r"https://raw\.githubusercontent\.com/([\w.-]+/[\w.-]+)/([0-9a-f]{40})/(\S+)", f.url())
        assert found and found.group(1) == f.repository and found.group(3) == f.path, f.url()
        assert re.fullmatch(r"[0-9a-f]{64}", f.sha256)


@pytest.mark.parametrize("name", list(datasets.DATASETS))
def test_the_local_copy_is_the_registrys(name, local_copy):
    ds = datasets.dataset(name)
    if not (REAL_DATA / ds.folder).is_dir():
        pytest.skip(f"no {REAL_DATA / ds.folder}")
    paths = ds.fetch()
    assert set(paths) == {f.name for f in ds.files}
    for f in ds.files:
        assert paths[f.name] == REAL_DATA / ds.folder / f.name and sha256(paths[f.name]) == f.sha256


@needs_kuka
def test_the_kuka_api_gives_the_files(local_copy):
    data = datasets.kuka_lwr4()
    assert data.runs == tuple(KUKA / f"measurements_{i}.npz" for i in (1, 2, 3))
    assert (data.urdf, data.identified_urdf) == (KUKA / "kuka_lwr4.urdf", KUKA / "kuka_lwr4_identified.urdf")


@needs_kuka
def test_the_packaged_configuration_loads_the_robot(local_copy):
    data = datasets.kuka_lwr4()
    assert data.config.read_text() == (REPO / "examples" / "kuka_lwr4.toml").read_text()  # the README's copy
    assert data.config.relative_to(Path(wbfriction.__file__).parent).as_posix() == "data/kuka_lwr4.toml"
    robot = load_robot(urdf=data.urdf, config=data.config)
    assert robot.actuated == datasets.KUKA_LWR4_JOINTS and not robot.floating_base


def test_the_configuration_and_references_ship_with_the_package():
    """pyproject's package-data names the configuration and the references (a wheel built from the checkout
    carries them)."""
    import fnmatch
    import tomllib

    globs = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["wbfriction"]
    for name in ("data/kuka_lwr4.toml", *(f"data/references/{n}.toml" for n in datasets.DATASETS)):
        assert any(fnmatch.fnmatch(name, g) for g in globs), name


@needs_kuka
def test_a_damaged_copy_is_refused(tmp_path, monkeypatch):
    root = copy_of_the_data(tmp_path)
    damaged = root / "kuka_lwr4" / "measurements_2.npz"
    flip_a_byte(damaged)
    monkeypatch.setenv(datasets.DATA_ENV, str(root))
    message = refused()
    expected = next(f.sha256 for f in KUKA_SET.files if f.name == "measurements_2.npz")
    assert message.startswith(f"{damaged}: SHA-256 {sha256(damaged)}, expected {expected}")
    assert sha256(damaged) != expected and "refused" in message


@needs_kuka
def test_a_missing_file_is_named(tmp_path, monkeypatch):
    root = copy_of_the_data(tmp_path, leave_out="kuka_lwr4.urdf")
    monkeypatch.setenv(datasets.DATA_ENV, str(root))
    message = refused()
    assert message.startswith(f"{root / 'kuka_lwr4' / 'kuka_lwr4.urdf'}: not found")
    assert f"{datasets.DATA_ENV}={root}" in message


class Server:
    """Files served over HTTP on this machine as GitHub serves a repository's: ``/<owner>/<name>/<commit>/<path>``."""

    def __init__(self, folder):
        class Counted(http.server.SimpleHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def do_GET(self):  # noqa: N802 - http.server's name
                served.append(self.path)
                super().do_GET()

        self.requests: list[str] = []
        served = self.requests
        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), partial(Counted, directory=str(folder)))
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}"
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def served(tmp_path, monkeypatch):
    """The KUKA files laid out as GitHub serves them and served over HTTP, no local copy set, the user's cache in
    ``tmp_path``; yields (the served tree, the server, the cache folder, the fetch to call)."""
    tree = tmp_path / "github"
    for f in KUKA_SET.files:
        target = tree / f.repository / f.commit / f.path
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(KUKA / f.name, target)
    server = Server(tree)
    monkeypatch.delenv(datasets.DATA_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    for proxy in ("no_proxy", "NO_PROXY"):  # this machine's server, whatever proxy the environment names
        monkeypatch.setenv(proxy, "127.0.0.1")
    monkeypatch.setattr(time, "sleep", lambda seconds: None)  # pooch's pause before it tries a download again
    yield tree, server, tmp_path / "cache" / "wbfriction" / "kuka_lwr4", partial(KUKA_SET.fetch, base=server.url)
    server.close()


def served_file(tree: Path, name: str) -> Path:
    f = next(f for f in KUKA_SET.files if f.name == name)
    return tree / f.repository / f.commit / f.path


@needs_kuka
def test_downloaded_once_into_the_cache_and_checked(served):
    tree, server, cache, fetch = served
    paths = fetch()
    assert set(paths) == set(NAMES) and all(p.parent == cache for p in paths.values())
    for name, path in paths.items():
        assert path.read_bytes() == served_file(tree, name).read_bytes()
    assert sorted(server.requests) == sorted(f"/{f.repository}/{f.commit}/{f.path}" for f in KUKA_SET.files)
    server.close()  # offline now: the cache serves
    assert fetch() == paths


@needs_kuka
def test_a_damaged_download_is_refused_and_not_kept(served):
    tree, _, cache, fetch = served
    flip_a_byte(served_file(tree, "measurements_3.npz"))
    message = refused(fetch)
    assert message.startswith("measurements_3.npz: the file downloaded from ")
    assert sha256(served_file(tree, "measurements_3.npz")) in message and datasets.DATA_ENV in message
    assert not (cache / "measurements_3.npz").exists()


@needs_kuka
def test_no_network_says_to_set_the_local_copy(served):
    _, server, _, fetch = served
    server.close()  # nothing answers at the URLs any more
    message = refused(fetch)
    f = KUKA_SET.files[0]
    assert message.startswith(f"measurements_1.npz: cannot be downloaded from {f.url(server.url)}")
    assert f"set {datasets.DATA_ENV} to a folder holding kuka_lwr4/measurements_1.npz" in message


def printed_command(printed: str, word: str) -> list[str]:
    return shlex.split(next(line for line in printed.splitlines() if f"wbfriction {word}" in line))


@needs_kuka
def test_the_command_writes_both_kuka_logs(tmp_path, capsys, local_copy):
    out = tmp_path / "new" / "kuka"
    code, printed, err = run_cli_printed(capsys, "dataset", "kuka-lwr4", "-o", out)
    assert code == 0, err
    assert_stages(err, "fetching the kuka-lwr4 dataset")  # piped: its stage's line (issue 67)
    runs = []
    for i in (1, 2, 3):
        with np.load(KUKA / f"measurements_{i}.npz") as recording:
            runs.append(recording["times"])
    assert [len(t) for t in runs] == [SAMPLES] * 3
    runs12, run3 = pq.read_table(out / "runs12.parquet"), pq.read_table(out / "run3.parquet")
    assert (runs12.num_rows, run3.num_rows) == (2 * SAMPLES, SAMPLES)
    np.testing.assert_array_equal(runs12["time"].to_numpy(), np.concatenate(runs[:2]))
    np.testing.assert_array_equal(run3["time"].to_numpy(), runs[2])
    assert f"{out / 'runs12.parquet'} ({2 * SAMPLES} samples" in err
    # the printed commands name the configuration written beside the logs, which names the URDF copied there
    identify = printed_command(printed, "identify")
    config = identify[identify.index("--config") + 1]
    assert config == str(out / "kuka_lwr4.toml") and "--urdf" not in identify and "--config-output" in identify
    assert (out / "kuka_lwr4.urdf").read_bytes() == (KUKA / "kuka_lwr4.urdf").read_bytes()
    assert identify[2] == str(out / "runs12.parquet")
    robot = load_robot(config=config)
    assert robot.actuated == datasets.KUKA_LWR4_JOINTS and not robot.floating_base
    log = read_log(out / "runs12.parquet", robot)
    assert log.segments == [(0, SAMPLES), (SAMPLES, 2 * SAMPLES)]  # the half hour between the runs is a gap


@needs_data("ur10e")
def test_the_command_writes_the_ur10e_logs_with_its_drive_gains(tmp_path, capsys, local_copy):
    """The UR10e's CSV (31 columns: t, q, qd, i, i_des, tau_des) as a log of currents, its stamps as recorded; the
    configuration's torque constants are the authors' drive gains, so ``current x constant`` is their torque."""
    out = tmp_path / "ur"
    code, printed, err = run_cli_printed(capsys, "dataset", "ur10e", "-o", out)
    assert code == 0, err
    raw = np.loadtxt(REAL_DATA / "ur10e" / "ur-20_02_12-50sec_12harm.csv", delimiter=",")
    table = pq.read_table(out / "excitation.parquet")
    np.testing.assert_array_equal(table["time"].to_numpy(), raw[:, 0])
    for k, j in enumerate(ur10e.UR10E_JOINTS):
        np.testing.assert_array_equal(table[f"q.{j}"].to_numpy(), raw[:, 1 + k])
        np.testing.assert_array_equal(table[f"qd.{j}"].to_numpy(), raw[:, 7 + k])
        np.testing.assert_array_equal(table[f"current.{j}"].to_numpy(), raw[:, 13 + k])
    assert pq.read_table(out / "joint1.parquet").num_rows == 5889
    robot = load_robot(config=out / "ur10e.toml")
    assert robot.actuated == ur10e.UR10E_JOINTS and not robot.floating_base
    gains = ur10e.read_parameters(REAL_DATA / "ur10e" / "UR10E_parameters.txt")["drvGains"]
    log = read_log(out / "excitation.parquet", robot)
    np.testing.assert_allclose(log.tau, raw[:, 13:19] * gains, rtol=1e-15)
    identify = printed_command(printed, "identify")
    assert "--armature" in identify and identify[identify.index("--armature") + 1] == "identify"


@needs_data("panda")
def test_the_command_writes_the_panda_log_and_the_arm_without_its_hand(tmp_path, capsys, local_copy):
    out = tmp_path / "panda"
    code, _, err = run_cli_printed(capsys, "dataset", "panda", "-o", out)
    assert code == 0, err
    folder = REAL_DATA / "panda"
    time_ = np.loadtxt(folder / "exciting_traj_time.txt")
    tau = np.loadtxt(folder / "exciting_traj_torques.txt").reshape(-1, 7)
    robot = load_robot(config=out / "panda.toml")
    assert robot.actuated == panda.PANDA_JOINTS and not robot.floating_base
    assert not np.any(robot.model.armature)  # link-side sensors: no rotor in the torques
    assert not any(f.name in panda.HAND_LINKS for f in robot.model.frames)
    assert robot.model.inertias[robot.model.getJointId("panda_joint7")].mass == pytest.approx(0.735522, abs=1e-12)
    log = read_log(out / "excitation.parquet", robot)
    np.testing.assert_array_equal(log.time, time_)
    np.testing.assert_array_equal(log.tau, tau)
    assert len(log) == 20544


@needs_data("panda")
def test_the_panda_arm_and_the_published_friction_predict_the_log_the_arm_with_its_hand_does_not(tmp_path,
                                                                                                local_copy):
    """Why the dataset's arm has no hand: its links are Gaz et al.'s identification, and with their published
    friction they give the log's torques to 0.07-0.45 N·m RMS per joint (the offset aside); with the Franka Hand's
    0.76 kg on the flange, every joint but the flange's 2.5 to 7 times worse (the shoulder 1.9 N·m)."""
    from wbfriction.friction.estimate import estimate_log
    from wbfriction.friction.options import EstimateOptions

    written = datasets.write_dataset("panda", tmp_path / "panda")
    arm = load_robot(config=written.config)
    hand = tmp_path / "hand.toml"
    hand.write_text(f'urdf = "example-robot-data:{panda.INSTALLED_URDF}"\nfloating_base = false\n'
                    "[locked_joints]\npanda_finger_joint1 = 0.0\npanda_finger_joint2 = 0.0\n")
    with_hand = load_robot(config=hand)
    ref = datasets.reference("panda")

    def rms(robot):
        est = estimate_log(robot, read_log(written.logs["train"], robot), EstimateOptions())
        out = []
        for k, joint in enumerate(est.joints):
            ok = est.valid[:, k]
            r = -est.tau_f[ok, k] - ref.f(joint, est.qd[ok, k])
            out.append(float(np.std(r)))
        return np.array(out)

    arm_rms, hand_rms = rms(arm), rms(with_hand)
    assert np.all(arm_rms < 0.5), arm_rms
    assert np.all(hand_rms[:6] > 2 * arm_rms[:6]) and hand_rms[1] > 1.5, (arm_rms, hand_rms)


@needs_data("panda")
def test_a_panda_file_with_a_value_missing_is_refused(tmp_path, local_copy):
    files = {f.name: REAL_DATA / "panda" / f.name for f in panda.PANDA_FILES}
    short = tmp_path / "exciting_traj_torques.txt"
    short.write_text("\n".join(files[short.name].read_text().splitlines()[:-1]) + "\n")
    with pytest.raises(InputError, match=r"exciting_traj_torques.txt: 143807 values, expected 7 for each of the "
                                         r"20544 stamps"):
        panda.read_panda_log({**files, short.name: short})


def test_the_command_refuses_an_unknown_dataset(tmp_path, capsys):
    code, _, err = run_cli_printed(capsys, "dataset", "kuka", "-o", tmp_path / "out")
    assert code == 2 and "'kuka'" in err and "kuka-lwr4" in err and len(said(err)) == 1


@needs_kuka
def test_the_command_refuses_a_damaged_copy_before_writing(tmp_path, capsys, monkeypatch):
    root = copy_of_the_data(tmp_path)
    flip_a_byte(root / "kuka_lwr4" / "kuka_lwr4.urdf", at=5000)
    monkeypatch.setenv(datasets.DATA_ENV, str(root))
    code, _, err = run_cli_printed(capsys, "dataset", "kuka-lwr4", "-o", tmp_path / "out")
    lines = said(err)
    assert code == 2 and len(lines) == 1 and f"{root / 'kuka_lwr4' / 'kuka_lwr4.urdf'}: SHA-256" in lines[0]
    assert not (tmp_path / "out").exists()  # refused before anything is written


def test_each_reference_reads_as_its_kind():
    ur, pa_, kuka = (datasets.reference(n) for n in ("ur10e", "panda", "kuka-lwr4"))
    assert isinstance(ur, CoulombViscous) and isinstance(pa_, Sigmoid) and isinstance(kuka, HeldOutRms)
    assert ur.joints == ur10e.UR10E_JOINTS and pa_.joints == panda.PANDA_JOINTS
    assert kuka.joints == datasets.KUKA_LWR4_JOINTS and not kuka.has_curve and kuka.held_out("lwr_0_joint") == 0.715
    # wbfriction's sign convention: positive at positive speed; the odd part removes the offset
    v = np.array([0.1, 0.5, 2.0])
    np.testing.assert_allclose(ur.odd("elbow_joint", v), 10.3777424977617 * v + 4.99431320112810)
    np.testing.assert_allclose(ur.f("elbow_joint", np.zeros(1)), 0.197915175643975)
    # the sigmoid is zero at rest, odd part A/2 tanh(alpha v / 2) when s = 0, towards A/2 at speed
    assert pa_.f("panda_joint1", np.zeros(1))[0] == pytest.approx(0.0, abs=1e-15)
    assert pa_.odd("panda_joint7", np.array([5.0]))[0] == pytest.approx(0.56489 / 2, rel=1e-3)
    with pytest.raises(InputError, match="no joint 'lwr_0_joint'"):
        ur.odd("lwr_0_joint", v)


@needs_data("ur10e")
def test_the_ur10e_reference_is_the_authors_file():
    """The shipped numbers are pi_frcn of UR10E_parameters.txt (per joint F_v, F_c, offset)."""
    published = ur10e.read_parameters(REAL_DATA / "ur10e" / "UR10E_parameters.txt")["pi_frcn"].reshape(6, 3)
    ref = datasets.reference("ur10e")
    np.testing.assert_array_equal(np.column_stack([ref.F_v, ref.F_c, ref.offset]), published)


def test_offline_the_error_is_the_only_line(tmp_path, monkeypatch, capfd):
    """Issue 53: with nothing answering, pooch's 'Failed to download ... Will retry' lines came before the one
    line that says what to do; only that line is printed now."""
    import logging
    import socket

    from wbfriction.datasets.store import RemoteFile, fetch_files
    with socket.socket() as s:  # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    monkeypatch.delenv(datasets.DATA_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    for proxy in ("no_proxy", "NO_PROXY"):
        monkeypatch.setenv(proxy, "127.0.0.1")
    monkeypatch.setattr(time, "sleep", lambda seconds: None)
    f = RemoteFile("x.npz", "o/r", "0" * 40, "x.npz", "0" * 64)
    with pytest.raises(InputError, match="x.npz: cannot be downloaded from"):
        fetch_files("offline", [f], base=f"http://127.0.0.1:{port}")
    out, err = capfd.readouterr()
    assert "retry" not in (out + err).lower() and "Failed to download" not in out + err
    import pooch
    assert pooch.get_logger().level == logging.NOTSET or pooch.get_logger().level < logging.WARNING  # restored
