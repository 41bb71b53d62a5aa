"""A Universal Robots UR10e's identification logs (``wbfriction dataset ur10e``).

Mamedov, Ozbek, Sarıyıldız and Çetin published the logs of their UR10e identification ("Practical aspects of
model-based collision detection", Frontiers in Robotics and AI, 2020; https://github.com/shamilmamedov/
dynamic_calibration, no licence file: the files are downloaded from there, never redistributed): the robot's
controller clock at about 100 Hz (steps of 10 and 12 ms, some of 2-16 ms), joint positions [rad] and velocities
[rad/s], and the motor currents [A]; their drive gains [N·m/A] turn a current into the joint torque, on the motor
side of the gear (the rotor's inertia is in it). Their identification (``UR10E_parameters.txt``): drive gains,
rotor inertias, the rigid-body parameters and, per joint, a Coulomb-viscous friction with an offset
(:mod:`~wbfriction.datasets.reference`).

Logs written (the CSV's 31 columns, no header: ``t``, ``q`` (6), ``qd`` (6), ``i`` (6), ``i_des`` (6),
``tau_des`` (6); the set-points are not written):

* ``excitation.parquet``: 50 s of 12 harmonics on every joint (``ur-20_02_12-50sec_12harm.csv``);
* ``joint1.parquet``: the shoulder pan swept alone for 63 s (``ur-20_01_22-joint_1.csv``), the other joints still:
  data no fit on the excitation saw.

Columns ``time``, ``q.<joint>``, ``qd.<joint>`` (the controller's) and ``current.<joint>``; the robot's
configuration ``ur10e.toml`` beside them names the URDF (their ``URe/urdf/ur10e.urdf``, no rotor inertias) and the
drive gains as ``[torque_constants]``.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.datasets.dataset import Dataset, WrittenDataset, register
from wbfriction.datasets.store import RemoteFile
from wbfriction.exceptions import InputError
from wbfriction.logs.tables import make_folder, write_atomic, write_table

REPOSITORY = "shamilmamedov/dynamic_calibration"
COMMIT = "11af40e7deb758ec080a175fed8fcdd6c99aca29"
"""The commit (2021-11-16, the repository's last) whose files are the dataset."""

UR10E_FILES = (
    RemoteFile("ur-20_02_12-50sec_12harm.csv", REPOSITORY, COMMIT,
               "dataset_ur10e/identification_data/ur-20_02_12-50sec_12harm.csv",
               "bb48cca42716a88f8b255d2d1b3eb3fa4a6eac4a9a52b694d4c1066ce8b4ca51"),
    RemoteFile("ur-20_01_22-joint_1.csv", REPOSITORY, COMMIT, "dataset_ur10e/jointwise_motion/ur-20_01_22-joint_1.csv",
               "29cbb22afa01aae4a7e2fedaf63d6df90ef98decb1ec74a9b4863d2bc4d5eda0"),
    RemoteFile("ur10e.urdf", REPOSITORY, COMMIT, "URe/urdf/ur10e.urdf",
               "0d2abc6ebc70725c691a35aa6c2d03fd6e8158017a1b7da7a10a3ef52de7b821"),
    RemoteFile("UR10E_parameters.txt", REPOSITORY, COMMIT, "UR10E_parameters.txt",
               "2c6be2d67d9b0512bd96936673caaedfba3fbc279fd7edde0b111df4b37bd677"),
)
"""The logs, the URDF and the authors' identification, from a fixed commit, with their SHA-256."""

UR10E_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
                "wrist_3_joint")
"""The CSV's joints, in order (the URDF's names)."""
LABELS = ("shoulder pan", "shoulder lift", "elbow", "wrist 1", "wrist 2", "wrist 3")
COLUMNS = 31
"""Columns of a log: t, q (6), qd (6), i (6), i_des (6), tau_des (6)."""
LOGS = {"train": ("ur-20_02_12-50sec_12harm.csv", "excitation.parquet", "the 50 s excitation"),
        "held_out": ("ur-20_01_22-joint_1.csv", "joint1.parquet", "the shoulder pan's sweep")}
"""Role -> (CSV, log written, what it is)."""


def read_parameters(path: Path) -> dict[str, np.ndarray]:
    """The arrays of the authors' ``UR10E_parameters.txt`` (``name = [v1 v2 ...]`` lines): ``drvGains`` (6)
    [N·m/A], ``pi_drvs`` (6) [kg·m²], ``pi_frcn`` (18: per joint F_v [N·m·s/rad], F_c [N·m], offset [N·m]),
    ``pi_rgd`` (60: per link Ixx Ixy Ixz Iyy Iyz Izz [kg·m²], m·c (3) [kg·m], m [kg]).

    Raises:
        InputError: a file without ``drvGains`` or a value that is not a number, naming the file.
    """
    out = {}
    for name, values in re.findall(r"^\s*(\w+)\s*=\s*\[([^\]]*)\]", path.read_text(encoding="utf-8"), re.M):
        try:
            out[name] = np.array([float(v) for v in values.split()])
        except ValueError as exc:
            raise InputError(f"{path}: {name}: {exc}") from None
    if out.get("drvGains", np.empty(0)).shape != (len(UR10E_JOINTS),):
        raise InputError(f"{path}: no drvGains of {len(UR10E_JOINTS)} values (the drive gains [N·m/A])")
    return out


def read_ur_log(path: Path) -> pa.Table:
    """One of the dataset's CSV logs (:data:`COLUMNS` columns, no header) as a log table: ``time`` [s, as
    recorded], ``q.<joint>`` [rad], ``qd.<joint>`` [rad/s] and ``current.<joint>`` [A].

    Raises:
        InputError: a file that is not a table of :data:`COLUMNS` numbers a row, naming it.
    """
    try:
        data = np.loadtxt(path, delimiter=",", ndmin=2)
    except ValueError as exc:
        raise InputError(f"{path}: not a CSV of numbers ({' '.join(str(exc).split())})") from None
    if data.shape[1] != COLUMNS:
        raise InputError(f"{path}: {data.shape[1]} columns, expected {COLUMNS} (t, q, qd, i, i_des, tau_des)")
    n = len(UR10E_JOINTS)
    columns: dict[str, np.ndarray] = {"time": data[:, 0]}
    for prefix, first in (("q", 1), ("qd", 1 + n), ("current", 1 + 2 * n)):
        columns |= {f"{prefix}.{j}": data[:, first + k] for k, j in enumerate(UR10E_JOINTS)}
    return pa.table(columns)


def robot_config(gains: np.ndarray, urdf: str) -> str:
    """The UR10e's configuration (TOML) naming ``urdf`` and the drive gains ``gains`` [N·m/A] as its torque
    constants."""
    lines = ["# A Universal Robots UR10e on a fixed base, for the logs of Mamedov et al. 2020 (wbfriction dataset",
             "# ur10e).",
             'name = "ur10e"', f'urdf = "{urdf}"   # beside this file', "floating_base = false", "",
             "# The log holds motor currents: the joint torque is the drive gain times the current, on the motor side",
             "# of the gear (the rotor's inertia is in it: 'wbfriction identify --armature identify' finds it).",
             "[torque_constants]   # the authors' drive gains [N·m/A] (UR10E_parameters.txt, drvGains)"]
    lines += [f"{j} = {float(g)!r}" for j, g in zip(UR10E_JOINTS, gains)]
    lines += ["", "[labels]"] + [f'{j} = "{label}"' for j, label in zip(UR10E_JOINTS, LABELS)]
    return "\n".join(lines) + "\n"


@register
class Ur10eDataset(Dataset):
    """The UR10e of Mamedov et al. (module docstring)."""

    name = "ur10e"
    folder = "ur10e"
    summary = "Mamedov et al.'s UR10e: a 50 s excitation and a 63 s joint sweep, motor currents at 100 Hz, 1 MB"
    files = UR10E_FILES

    def write(self, directory: str | Path, files: dict[str, Path] | None = None) -> WrittenDataset:
        files = self.fetch() if files is None else files
        gains = read_parameters(files["UR10E_parameters.txt"])["drvGains"]
        tables = {role: read_ur_log(files[csv]) for role, (csv, _, _) in LOGS.items()}
        folder = make_folder(directory)
        logs = {role: folder / LOGS[role][1] for role in LOGS}
        for role, table in tables.items():
            write_table(table, logs[role])
        urdf, config = folder / "ur10e.urdf", folder / "ur10e.toml"
        write_atomic(urdf, lambda tmp: tmp.write_bytes(files["ur10e.urdf"].read_bytes()))
        write_atomic(config, lambda tmp: tmp.write_text(robot_config(gains, urdf.name)))
        q = {role: shlex.quote(str(p)) for role, p in logs.items()}
        robot = f"--config {shlex.quote(str(config))}"
        commands = (f"wbfriction identify {q['train']} {robot} --armature identify -o ur10e_identified.urdf "
                    "--config-output ur10e_identified.toml",
                    f"wbfriction estimate {q['train']} --config ur10e_identified.toml -o excitation_friction.parquet",
                    "wbfriction fit excitation_friction.parquet -o ur10e_params.json",
                    f"wbfriction estimate {q['held_out']} --config ur10e_identified.toml -o joint1_friction.parquet",
                    "wbfriction predict joint1_friction.parquet --params ur10e_params.json")
        return WrittenDataset(self.name, logs, {r: t.num_rows for r, t in tables.items()}, config, commands,
                              {role: what for role, (_, _, what) in LOGS.items()})
