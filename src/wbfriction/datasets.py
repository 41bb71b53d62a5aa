"""Real robot logs a user can fetch: the KUKA LWR4+ recordings of FloBaRoID.

FloBaRoID (https://github.com/kjyv/FloBaRoID, LGPL-3.0) published three recordings of a real KUKA LWR4+
(April 2016; link-side joint torque sensors, receive-time stamps about 5 ms apart; 5027 samples each):
runs 1 and 2 repeat one excitation trajectory, run 3 moves differently. Its ``model/`` folder holds the
robot's URDF (joints ``lwr_0_joint`` ... ``lwr_6_joint``, base welded to the world) and its own
identified inertias. There is no ground-truth friction for this robot.

The files are downloaded once with :mod:`pooch` from fixed commits of that repository into the user's
cache folder (``pooch.os_cache("wbfriction")``, e.g. ``~/.cache/wbfriction/kuka_lwr4``), each checked
against its SHA-256 (:data:`KUKA_LWR4_REGISTRY`). Offline machines and continuous integration set
the environment variable :data:`DATA_ENV` (``WBFRICTION_DATA``) to a folder holding a copy
(``$WBFRICTION_DATA/kuka_lwr4/<file>``): nothing is downloaded, and each file is checked against the
same SHA-256, a file that differs refused.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from wbfriction.exceptions import InputError
from wbfriction.logs.npz import read_npz_recordings
from wbfriction.logs.tables import file_sha256, make_folder, output_error, write_atomic, write_table

DATA_ENV = "WBFRICTION_DATA"
"""Environment variable: a folder holding local copies of the datasets (``<folder>/kuka_lwr4/<file>``),
used instead of downloading."""

FLOBAROID = "https://raw.githubusercontent.com/kjyv/FloBaRoID"
"""Where GitHub serves the files of FloBaRoID's repository, by commit and path."""

FLOBAROID_DATA_COMMIT = "e6575db3821892f32ccd3dec739666ec24314cff"
"""The commit (2017-03-27) whose ``data/KUKA/HW/measurements_*.npz`` are the recordings, stored in git
(later commits keep them in Git LFS, with the same SHA-256)."""

FLOBAROID_MODEL_COMMIT = "c8a91a99c28533d7cc62c452056e4319b9bd0571"
"""The commit (2026-03-18) whose ``model/kuka_lwr4*.urdf`` are the descriptions: ``kuka_lwr4.urdf`` there
carries ``<dynamics damping friction>`` values set for a simulator, not measured; the identified URDF is
the same as at :data:`FLOBAROID_DATA_COMMIT`."""

KUKA_LWR4_SOURCES = {
    "measurements_1.npz": (FLOBAROID_DATA_COMMIT, "data/KUKA/HW/measurements_1.npz"),
    "measurements_2.npz": (FLOBAROID_DATA_COMMIT, "data/KUKA/HW/measurements_2.npz"),
    "measurements_3.npz": (FLOBAROID_DATA_COMMIT, "data/KUKA/HW/measurements_3.npz"),
    "kuka_lwr4.urdf": (FLOBAROID_MODEL_COMMIT, "model/kuka_lwr4.urdf"),
    "kuka_lwr4_identified.urdf": (FLOBAROID_MODEL_COMMIT, "model/kuka_lwr4_identified.urdf"),
}
"""File name -> (commit, path in FloBaRoID's repository)."""

KUKA_LWR4_URLS = {name: f"{FLOBAROID}/{commit}/{path}" for name, (commit, path) in KUKA_LWR4_SOURCES.items()}
"""File name -> the URL it is downloaded from."""

KUKA_LWR4_REGISTRY = {
    "measurements_1.npz": "sha256:55b94c07e86a75311a584cc945c4436e7a5dbeafd5f7378a53225a0dd820c1fd",
    "measurements_2.npz": "sha256:e15b6df10dd26ecdd3f870bf9a908184207db26f13ae34b9e96931ab9fa14de8",
    "measurements_3.npz": "sha256:4ca527bbac6d6f299e9478451c6b1f059672bf38859e218b0b37fc20bd783acd",
    "kuka_lwr4.urdf": "sha256:8fd76631f12b38404812bc343e998cc9ca3af18d850856c5b050b39ab6fc62ad",
    "kuka_lwr4_identified.urdf": "sha256:524468fde716e8a4e9c8b8d50a746f8e75597a8fc924a629ece1873a33f641c7",
}
"""File name -> its SHA-256 (pooch's registry): a downloaded file or a local copy that differs is refused."""

KUKA_LWR4_JOINTS = tuple(f"lwr_{i}_joint" for i in range(7))
"""The recordings' columns, in order: the URDF's joints."""

KUKA_LWR4_LOGS = ("runs12.parquet", "run3.parquet")
"""The logs :func:`write_kuka_lwr4_logs` writes: runs 1 and 2 (one log, the half hour between them a gap),
and run 3 (held out)."""
KUKA_LWR4_ROBOT = ("kuka_lwr4.urdf", "kuka_lwr4.toml")
"""The robot files :func:`write_kuka_lwr4_logs` writes beside the logs: FloBaRoID's URDF, and the packaged
configuration naming it (``urdf = "kuka_lwr4.urdf"``, relative to the TOML), so ``--config <dir>/kuka_lwr4.toml``
is the whole robot."""


@dataclass(frozen=True)
class KukaLwr4:
    """The KUKA LWR4+ dataset's files, checked against their SHA-256.

    Attributes:
        runs: the recordings ``measurements_1.npz`` ... ``measurements_3.npz`` (read with
            :func:`wbfriction.logs.read_npz_recordings` and :data:`KUKA_LWR4_JOINTS`): stamps [s] (Unix
            epoch), positions [rad], velocities [rad/s], torques [N·m].
        urdf: FloBaRoID's description of the robot (its ``<dynamics>`` values are a simulator's guesses).
        identified_urdf: FloBaRoID's identified inertias for these recordings, a peer's result to compare
            against (its negative ``<dynamics friction>`` values make Pinocchio refuse it as it is: drop
            its ``<dynamics>`` tags).
        config: the robot configuration (TOML: fixed base, one group per joint) that ships with wbfriction.
    """

    runs: tuple[Path, Path, Path]
    urdf: Path
    identified_urdf: Path
    config: Path


@dataclass(frozen=True)
class KukaLwr4Logs:
    """The logs :func:`write_kuka_lwr4_logs` wrote.

    Attributes:
        runs12: runs 1 and 2 in the log format, one after the other (a gap between them).
        run3: run 3 in the log format.
        rows: the samples of each, (runs12, run3).
        config: the robot configuration written beside them, naming the URDF copied there (``--config``).
    """

    runs12: Path
    run3: Path
    rows: tuple[int, int]
    config: Path


def kuka_lwr4_config() -> Path:
    """The KUKA LWR4+'s robot configuration shipped with the package (``wbfriction/data/kuka_lwr4.toml``)."""
    return Path(str(resources.files("wbfriction").joinpath("data").joinpath("kuka_lwr4.toml")))


def _local_copy(name: str) -> Path | None:
    """The folder :data:`DATA_ENV` names for the dataset ``name`` (``$WBFRICTION_DATA/<name>``), or None
    when the variable is not set (or empty)."""
    root = os.environ.get(DATA_ENV, "")
    return Path(root).expanduser() / name if root else None


def _sha256(name: str) -> str:
    return KUKA_LWR4_REGISTRY[name].removeprefix("sha256:")


def _verified_copy(folder: Path, name: str) -> Path:
    """The file ``name`` of the KUKA LWR4+ dataset in ``folder``, once its SHA-256 is the registry's.

    Raises:
        InputError: the file is not in ``folder`` (naming both and :data:`DATA_ENV`), or its SHA-256
            differs (naming the file, the expected and the found hash): a damaged or another copy.
    """
    path = folder / name
    if not path.is_file():
        raise InputError(f"{path}: not found ({DATA_ENV}={os.environ.get(DATA_ENV, '')} names a local copy of the "
                         f"datasets; its kuka_lwr4 folder must hold {', '.join(KUKA_LWR4_REGISTRY)})")
    found, expected = file_sha256(path), _sha256(name)
    if found != expected:
        raise InputError(f"{path}: SHA-256 {found}, expected {expected}: not FloBaRoID's file, refused (a damaged "
                         f"or different copy; the original is {KUKA_LWR4_URLS[name]})")
    return path


def _downloaded(names: tuple[str, ...]) -> dict[str, Path]:
    """The files ``names`` of the KUKA LWR4+ dataset in the user's cache, downloaded there first if they are
    not, each checked by pooch against its SHA-256 (a cached file that differs is downloaded again).

    Raises:
        InputError: a file that cannot be downloaded (no network, the server's refusal), or whose download
            differs from its SHA-256, naming it, the URL and the reason, and :data:`DATA_ENV` as the way to
            work offline.
        OutputError: the cache folder cannot be written.
    """
    import pooch
    import requests

    cache = Path(pooch.os_cache("wbfriction")) / "kuka_lwr4"
    store = pooch.create(path=cache, base_url=f"{FLOBAROID}/{FLOBAROID_DATA_COMMIT}/", registry=KUKA_LWR4_REGISTRY,
                         urls=KUKA_LWR4_URLS, retry_if_failed=2)
    offline = f"set {DATA_ENV} to a folder holding kuka_lwr4/{{name}} (a copy of FloBaRoID's files) to work offline"
    paths = {}
    for name in names:
        try:
            paths[name] = Path(store.fetch(name))
        except requests.RequestException as exc:
            reason = " ".join(str(exc).split()) or type(exc).__name__
            raise InputError(f"{name}: cannot be downloaded from {KUKA_LWR4_URLS[name]} ({reason}); "
                             + offline.format(name=name)) from exc
        except ValueError as exc:  # pooch: the download's hash is not the registry's
            reason = " ".join(str(exc).split())
            raise InputError(f"{name}: the file downloaded from {KUKA_LWR4_URLS[name]} is refused ({reason}); "
                             + offline.format(name=name)) from exc
        except OSError as exc:
            raise output_error(cache / name, exc) from exc
    return paths


def kuka_lwr4() -> KukaLwr4:
    """The KUKA LWR4+ dataset of FloBaRoID: its recordings, URDFs and wbfriction's configuration.

    Files come from ``$WBFRICTION_DATA/kuka_lwr4/`` when :data:`DATA_ENV` is set (nothing downloaded),
    else from the user's cache, downloaded there on first use (about 6 MB). Either way each file's SHA-256
    is :data:`KUKA_LWR4_REGISTRY`'s.

    Returns:
        The files' paths.

    Raises:
        InputError: a local copy missing a file or holding one that differs (naming it, the expected and
            the found SHA-256); a file that cannot be downloaded or whose download differs (naming it and
            saying to set :data:`DATA_ENV`).
        OutputError: the cache folder cannot be written.
    """
    names = tuple(KUKA_LWR4_REGISTRY)
    folder = _local_copy("kuka_lwr4")
    paths = {n: _verified_copy(folder, n) for n in names} if folder is not None else _downloaded(names)
    return KukaLwr4(runs=(paths["measurements_1.npz"], paths["measurements_2.npz"], paths["measurements_3.npz"]),
                    urdf=paths["kuka_lwr4.urdf"], identified_urdf=paths["kuka_lwr4_identified.urdf"],
                    config=kuka_lwr4_config())


def write_kuka_lwr4_logs(directory: str | Path, data: KukaLwr4 | None = None) -> KukaLwr4Logs:
    """Write the KUKA LWR4+ recordings as wbfriction logs (:data:`KUKA_LWR4_LOGS`): ``runs12.parquet`` (runs
    1 and 2, for estimating and fitting) and ``run3.parquet`` (run 3, held out), stamps untouched; and beside
    them the robot (:data:`KUKA_LWR4_ROBOT`): the URDF and a configuration that names it, so that
    ``--config <directory>/kuka_lwr4.toml`` loads the robot.

    Args:
        directory: the folder to write into, made if it does not exist; files already there are replaced,
            each written whole or not at all.
        data: the dataset (default: :func:`kuka_lwr4`, fetched or taken from :data:`DATA_ENV`).

    Returns:
        The logs' paths and sample counts.

    Raises:
        InputError: what :func:`kuka_lwr4` and :func:`wbfriction.logs.read_npz_recordings` raise.
        OutputError: the folder cannot be made or a log cannot be written.
    """
    data = kuka_lwr4() if data is None else data
    folder = make_folder(directory)
    runs12, run3 = (folder / name for name in KUKA_LWR4_LOGS)
    tables = (read_npz_recordings(data.runs[:2], KUKA_LWR4_JOINTS), read_npz_recordings(data.runs[2:],
                                                                                          KUKA_LWR4_JOINTS))
    for table, path in zip(tables, (runs12, run3)):
        write_table(table, path)
    urdf, config = (folder / name for name in KUKA_LWR4_ROBOT)
    write_atomic(urdf, lambda tmp: tmp.write_bytes(data.urdf.read_bytes()))
    text = data.config.read_text()
    write_atomic(config, lambda tmp: tmp.write_text(text.replace('\nname = "kuka_lwr4"\n', '\nname = "kuka_lwr4"\n'
                                                                 f'urdf = "{urdf.name}"   # beside this file\n', 1)))
    return KukaLwr4Logs(runs12=runs12, run3=run3, rows=(tables[0].num_rows, tables[1].num_rows), config=config)
