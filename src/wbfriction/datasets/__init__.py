"""Real robots' public logs a user can fetch, as wbfriction logs with the robot beside them, and their references.

Each dataset (:mod:`~wbfriction.datasets.dataset`: one module each, registered in :data:`DATASETS`) names its files
by repository, commit, path and SHA-256 (:mod:`~wbfriction.datasets.store`): downloaded once with :mod:`pooch` into
the user's cache, or read from ``$WBFRICTION_DATA/<folder>/`` (:data:`DATA_ENV`) on offline machines, checked the
same way. ``wbfriction dataset NAME -o DIR`` writes its logs and the robot's configuration (:func:`write_dataset`).
The published friction each is compared with ships as data (:mod:`~wbfriction.datasets.reference`).

* ``kuka-lwr4`` (:mod:`~wbfriction.datasets.kuka`): FloBaRoID's KUKA LWR4+, link-side torque sensors;
* ``ur10e`` (:mod:`~wbfriction.datasets.ur10e`): Mamedov et al.'s UR10e, motor currents and drive gains;
* ``panda`` (:mod:`~wbfriction.datasets.panda`): Gaz et al.'s Franka Panda, link-side torque sensors;
* ``aliengo`` (:mod:`~wbfriction.datasets.aliengo`): the iit-DLSLab's Unitree Aliengo, hung, PD-driven joints (no
  torque sensor: the set-points and the drivers' gains), and the same lab's identification as the peer
  (:func:`~wbfriction.datasets.aliengo.aliengo_peer`);
* ``go2`` (:mod:`~wbfriction.datasets.go2`): the same lab's Unitree Go2, hung and logged the same way, its URDF the
  installed example-robot-data's (the built-in ``go2``'s), and its PACE identification as the peer
  (:func:`~wbfriction.datasets.go2.go2_peer`).

The two hung quadrupeds share their reading, split, robot TOML and route (:mod:`~wbfriction.datasets.hung_quadruped`),
their peer's reader (:mod:`~wbfriction.datasets.pace_peer`) and the ``.pt`` reader
(:mod:`~wbfriction.datasets.torch_pickle`).
"""

from __future__ import annotations

from pathlib import Path

from wbfriction.datasets.aliengo import (
    ALIENGO_FILES,
    ALIENGO_JOINTS,
    AliengoDataset,
    aliengo_peer,
)
from wbfriction.datasets.dataset import DATASETS, Dataset, WrittenDataset, dataset, register
from wbfriction.datasets.go2 import GO2_FILES, Go2Dataset, go2_peer
from wbfriction.datasets.hung_quadruped import HungQuadrupedDataset
from wbfriction.datasets.kuka import (
    KUKA_LWR4_FILES,
    KUKA_LWR4_JOINTS,
    KUKA_LWR4_LOGS,
    KUKA_LWR4_ROBOT,
    KukaLwr4,
    KukaLwr4Dataset,
    KukaLwr4Logs,
    kuka_lwr4,
    kuka_lwr4_config,
    write_kuka_lwr4_logs,
)
from wbfriction.datasets.pace_peer import PeerActuator
from wbfriction.datasets.panda import PandaDataset
from wbfriction.datasets.reference import Reference, reference
from wbfriction.datasets.store import DATA_ENV, GITHUB_RAW, RemoteFile, fetch_files
from wbfriction.datasets.torch_pickle import read_pt
from wbfriction.datasets.ur10e import Ur10eDataset


def write_dataset(name: str, directory: str | Path) -> WrittenDataset:
    """Fetch the dataset ``name`` and write its logs and robot configuration into ``directory``
    (:meth:`~wbfriction.datasets.dataset.Dataset.write`).

    Raises:
        InputError: an unknown name (listing the known ones); a missing, damaged or undownloadable file.
        OutputError: the folder, the cache or a file cannot be written.
    """
    return dataset(name).write(directory)


__all__ = ["ALIENGO_FILES", "ALIENGO_JOINTS", "AliengoDataset", "DATASETS", "DATA_ENV", "Dataset",
           "GITHUB_RAW", "GO2_FILES", "Go2Dataset", "HungQuadrupedDataset", "KUKA_LWR4_FILES",
           "KUKA_LWR4_JOINTS", "KUKA_LWR4_LOGS", "KUKA_LWR4_ROBOT", "KukaLwr4", "KukaLwr4Dataset",
           "KukaLwr4Logs", "PandaDataset", "PeerActuator", "Reference", "RemoteFile", "Ur10eDataset",
           "WrittenDataset", "aliengo_peer", "dataset", "fetch_files", "go2_peer", "kuka_lwr4",
           "kuka_lwr4_config", "read_pt", "reference", "register", "write_dataset", "write_kuka_lwr4_logs"]
