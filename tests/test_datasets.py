"""The KUKA LWR4+ dataset as a pip user fetches it (issue 39): from a local copy (``WBFRICTION_DATA``) or
downloaded with pooch (here from a local HTTP server: this machine has no network), every file checked
against its SHA-256, a damaged or missing file refused in one line naming it; ``wbfriction dataset
kuka-lwr4`` writes the two logs."""

from __future__ import annotations

import functools
import hashlib
import http.server
import re
import shlex
import shutil
import threading
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

import wbfriction
from helpers import KUKA, REPO, needs_kuka, run_cli_printed
from wbfriction import datasets
from wbfriction.exceptions import InputError
from wbfriction.logs.source import read_log
from wbfriction.model import load_robot

pytestmark = needs_kuka
NAMES = ("measurements_1.npz", "measurements_2.npz", "measurements_3.npz", "kuka_lwr4.urdf",
         "kuka_lwr4_identified.urdf")
SAMPLES = 5027
"""Samples of each run (FloBaRoID's recordings, read with NumPy here)."""


def sha256(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def copy_of_the_data(tmp_path, leave_out: str | None = None):
    """A writable copy of the local data folder (``<root>/kuka_lwr4/<file>``), returning ``root``."""
    folder = tmp_path / "data" / "kuka_lwr4"
    folder.mkdir(parents=True)
    for name in NAMES:
        if name != leave_out:
            shutil.copyfile(KUKA / name, folder / name)
    return folder.parent


def flip_a_byte(path, at: int = 1_000_000) -> None:
    data = bytearray(path.read_bytes())
    data[at] ^= 0x01
    path.write_bytes(bytes(data))


def refused() -> str:
    with pytest.raises(InputError) as info:
        datasets.kuka_lwr4()
    assert "\n" not in str(info.value)
    return str(info.value)


@pytest.fixture
def local_copy(monkeypatch):
    monkeypatch.setenv(datasets.DATA_ENV, str(KUKA.parent))


def test_the_local_copy_is_the_registrys(local_copy):
    data = datasets.kuka_lwr4()
    assert data.runs == tuple(KUKA / f"measurements_{i}.npz" for i in (1, 2, 3))
    assert (data.urdf, data.identified_urdf) == (KUKA / "kuka_lwr4.urdf", KUKA / "kuka_lwr4_identified.urdf")
    for path in (*data.runs, data.urdf, data.identified_urdf):
        assert datasets.KUKA_LWR4_REGISTRY[path.name] == f"sha256:{sha256(path)}"


def test_every_file_comes_from_a_fixed_commit_of_flobaroid():
    assert set(datasets.KUKA_LWR4_REGISTRY) == set(datasets.KUKA_LWR4_URLS) == set(NAMES)
    for name, url in datasets.KUKA_LWR4_URLS.items():
        found = re.fullmatch(r"https://raw\.githubusercontent\.com/kjyv/FloBaRoID/([0-9a-f]{40})/(\S+)", url)
        assert found and found.group(2).endswith("/" + name), url


def test_the_packaged_configuration_loads_the_robot(local_copy):
    data = datasets.kuka_lwr4()
    assert data.config.read_text() == (REPO / "examples" / "kuka_lwr4.toml").read_text()  # the README's copy
    assert data.config.relative_to(Path(wbfriction.__file__).parent).as_posix() == "data/kuka_lwr4.toml"
    robot = load_robot(urdf=data.urdf, config=data.config)
    assert robot.actuated == datasets.KUKA_LWR4_JOINTS and not robot.floating_base


def test_the_configuration_ships_with_the_package():
    """pyproject's package-data names the configuration (a wheel built from the checkout carries it)."""
    import fnmatch
    import tomllib

    globs = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["wbfriction"]
    assert any(fnmatch.fnmatch("data/kuka_lwr4.toml", g) for g in globs)


def test_a_damaged_copy_is_refused(tmp_path, monkeypatch):
    root = copy_of_the_data(tmp_path)
    damaged = root / "kuka_lwr4" / "measurements_2.npz"
    flip_a_byte(damaged)
    monkeypatch.setenv(datasets.DATA_ENV, str(root))
    message = refused()
    expected = datasets.KUKA_LWR4_REGISTRY["measurements_2.npz"].removeprefix("sha256:")
    assert message.startswith(f"{damaged}: SHA-256 {sha256(damaged)}, expected {expected}")
    assert sha256(damaged) != expected and "refused" in message


def test_a_missing_file_is_named(tmp_path, monkeypatch):
    root = copy_of_the_data(tmp_path, leave_out="kuka_lwr4.urdf")
    monkeypatch.setenv(datasets.DATA_ENV, str(root))
    message = refused()
    assert message.startswith(f"{root / 'kuka_lwr4' / 'kuka_lwr4.urdf'}: not found")
    assert f"{datasets.DATA_ENV}={root}" in message


class Server:
    """The data folder served over HTTP on this machine, as GitHub serves FloBaRoID's files."""

    def __init__(self, folder):
        class Quiet(http.server.SimpleHTTPRequestHandler):
            def log_message(self, *args):
                pass

        self.requests: list[str] = []
        served = self.requests

        class Counted(Quiet):
            def do_GET(self):  # noqa: N802 - http.server's name
                served.append(self.path)
                super().do_GET()

        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0),
                                                     functools.partial(Counted, directory=str(folder)))
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}"
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def served(tmp_path, monkeypatch):
    """A copy of the data served over HTTP, the dataset's URLs pointing at it, no local copy set and the
    user's cache in ``tmp_path``; yields (the served folder, the server, the cache folder)."""
    folder = copy_of_the_data(tmp_path) / "kuka_lwr4"
    server = Server(folder)
    monkeypatch.setattr(datasets, "KUKA_LWR4_URLS", {n: f"{server.url}/{n}" for n in NAMES})
    monkeypatch.delenv(datasets.DATA_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    for proxy in ("no_proxy", "NO_PROXY"):  # this machine's server, whatever proxy the environment names
        monkeypatch.setenv(proxy, "127.0.0.1")
    monkeypatch.setattr(time, "sleep", lambda seconds: None)  # pooch's pause before it tries a download again
    yield folder, server, tmp_path / "cache" / "wbfriction" / "kuka_lwr4"
    server.close()


def test_downloaded_once_into_the_cache_and_checked(served):
    folder, server, cache = served
    data = datasets.kuka_lwr4()
    assert data.runs == tuple(cache / f"measurements_{i}.npz" for i in (1, 2, 3)) and data.urdf.parent == cache
    for path in (*data.runs, data.urdf, data.identified_urdf):
        assert path.read_bytes() == (folder / path.name).read_bytes()
    assert sorted(server.requests) == sorted(f"/{n}" for n in NAMES)
    server.close()  # offline now: the cache serves
    assert datasets.kuka_lwr4() == data


def test_a_damaged_download_is_refused_and_not_kept(served):
    folder, _, cache = served
    flip_a_byte(folder / "measurements_3.npz")
    message = refused()
    assert message.startswith("measurements_3.npz: the file downloaded from ")
    assert sha256(folder / "measurements_3.npz") in message and datasets.DATA_ENV in message
    assert not (cache / "measurements_3.npz").exists()


def test_no_network_says_to_set_the_local_copy(served):
    _, server, _ = served
    server.close()  # nothing answers at the URLs any more
    message = refused()
    assert message.startswith(f"measurements_1.npz: cannot be downloaded from {server.url}/measurements_1.npz")
    assert f"set {datasets.DATA_ENV} to a folder holding kuka_lwr4/measurements_1.npz" in message


def test_the_command_writes_both_logs(tmp_path, capsys, local_copy):
    out = tmp_path / "new" / "kuka"
    code, printed, err = run_cli_printed(capsys, "dataset", "kuka-lwr4", "-o", out)
    assert code == 0, err
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
    estimate = shlex.split(next(line for line in printed.splitlines() if "wbfriction estimate" in line))
    config = estimate[estimate.index("--config") + 1]
    assert config == str(out / "kuka_lwr4.toml") and "--urdf" not in estimate
    assert (out / "kuka_lwr4.urdf").read_bytes() == (KUKA / "kuka_lwr4.urdf").read_bytes()
    assert estimate[2] == str(out / "runs12.parquet")
    robot = load_robot(config=config)
    assert robot.actuated == datasets.KUKA_LWR4_JOINTS and not robot.floating_base
    log = read_log(out / "runs12.parquet", robot)
    assert log.segments == [(0, SAMPLES), (SAMPLES, 2 * SAMPLES)]  # the half hour between the runs is a gap


def test_the_command_refuses_a_damaged_copy_and_an_unknown_dataset(tmp_path, capsys, monkeypatch):
    root = copy_of_the_data(tmp_path)
    flip_a_byte(root / "kuka_lwr4" / "kuka_lwr4.urdf", at=5000)
    monkeypatch.setenv(datasets.DATA_ENV, str(root))
    code, _, err = run_cli_printed(capsys, "dataset", "kuka-lwr4", "-o", tmp_path / "out")
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and f"{root / 'kuka_lwr4' / 'kuka_lwr4.urdf'}: SHA-256" in lines[0]
    assert not (tmp_path / "out").exists()  # refused before anything is written
    code, _, err = run_cli_printed(capsys, "dataset", "kuka", "-o", tmp_path / "out")
    assert code == 2 and "'kuka'" in err and "kuka-lwr4" in err and len(err.strip().splitlines()) == 1
