"""The iit-DLSLab's hung quadrupeds: a Unitree robot with its base fixed, its joints PD-driven, and the lab's peer.

The iit-DLSLab published the logs of their quadrupeds' identification (https://github.com/iit-DLSLab/
simple-robot-identification-isaaclab, BSD-3-Clause; the files are downloaded from there, never redistributed): each
robot hung in the air, base fixed and level, every joint tracking triangle position ramps under its motor driver's
PD law, 200 Hz, about 24 s. No torque is logged (no joint torque sensor): the log holds the encoder's angles, the
driver's own velocities and the set-points. ``datasets/<robot>/traj_0.pt`` is a PyTorch zip-pickle, read here
without torch (:func:`~wbfriction.datasets.torch_pickle.read_pt`). One :class:`HungQuadrupedDataset` subclass a robot:
:mod:`~wbfriction.datasets.aliengo`, :mod:`~wbfriction.datasets.go2`.

Logs written (``traj_0.pt``'s dict: ``time`` (N) [s, a linspace], ``dof_pos``, ``dof_vel``, ``des_dof_pos``,
``des_dof_vel`` (N×12) [rad, rad/s], ``kp``, ``kd`` (12); joints FL_hip, FL_thigh, FL_calf, FR_..., RL_..., RR_...,
the URDF's ``<name>_joint`` (:data:`QUADRUPED_JOINTS`), mapped by name):

* ``train.parquet``: the first 60 % of the samples;
* ``held_out.parquet``: the rest (fit on the first, predict the second).

Columns ``time``, ``q.<joint>`` (the encoder), ``qd.<joint>`` (the driver's velocity), ``q_des.<joint>`` and
``qd_des.<joint>`` (zeros, as logged); the robot's configuration ``<robot>.toml`` beside them names the URDF (a file
of the dataset copied beside it, or the installed example-robot-data's), a fixed base, the drivers' ``[pd]`` gains
from the log and the joints' labels.

**The peer.** The same lab's identification of each robot (``robot_model/<robot>/isaaclab_identified_parameters.py``:
PACE, :mod:`~wbfriction.datasets.pace_peer`) is read at run time (:meth:`HungQuadrupedDataset.peer`) and written
beside the logs as a robot-TOML fragment, ``peer.toml``.
"""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import ClassVar

import numpy as np
import pyarrow as pa

from wbfriction.datasets.dataset import Dataset, WrittenDataset
from wbfriction.datasets.pace_peer import PeerActuator, peer_config, read_peer
from wbfriction.datasets.torch_pickle import read_pt
from wbfriction.exceptions import InputError
from wbfriction.logs.tables import make_folder, write_atomic, write_table

REPOSITORY = "iit-DLSLab/simple-robot-identification-isaaclab"
COMMIT = "5b3aa99460562bc042640c599ed08ed3272131f4"
"""The commit (2026-05-14, "added info of the gain used to obtain identification isaaclab") whose logs and
identifications are the datasets (the Aliengo's log is unchanged since eab38ab, 2026-04-22)."""

LEGS = ("FL", "FR", "RL", "RR")
PARTS = ("hip", "thigh", "calf")
QUADRUPED_JOINTS = tuple(f"{leg}_{part}_joint" for leg in LEGS for part in PARTS)
"""The logs' joints, in their column order (the URDFs' names; PACE's ``joint_order``)."""
LABELS = {f"{leg}_{part}_joint": f"{side} {part}" for leg, side in zip(LEGS, ("front left", "front right",
                                                                            "rear left", "rear right"))
          for part in PARTS}
SIGNALS = {"q": "dof_pos", "qd": "dof_vel", "q_des": "des_dof_pos", "qd_des": "des_dof_vel"}
"""Log column prefix -> the .pt's key (N×12)."""
TRAIN_FRACTION = 0.6
"""The first 60 % of the samples is ``train``, the rest ``held_out``."""
LOGS = {"train": ("train.parquet", "the first 60 %"), "held_out": ("held_out.parquet", "the last 40 %, held out")}
"""Role -> (log written, what it is)."""


# ----------------------------------------------------------------------------------------------------- the log
def read_trajectory(path: str | Path) -> dict[str, np.ndarray]:
    """A hung quadruped's log (``traj_0.pt``): ``time`` (N,) [s]; ``dof_pos``, ``dof_vel``, ``des_dof_pos``,
    ``des_dof_vel`` (N, 12) [rad, rad/s] in :data:`QUADRUPED_JOINTS` order; ``kp``, ``kd`` (12,) [N·m/rad,
    N·m·s/rad]; all float64.

    Raises:
        InputError: what :func:`~wbfriction.datasets.torch_pickle.read_pt` raises; a key missing, an array of
            another shape, a value that is not finite, stamps that do not increase, naming the file and the key.
    """
    doc = read_pt(path)
    n_joints = len(QUADRUPED_JOINTS)
    if "time" not in doc:
        raise InputError(f"{path}: no 'time' (keys: {', '.join(doc)})")
    n = len(doc["time"])
    shapes = {"time": (n,), **dict.fromkeys(SIGNALS.values(), (n, n_joints)), "kp": (n_joints,),
              "kd": (n_joints,)}
    out = {}
    for key, shape in shapes.items():
        if key not in doc:
            raise InputError(f"{path}: no '{key}' (keys: {', '.join(doc)})")
        value = np.asarray(doc[key], dtype=float)
        if key in ("kp", "kd") and value.shape == (1, n_joints):
            value = value[0]
        if value.shape != shape:
            raise InputError(f"{path}: '{key}' has shape {value.shape}, expected {shape}")
        if not np.all(np.isfinite(value)):
            raise InputError(f"{path}: '{key}' holds values that are not finite")
        out[key] = value
    if n < 2 or np.any(np.diff(out["time"]) <= 0):
        raise InputError(f"{path}: 'time' does not increase")
    return out


def trajectory_table(trajectory: dict[str, np.ndarray], rows: slice = slice(None)) -> pa.Table:
    """Rows ``rows`` of :func:`read_trajectory`'s log as a log table: ``time`` [s, as recorded] and, per joint of
    :data:`QUADRUPED_JOINTS`, ``q.<joint>``, ``qd.<joint>``, ``q_des.<joint>``, ``qd_des.<joint>``."""
    columns: dict[str, np.ndarray] = {"time": trajectory["time"][rows]}
    for prefix, key in SIGNALS.items():
        columns |= {f"{prefix}.{j}": trajectory[key][rows, k] for k, j in enumerate(QUADRUPED_JOINTS)}
    return pa.table(columns)


def split_rows(n: int) -> tuple[slice, slice]:
    """The ``train`` (the first :data:`TRAIN_FRACTION` of ``n`` samples, rounded down) and ``held_out`` rows."""
    k = int(n * TRAIN_FRACTION)
    return slice(0, k), slice(k, n)


def log_range(trajectory: dict[str, np.ndarray], joints: tuple[str, ...]) -> dict[str, tuple[float, float]]:
    """The range [rad] the log's angles and set-points cover, per joint of ``joints``, rounded outward to 0.01 rad."""
    both = np.vstack([trajectory["dof_pos"], trajectory["des_dof_pos"]])
    return {j: (float(np.floor(both[:, k].min() * 100) / 100), float(np.ceil(both[:, k].max() * 100) / 100))
            for j in joints for k in [QUADRUPED_JOINTS.index(j)]}


# ---------------------------------------------------------------------------------------------------- the robot
def _gains_toml(key: str, values: np.ndarray, unit: str) -> list[str]:
    if np.all(values == values[0]):
        return [f"{key} = {float(values[0])!r}   # [{unit}], every joint (the log's '{key}')"]
    table = ", ".join(f"{j} = {float(v)!r}" for j, v in zip(QUADRUPED_JOINTS, values))
    return [f"{key} = {{ {table} }}   # [{unit}] (the log's '{key}')"]


def robot_config(name: str, model: str, kp: np.ndarray, kd: np.ndarray, urdf: str, urdf_note: str,
                 angle_limits: dict[str, tuple[float, float]] | None = None) -> str:
    """A hung quadruped's configuration (TOML): its ``name``, ``urdf`` (a path beside the TOML or
    ``example-robot-data:<path>``; ``urdf_note`` its comment), a fixed base, the drivers' gains ``kp`` [N·m/rad] and
    ``kd`` [N·m·s/rad] (one number when every joint has the same, else a table), no delay, the joints' groups
    (``hip``, ``thigh``, ``calf``: a real driver's noise, :data:`~wbfriction.sim.pd_options.REAL_DRIVER`, is given per
    group), labels, and ``angle_limits`` (joint -> [lower, upper] [rad]) for the joints the URDF leaves continuous.
    ``model`` is Unitree's model, named in the header (``"Aliengo"``)."""
    lines = [f"# A Unitree {model} hung with its base fixed and level, its joints PD-driven, for the iit-DLSLab log",
             f"# (wbfriction dataset {name}).",
             f'name = "{name}"', f'urdf = "{urdf}"   # {urdf_note}',
             "floating_base = false", "",
             "# No torque sensor: each motor driver applies tau = kp (q_des - q) + kd (qd_des - qd), clipped at the",
             "# URDF's effort limits, on its encoder's angle q and its own velocity qd (the log's columns).",
             "[pd]"]
    lines += _gains_toml("kp", kp, "N·m/rad") + _gains_toml("kd", kd, "N·m·s/rad")
    lines += ["delay = 0.0   # [s]: 'wbfriction identify --actuator pd' finds it", "", "[groups]"]
    for part in PARTS:
        members = ", ".join(f'"{j}"' for j in QUADRUPED_JOINTS if f"_{part}_" in j)
        lines.append(f"{part} = [{members}]")
    lines += ["", "[labels]"]
    lines += [f'{j} = "{LABELS[j]}"' for j in QUADRUPED_JOINTS]
    if angle_limits:
        lines += ["", "# The URDF leaves these joints continuous: their limits are the range the log moved them",
                  "# through (a design, 'wbfriction excite', stays within it)", "[angle_limits]"]
        lines += [f"{j} = [{lo:g}, {hi:g}]" for j, (lo, hi) in angle_limits.items()]
    return "\n".join(lines) + "\n"


# -------------------------------------------------------------------------------------------------- the dataset
class HungQuadrupedDataset(Dataset):
    """An iit-DLSLab hung quadruped (module docstring): its log split 60/40, the robot's TOML, the peer's fragment,
    and the PD route as the commands a user runs next.

    Subclasses set :class:`~wbfriction.datasets.dataset.Dataset`'s class attributes and these.
    """

    robot: ClassVar[str]
    """The robot's name: the TOML's ``name``, its file (``<robot>.toml``) and the route's files' stem."""
    model: ClassVar[str]
    """Unitree's model, as a sentence names it (``"Aliengo"``)."""
    log_file: ClassVar[str]
    """The log's file (one of :attr:`files`)."""
    peer_file: ClassVar[str]
    """The peer's parameters file (one of :attr:`files`)."""
    urdf: ClassVar[str]
    """The robot's description: one of :attr:`files` (copied beside the TOML) or an installed one
    (``example-robot-data:<path>``, which the TOML names as is)."""
    urdf_note: ClassVar[str]
    """The TOML's comment on its ``urdf`` (where the description comes from)."""
    continuous: ClassVar[tuple[str, ...]] = ()
    """The joints the URDF leaves ``continuous`` (no position limits): the TOML bounds them by the log's range."""

    def peer(self, files: dict[str, Path] | None = None) -> PeerActuator:
        """The peer's identification (:func:`~wbfriction.datasets.pace_peer.read_peer` of :attr:`peer_file`;
        ``files``: the dataset's files by name, default fetched).

        Raises:
            InputError: a missing, damaged or undownloadable file; a file ``read_peer`` refuses.
        """
        files = self.fetch() if files is None else files
        return read_peer(files[self.peer_file], QUADRUPED_JOINTS)

    def write(self, directory: str | Path, files: dict[str, Path] | None = None) -> WrittenDataset:
        files = self.fetch() if files is None else files
        trajectory = read_trajectory(files[self.log_file])
        peer = self.peer(files)
        rows = dict(zip(LOGS, split_rows(len(trajectory["time"]))))
        tables = {role: trajectory_table(trajectory, rows[role]) for role in LOGS}
        folder = make_folder(directory)
        logs = {role: folder / LOGS[role][0] for role in LOGS}
        for role, table in tables.items():
            write_table(table, logs[role])
        urdf, config = self.urdf, folder / f"{self.robot}.toml"
        if urdf in {f.name for f in self.files}:  # the dataset's own description, copied beside the TOML
            write_atomic(folder / urdf, lambda tmp: tmp.write_bytes(files[urdf].read_bytes()))
        text = robot_config(self.robot, self.model, trajectory["kp"], trajectory["kd"], urdf, self.urdf_note,
                            log_range(trajectory, self.continuous))
        write_atomic(config, lambda tmp: tmp.write_text(text))
        source = next(f for f in self.files if f.name == self.peer_file)
        fragment = peer_config(peer, self.model, config.name, source)
        write_atomic(folder / "peer.toml", lambda tmp: tmp.write_text(fragment))
        return WrittenDataset(self.name, logs, {r: t.num_rows for r, t in tables.items()}, config,
                              self.commands(logs, config), {role: what for role, (_, what) in LOGS.items()})

    def commands(self, logs: dict[str, Path], config: Path) -> tuple[str, ...]:
        """What a user runs next on the logs written (``logs`` by role, ``config`` the robot's TOML): the PD route
        (identify the drivers and the robot, estimate on the momentum route, fit, predict the held-out log, export,
        refine the export on its own replay of the training log), one command a line, quoted for a POSIX shell."""
        q = {role: shlex.quote(str(p)) for role, p in logs.items()}
        r = self.robot
        return (f"wbfriction identify {q['train']} --config {shlex.quote(str(config))} --actuator pd "
                f"--config-output {r}_identified.toml --json {r}_actuator.json",
                f"wbfriction estimate {q['train']} --config {r}_identified.toml --route momentum "
                "-o train_friction.parquet",
                f"wbfriction fit train_friction.parquet -o {r}_params.json",
                f"wbfriction estimate {q['held_out']} --config {r}_identified.toml --route momentum "
                "-o held_out_friction.parquet",
                f"wbfriction predict held_out_friction.parquet --params {r}_params.json",
                # no F_v of this log is ok: what the drivers' delay holds back is not told, and F_v carries
                # kp delay (issue 63); the simulator takes the pair written, each fit's status in a comment
                f"wbfriction export {r}_params.json --config {r}_identified.toml --include weak,at-bound "
                f"-o {r}_isaac.yaml -o {r}.xml",
                # the exported MJCF refined on its own replay of the training log, checked on the held-out one
                f"wbfriction refine {q['train']} {r}.xml --config {r}_identified.toml "
                f"-o {r}_refined.xml --held-out {q['held_out']}")
