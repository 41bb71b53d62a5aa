"""A Unitree Aliengo hung with its base fixed, its joints PD-driven (``wbfriction dataset aliengo``).

The iit-DLSLab published the log of their Aliengo identification (https://github.com/iit-DLSLab/
simple-robot-identification-isaaclab, BSD-3-Clause; the files are downloaded from there, never redistributed):
the robot hung in the air, base fixed and level, every joint tracking triangle position ramps under its motor
driver's PD law (``kp`` 25 N·m/rad, ``kd`` 0.5 N·m·s/rad), 200 Hz, 23.5 s. No torque is logged (the Aliengo has no
joint torque sensor): the log holds the encoder's angles, the driver's own velocities and the set-points.
``datasets/aliengo/traj_0.pt`` is a PyTorch zip-pickle, read without torch
(:func:`~wbfriction.datasets.torch_pickle.read_pt`). The URDF is
Unitree's (https://github.com/unitreerobotics/unitree_ros, ``robots/aliengo_description/urdf/aliengo.urdf``; its
thigh joints are ``continuous``).

Logs written (:mod:`~wbfriction.datasets.hung_quadruped`): ``train.parquet`` (the first 60 %, 2820 samples),
``held_out.parquet`` (the last 1880) and ``aliengo.toml``, which names the URDF copied beside it and bounds the
continuous thighs by the log's range.

**The peer.** The same lab's identification of this robot (``robot_model/aliengo/isaaclab_identified_parameters.py``:
PACE, Bjelonic et al. 2025, https://github.com/leggedrobotics/pace-sim2real: CMA-ES over Isaac Lab rollouts of the
log) is read at run time (:func:`aliengo_peer`, :class:`~wbfriction.datasets.pace_peer.PeerActuator`) and written
beside the logs as a robot-TOML fragment, ``peer.toml`` (:func:`~wbfriction.datasets.pace_peer.peer_config`).

What the Aliengo shares with the Go2 (:mod:`~wbfriction.datasets.go2`) is in
:mod:`~wbfriction.datasets.hung_quadruped` (the log, its split, the TOML, the route) and
:mod:`~wbfriction.datasets.pace_peer` (the peer); the names this module had are imported here from there.
"""

from __future__ import annotations

from pathlib import Path

from wbfriction.datasets.dataset import register
from wbfriction.datasets.hung_quadruped import (
    COMMIT,
    LABELS,
    LEGS,
    LOGS,
    PARTS,
    QUADRUPED_JOINTS,
    REPOSITORY,
    SIGNALS,
    TRAIN_FRACTION,
    HungQuadrupedDataset,
    log_range,
    read_trajectory,
    split_rows,
    trajectory_table,
)
from wbfriction.datasets.pace_peer import PEER_STEP, PeerActuator
from wbfriction.datasets.pace_peer import read_peer as read_pace_peer
from wbfriction.datasets.store import RemoteFile
from wbfriction.datasets.torch_pickle import read_pt

URDF_REPOSITORY = "unitreerobotics/unitree_ros"
URDF_COMMIT = "fc15975b28a8b166302696ebb12081f1df8dfbed"
"""The commit (2022-11-16, "reconfirm Aliengo inertial params") that last changed the URDF."""

LOG_FILE, PEER_FILE, URDF_FILE = "aliengo_traj_0.pt", "aliengo_isaaclab_identified_parameters.txt", "aliengo.urdf"
ALIENGO_FILES = (
    RemoteFile(LOG_FILE, REPOSITORY, COMMIT, "datasets/aliengo/traj_0.pt",
               "fd58442b024056044d0c52a301251be30417d2a89cc61f98ef8e50783d14c772"),
    RemoteFile(PEER_FILE, REPOSITORY, COMMIT, "robot_model/aliengo/isaaclab_identified_parameters.py",
               "9d236ca96ff0db6959cb1fcd011b93b9efe59739b0520dc0289b8d3fa1d88e5a"),
    RemoteFile(URDF_FILE, URDF_REPOSITORY, URDF_COMMIT, "robots/aliengo_description/urdf/aliengo.urdf",
               "5d5e87e2db2c76b025eea255ebaac65b2fec5d2c241087c8b2fe57d40ea9b075"),
)
"""The log, the peer's identification and the URDF, each from a fixed commit, with their SHA-256 (named as in the
local copy's ``unitree_aliengo`` folder: the parameters file is Python source, stored as ``.txt``)."""

ALIENGO_JOINTS = QUADRUPED_JOINTS
"""The log's joints, in its column order (the URDF's names; the URDF lists the legs FR, FL, RR, RL)."""
CONTINUOUS = tuple(j for j in ALIENGO_JOINTS if "_thigh_" in j)
"""The joints the URDF leaves ``continuous`` (no position limits)."""


@register
class AliengoDataset(HungQuadrupedDataset):
    """The iit-DLSLab's Unitree Aliengo (module docstring)."""

    name = "aliengo"
    folder = "unitree_aliengo"
    summary = ("the iit-DLSLab's Unitree Aliengo: 23.5 s of triangle ramps on 12 PD-driven joints, hung, no torque "
               "sensor, 200 Hz, 1 MB")
    files = ALIENGO_FILES
    robot, model = "aliengo", "Aliengo"
    log_file, peer_file, urdf = LOG_FILE, PEER_FILE, URDF_FILE
    urdf_note = "beside this file (Unitree's unitree_ros)"
    continuous = CONTINUOUS


def read_peer(path: str | Path) -> PeerActuator:
    """The Aliengo peer's parameters file (:func:`~wbfriction.datasets.pace_peer.read_peer` over
    :data:`ALIENGO_JOINTS`).

    Raises:
        InputError: what ``pace_peer.read_peer`` raises, naming the file and key.
    """
    return read_pace_peer(path, ALIENGO_JOINTS)


def aliengo_peer(files: dict[str, Path] | None = None) -> PeerActuator:
    """The peer's identification (:meth:`~wbfriction.datasets.hung_quadruped.HungQuadrupedDataset.peer` of the
    dataset's parameters file; ``files``: the dataset's files by name, default fetched).

    Raises:
        InputError: a missing, damaged or undownloadable file; a file :func:`read_peer` refuses.
    """
    return AliengoDataset().peer(files)


__all__ = ["ALIENGO_FILES", "ALIENGO_JOINTS", "COMMIT", "CONTINUOUS", "LABELS", "LEGS", "LOGS", "LOG_FILE", "PARTS",
           "PEER_FILE", "PEER_STEP", "PeerActuator", "REPOSITORY", "SIGNALS", "TRAIN_FRACTION", "URDF_COMMIT",
           "URDF_FILE", "URDF_REPOSITORY", "AliengoDataset", "aliengo_peer", "log_range", "read_peer", "read_pt",
           "read_trajectory", "split_rows", "trajectory_table"]
