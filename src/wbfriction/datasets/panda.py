"""A Franka Emika Panda's excitation log (``wbfriction dataset panda``).

Gaz, Cognetti, Oliva, Robuffo Giordano and De Luca published the log of their Panda identification ("Dynamic
identification of the Franka Emika Panda robot with retrieval of feasible parameters using penalty-based
optimization", IEEE RA-L 2019; https://github.com/marcocognetti/FrankaEmikaPandaDynModel, GPL-3.0: downloaded from
there, never redistributed): 21 s of an excitation trajectory at about 1 kHz (steps of 0.7-8.8 ms as recorded),
joint positions [rad], velocities [rad/s] and the joint torque sensors' torques [N·m] (link side: the rotor and the
friction before the sensor are not in them). Four text files, one value a line, seven values a sample
(``panda_joint1`` ... ``panda_joint7``); one stamp a sample [s]. Their friction model is a sigmoid per joint
(:mod:`~wbfriction.datasets.reference`).

Written: ``excitation.parquet`` (``time``, ``q.<joint>``, ``qd.<joint>``, ``tau.<joint>``), the robot's description
``panda_arm.urdf`` and its configuration ``panda.toml`` (no armature: link-side torques). The description is
example-robot-data's Panda (the installed package's URDF, read at run time, Apache-2.0) **without its hand**: the
log was recorded with no end effector. Its links' inertias are Gaz et al.'s own identification (link 1's 4.970684
kg ...), which, with the published friction, predicts the log's torques to 0.07-0.60 N·m RMS per joint; with the
hand's 0.76 kg on the flange, to 0.06-2.96 N·m (elbow and shoulder 3.0 and 2.6), and the identification's
validation gives the arm alone 0.248 N·m of held-out RMS, the arm with the hand 1.32 (issue 52).
"""

from __future__ import annotations

import shlex
from pathlib import Path

import numpy as np
import pyarrow as pa
from lxml import etree as ET

from wbfriction.datasets.dataset import Dataset, WrittenDataset, register
from wbfriction.datasets.store import RemoteFile
from wbfriction.exceptions import InputError
from wbfriction.logs.tables import make_folder, write_atomic, write_table
from wbfriction.model.loading import example_robot_data_dir

REPOSITORY = "marcocognetti/FrankaEmikaPandaDynModel"
COMMIT = "24d85ce4e648e2e894c832bfeee9b16711eb1a1a"
"""The commit (2022-09-19, the repository's last) whose ``rbt_log`` files are the log (unchanged since 2019)."""
FOLDER = "matlab/data/Exciting_Traj/Trajectory_1/rbt_log"

PANDA_FILES = (
    RemoteFile("exciting_traj_time.txt", REPOSITORY, COMMIT, f"{FOLDER}/exciting_traj_time.txt",
               "031063612f297011dc005ab29830903e36f4bfeba77bce59c0fbde13620fb20d"),
    RemoteFile("exciting_traj_positions.txt", REPOSITORY, COMMIT, f"{FOLDER}/exciting_traj_positions.txt",
               "50bf82a082c439aff8220e8142985c8dd783f7ddc1415987cd75c9efb88bcf69"),
    RemoteFile("exciting_traj_velocity.txt", REPOSITORY, COMMIT, f"{FOLDER}/exciting_traj_velocity.txt",
               "3340f299e926c501b66d540fa461ea0a7184b8dda32e505ebed062db57860d49"),
    RemoteFile("exciting_traj_torques.txt", REPOSITORY, COMMIT, f"{FOLDER}/exciting_traj_torques.txt",
               "11fda32785bb29ce444e14e0f45f4893aab7142dc6ee29576d828ab154852f9c"),
)
"""The log's four files, from a fixed commit, with their SHA-256."""

PANDA_JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
"""The log's joints, in order (example-robot-data's names)."""
SIGNALS = (("q", "exciting_traj_positions.txt"), ("qd", "exciting_traj_velocity.txt"),
           ("tau", "exciting_traj_torques.txt"))
"""Column prefix -> the file of its values."""

CONFIG = """\
# Franka Emika's Panda on a fixed base, for the log of Gaz et al. 2019 (wbfriction dataset panda): the installed
# example-robot-data's description, nothing of it copied.
name = "panda_gaz2019"
urdf = "panda_arm.urdf"   # example-robot-data's Panda without its hand: the log has no end effector
floating_base = false

# The log holds the joint torque sensors' torques (link side): no armature, no torque constants.

[labels]
panda_joint1 = "A1 base yaw"
panda_joint2 = "A2 shoulder"
panda_joint3 = "A3 upper arm roll"
panda_joint4 = "A4 elbow"
panda_joint5 = "A5 forearm roll"
panda_joint6 = "A6 wrist"
panda_joint7 = "A7 flange roll"
"""
"""The configuration written beside the log."""


HAND_LINKS = ("panda_hand", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger")
"""The links of the Franka Hand in example-robot-data's Panda, not on the robot when the log was recorded."""
INSTALLED_URDF = "panda_description/urdf/panda.urdf"
"""The Panda's description in the installed example-robot-data package."""


def arm_urdf(source: Path) -> bytes:
    """The URDF ``source`` (example-robot-data's Panda) without the links of :data:`HAND_LINKS` and the joints that
    carry them: the arm as Gaz et al. recorded it (module docstring). Everything else as written (lxml keeps its
    comments and layout).

    Raises:
        InputError: a description that does not parse or has no such link.
    """
    try:
        tree = ET.parse(str(source))
    except (OSError, ET.XMLSyntaxError) as exc:
        raise InputError(f"{source}: cannot be read as a URDF ({exc})") from None
    root = tree.getroot()
    links = {link.get("name"): link for link in root.findall("link")}
    missing = [n for n in HAND_LINKS if n not in links]
    if missing:
        raise InputError(f"{source}: no link {', '.join(missing)} (not example-robot-data's Panda with its hand)")
    for joint in root.findall("joint"):
        child = joint.find("child")
        if child is not None and child.get("link") in HAND_LINKS:
            root.remove(joint)
    for name in HAND_LINKS:
        root.remove(links[name])
    return ET.tostring(tree, xml_declaration=True, encoding="utf-8")


def _values(path: Path) -> np.ndarray:
    try:
        return np.loadtxt(path, ndmin=1)
    except ValueError as exc:
        raise InputError(f"{path}: not one number a line ({' '.join(str(exc).split())})") from None


def read_panda_log(files: dict[str, Path]) -> pa.Table:
    """The dataset's four text files as a log table: ``time`` [s], ``q.<joint>`` [rad], ``qd.<joint>`` [rad/s],
    ``tau.<joint>`` [N·m].

    Raises:
        InputError: a file whose values are not seven a stamp, naming it and the counts.
    """
    time = _values(files["exciting_traj_time.txt"])
    columns: dict[str, np.ndarray] = {"time": time}
    for prefix, name in SIGNALS:
        values = _values(files[name])
        if values.size != len(PANDA_JOINTS) * time.size:
            raise InputError(f"{files[name]}: {values.size} values, expected {len(PANDA_JOINTS)} for each of the "
                             f"{time.size} stamps of {files['exciting_traj_time.txt'].name}")
        values = values.reshape(time.size, len(PANDA_JOINTS))
        columns |= {f"{prefix}.{j}": values[:, k] for k, j in enumerate(PANDA_JOINTS)}
    return pa.table(columns)


@register
class PandaDataset(Dataset):
    """The Panda of Gaz et al. (module docstring)."""

    name = "panda"
    folder = "panda"
    summary = "Gaz et al.'s Franka Panda: 21 s of excitation, link-side torque sensors at 1 kHz, about 9 MB"
    files = PANDA_FILES

    def write(self, directory: str | Path, files: dict[str, Path] | None = None) -> WrittenDataset:
        files = self.fetch() if files is None else files
        table = read_panda_log(files)
        folder = make_folder(directory)
        log, config, urdf = folder / "excitation.parquet", folder / "panda.toml", folder / "panda_arm.urdf"
        arm = arm_urdf(example_robot_data_dir() / INSTALLED_URDF)
        write_table(table, log)
        write_atomic(urdf, lambda tmp: tmp.write_bytes(arm))
        write_atomic(config, lambda tmp: tmp.write_text(CONFIG))
        q, robot = shlex.quote(str(log)), f"--config {shlex.quote(str(config))}"
        commands = (f"wbfriction identify {q} {robot} --armature none -o panda_identified.urdf "
                    "--config-output panda_identified.toml",
                    f"wbfriction estimate {q} --config panda_identified.toml -o panda_friction.parquet",
                    "wbfriction fit panda_friction.parquet -o panda_params.json")
        return WrittenDataset(self.name, {"train": log}, {"train": table.num_rows}, config, commands,
                              {"train": "the 21 s excitation"})
