"""FloBaRoID's KUKA LWR4+ recordings (``wbfriction dataset kuka-lwr4``).

FloBaRoID (https://github.com/kjyv/FloBaRoID, LGPL-3.0) published three recordings of a real KUKA LWR4+
(April 2016; link-side joint torque sensors, receive-time stamps about 5 ms apart; 5027 samples each):
runs 1 and 2 repeat one excitation trajectory, run 3 moves differently. Its ``model/`` folder holds the
robot's URDF (joints ``lwr_0_joint`` ... ``lwr_6_joint``, base welded to the world) and its own
identified inertias. There is no ground-truth friction for this robot; the peer's reference is its method's
held-out torque error on run 3 (:mod:`~wbfriction.datasets.reference`).
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from wbfriction.datasets.dataset import Dataset, WrittenDataset, register
from wbfriction.datasets.store import RemoteFile
from wbfriction.logs.formats.npz import read_npz_recordings
from wbfriction.logs.tables import make_folder, write_atomic, write_table

FLOBAROID = "kjyv/FloBaRoID"
FLOBAROID_DATA_COMMIT = "e6575db3821892f32ccd3dec739666ec24314cff"
"""The commit (2017-03-27) whose ``data/KUKA/HW/measurements_*.npz`` are the recordings, stored in git
(later commits keep them in Git LFS, with the same SHA-256)."""
FLOBAROID_MODEL_COMMIT = "c8a91a99c28533d7cc62c452056e4319b9bd0571"
"""The commit (2026-03-18) whose ``model/kuka_lwr4*.urdf`` are the descriptions: ``kuka_lwr4.urdf`` there
carries ``<dynamics damping friction>`` values set for a simulator, not measured; the identified URDF is
the same as at :data:`FLOBAROID_DATA_COMMIT`."""

KUKA_LWR4_FILES = (
    RemoteFile("measurements_1.npz", FLOBAROID, FLOBAROID_DATA_COMMIT, "data/KUKA/HW/measurements_1.npz",
               "55b94c07e86a75311a584cc945c4436e7a5dbeafd5f7378a53225a0dd820c1fd"),
    RemoteFile("measurements_2.npz", FLOBAROID, FLOBAROID_DATA_COMMIT, "data/KUKA/HW/measurements_2.npz",
               "e15b6df10dd26ecdd3f870bf9a908184207db26f13ae34b9e96931ab9fa14de8"),
    RemoteFile("measurements_3.npz", FLOBAROID, FLOBAROID_DATA_COMMIT, "data/KUKA/HW/measurements_3.npz",
               "4ca527bbac6d6f299e9478451c6b1f059672bf38859e218b0b37fc20bd783acd"),
    RemoteFile("kuka_lwr4.urdf", FLOBAROID, FLOBAROID_MODEL_COMMIT, "model/kuka_lwr4.urdf",
               "8fd76631f12b38404812bc343e998cc9ca3af18d850856c5b050b39ab6fc62ad"),
    RemoteFile("kuka_lwr4_identified.urdf", FLOBAROID, FLOBAROID_MODEL_COMMIT, "model/kuka_lwr4_identified.urdf",
               "524468fde716e8a4e9c8b8d50a746f8e75597a8fc924a629ece1873a33f641c7"),
)
"""Every file: FloBaRoID's recordings and robot descriptions, each from a fixed commit, with its SHA-256."""

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


@register
class KukaLwr4Dataset(Dataset):
    """FloBaRoID's KUKA LWR4+ (module docstring): ``runs12.parquet`` (runs 1 and 2, for estimating, fitting and
    identifying) and ``run3.parquet`` (held out), FloBaRoID's URDF and the configuration naming it."""

    name = "kuka-lwr4"
    folder = "kuka_lwr4"
    summary = "FloBaRoID's KUKA LWR4+: three runs of 25 s, link-side joint torque sensors, about 6 MB"
    files = KUKA_LWR4_FILES

    def write(self, directory: str | Path, files: dict[str, Path] | None = None) -> WrittenDataset:
        files = self.fetch() if files is None else files
        data = KukaLwr4(runs=(files["measurements_1.npz"], files["measurements_2.npz"], files["measurements_3.npz"]),
                        urdf=files["kuka_lwr4.urdf"], identified_urdf=files["kuka_lwr4_identified.urdf"],
                        config=kuka_lwr4_config())
        folder = make_folder(directory)
        runs12, run3 = (folder / name for name in KUKA_LWR4_LOGS)
        tables = (read_npz_recordings(data.runs[:2], KUKA_LWR4_JOINTS),
                  read_npz_recordings(data.runs[2:], KUKA_LWR4_JOINTS))
        for table, path in zip(tables, (runs12, run3)):
            write_table(table, path)
        urdf, config = (folder / name for name in KUKA_LWR4_ROBOT)
        write_atomic(urdf, lambda tmp: tmp.write_bytes(data.urdf.read_bytes()))
        text = data.config.read_text()
        write_atomic(config, lambda tmp: tmp.write_text(text.replace(
            '\nname = "kuka_lwr4"\n', f'\nname = "kuka_lwr4"\nurdf = "{urdf.name}"   # beside this file\n', 1)))
        robot = f"--config {shlex.quote(str(config))}"
        q12, q3 = shlex.quote(str(runs12)), shlex.quote(str(run3))
        commands = (f"wbfriction identify {q12} {robot} -o kuka_identified.urdf --config-output kuka_identified.toml",
                    f"wbfriction estimate {q12} --config kuka_identified.toml -o runs12_friction.parquet",
                    "wbfriction fit runs12_friction.parquet -o runs12_params.json",
                    f"wbfriction estimate {q3} --config kuka_identified.toml -o run3_friction.parquet",
                    "wbfriction predict run3_friction.parquet --params runs12_params.json")
        return WrittenDataset(self.name, {"train": runs12, "held_out": run3},
                              {"train": tables[0].num_rows, "held_out": tables[1].num_rows}, config, commands,
                              {"train": "runs 1 and 2", "held_out": "run 3"})


def kuka_lwr4() -> KukaLwr4:
    """The KUKA LWR4+ dataset of FloBaRoID: its recordings, URDFs and wbfriction's configuration.

    Files come from ``$WBFRICTION_DATA/kuka_lwr4/`` when :data:`~wbfriction.datasets.store.DATA_ENV` is set
    (nothing downloaded), else from the user's cache, downloaded there on first use (about 6 MB). Either way each
    file's SHA-256 is :data:`KUKA_LWR4_FILES`'s.

    Raises:
        InputError: a local copy missing a file or holding one that differs (naming it, the expected and
            the found SHA-256); a file that cannot be downloaded or whose download differs (naming it and
            saying to set ``WBFRICTION_DATA``).
        OutputError: the cache folder cannot be written.
    """
    paths = KukaLwr4Dataset().fetch()
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
        data: the dataset (default: :func:`kuka_lwr4`, fetched or taken from ``WBFRICTION_DATA``).

    Raises:
        InputError: what :func:`kuka_lwr4` and :func:`wbfriction.logs.read_npz_recordings` raise.
        OutputError: the folder cannot be made or a log cannot be written.
    """
    files = None if data is None else {**{p.name: p for p in data.runs}, "kuka_lwr4.urdf": data.urdf,
                                       "kuka_lwr4_identified.urdf": data.identified_urdf}
    written = KukaLwr4Dataset().write(directory, files)
    return KukaLwr4Logs(runs12=written.logs["train"], run3=written.logs["held_out"],
                        rows=(written.rows["train"], written.rows["held_out"]), config=written.config)
