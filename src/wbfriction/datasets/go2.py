"""A Unitree Go2 hung with its base fixed, its joints PD-driven (``wbfriction dataset go2``).

The same lab and recording set-up as the Aliengo's (:mod:`~wbfriction.datasets.aliengo`; what they share:
:mod:`~wbfriction.datasets.hung_quadruped`): the iit-DLSLab's Go2 log (https://github.com/iit-DLSLab/
simple-robot-identification-isaaclab, BSD-3-Clause, ``datasets/go2/traj_0.pt``; downloaded from there, never
redistributed), the robot hung in the air, base fixed and level, every joint tracking triangle position ramps
under its motor driver's PD law (``kp`` 20 N·m/rad, ``kd`` 1.5 N·m·s/rad, as logged), 200 Hz, 4779 samples
(23.9 s). No torque is logged.

The URDF is example-robot-data's ``go2_description/urdf/go2.urdf`` (upstream Unitree's unitree_ros; the installed
package's, the built-in robot ``go2``'s: :func:`~wbfriction.model.loading.example_robot_data_dir`), named by the
TOML as ``example-robot-data:<path>``, never copied. Its joints ``FL_hip_joint`` ... ``RR_calf_joint`` are the log's,
in its order and sign convention; all revolute with limits (no ``continuous`` joint); its fixed rotor links add
their inertia to the links they hang on.

Logs written: ``train.parquet`` (the first 60 %, 2867 samples), ``held_out.parquet`` (the last 1912) and
``go2.toml``; ``peer.toml``, the same lab's PACE identification (``robot_model/go2/isaaclab_identified_parameters.py``:
per joint ``armature``, ``viscous_friction``, ``dynamic_friction`` (the Coulomb level), ``bias``; ``delay`` 1 step of
5 ms; ``Kp`` 20, ``Kd`` 1.5), read at run time (:func:`go2_peer`, :mod:`~wbfriction.datasets.pace_peer`). PACE
fitted it on the whole log: the held-out 40 % is held out from wbfriction's route only.
"""

from __future__ import annotations

from pathlib import Path

from wbfriction.datasets.dataset import register
from wbfriction.datasets.hung_quadruped import COMMIT, QUADRUPED_JOINTS, REPOSITORY, HungQuadrupedDataset
from wbfriction.datasets.pace_peer import PeerActuator
from wbfriction.datasets.store import RemoteFile

LOG_FILE, PEER_FILE = "go2_traj_0.pt", "go2_isaaclab_identified_parameters.txt"
GO2_FILES = (
    RemoteFile(LOG_FILE, REPOSITORY, COMMIT, "datasets/go2/traj_0.pt",
               "3a98be68c018d212d27f7fa2427d6b1591024d07da2dfa0380efc922072726d0"),
    RemoteFile(PEER_FILE, REPOSITORY, COMMIT, "robot_model/go2/isaaclab_identified_parameters.py",
               "b13caa6b46e866f01c2f338cd4c86d25c22691e27fc9b3a1a749a6120206ce40"),
)
"""The log and the peer's identification, from a fixed commit, with their SHA-256 (named as in the local copy's
``unitree_go2`` folder: the parameters file is Python source, stored as ``.txt``). The URDF is the installed
example-robot-data's (:data:`INSTALLED_URDF`), not a file of the dataset."""

INSTALLED_URDF = "example-robot-data:go2_description/urdf/go2.urdf"
"""The Go2's description as the TOML names it: the installed example-robot-data package's (the built-in ``go2``'s)."""
GO2_JOINTS = QUADRUPED_JOINTS
"""The log's joints, in its column order (the URDF's names and order)."""


@register
class Go2Dataset(HungQuadrupedDataset):
    """The iit-DLSLab's Unitree Go2 (module docstring)."""

    name = "go2"
    folder = "unitree_go2"
    summary = ("the iit-DLSLab's Unitree Go2: 23.9 s of triangle ramps on 12 PD-driven joints, hung, no torque "
               "sensor, 200 Hz, 1 MB")
    files = GO2_FILES
    robot, model = "go2", "Go2"
    log_file, peer_file, urdf = LOG_FILE, PEER_FILE, INSTALLED_URDF
    urdf_note = "the installed example-robot-data's, as the built-in go2's"


def go2_peer(files: dict[str, Path] | None = None) -> PeerActuator:
    """The peer's identification (:meth:`~wbfriction.datasets.hung_quadruped.HungQuadrupedDataset.peer` of the
    dataset's parameters file; ``files``: the dataset's files by name, default fetched).

    Raises:
        InputError: a missing, damaged or undownloadable file; a file the peer's reader refuses.
    """
    return Go2Dataset().peer(files)


__all__ = ["GO2_FILES", "GO2_JOINTS", "INSTALLED_URDF", "LOG_FILE", "PEER_FILE", "Go2Dataset", "go2_peer"]
