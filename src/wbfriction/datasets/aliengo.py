"""A Unitree Aliengo hung with its base fixed, its joints PD-driven (``wbfriction dataset aliengo``).

The iit-DLSLab published the log of their Aliengo identification (https://github.com/iit-DLSLab/
simple-robot-identification-isaaclab, BSD-3-Clause; the files are downloaded from there, never redistributed):
the robot hung in the air, base fixed and level, every joint tracking triangle position ramps under its motor
driver's PD law (``kp`` 25 N·m/rad, ``kd`` 0.5 N·m·s/rad), 200 Hz, 23.5 s. No torque is logged (the Aliengo has no
joint torque sensor): the log holds the encoder's angles, the driver's own velocities and the set-points.
``datasets/aliengo/traj_0.pt`` is a PyTorch zip-pickle, read here without torch (:func:`read_pt`). The URDF is
Unitree's (https://github.com/unitreerobotics/unitree_ros, ``robots/aliengo_description/urdf/aliengo.urdf``; its
thigh joints are ``continuous``).

Logs written (``traj_0.pt``'s dict: ``time`` (N) [s, a linspace], ``dof_pos``, ``dof_vel``, ``des_dof_pos``,
``des_dof_vel`` (N×12) [rad, rad/s], ``kp``, ``kd`` (12); joints FL_hip, FL_thigh, FL_calf, FR_..., RL_..., RR_...,
the URDF's ``<name>_joint``, mapped by name):

* ``train.parquet``: the first 60 % of the samples;
* ``held_out.parquet``: the rest (fit on the first, predict the second).

Columns ``time``, ``q.<joint>`` (the encoder), ``qd.<joint>`` (the driver's velocity), ``q_des.<joint>`` and
``qd_des.<joint>`` (zeros, as logged); the robot's configuration ``aliengo.toml`` beside them names the URDF (copied
beside it), a fixed base, the drivers' ``[pd]`` gains from the log and the joints' labels.

**The peer.** The same lab's identification of this robot (``robot_model/aliengo/isaaclab_identified_parameters.py``:
PACE, Bjelonic et al. 2025, https://github.com/leggedrobotics/pace-sim2real: CMA-ES over Isaac Lab rollouts of the
log) is read at run time (:func:`aliengo_peer`, :class:`PeerActuator`) and written beside the logs as a robot-TOML
fragment, ``peer.toml`` (:func:`peer_config`).
"""

from __future__ import annotations

import ast
import collections
import pickle
import re
import shlex
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from wbfriction.datasets.dataset import Dataset, WrittenDataset, register
from wbfriction.datasets.store import RemoteFile
from wbfriction.exceptions import InputError
from wbfriction.logs.tables import make_folder, write_atomic, write_table

REPOSITORY = "iit-DLSLab/simple-robot-identification-isaaclab"
COMMIT = "5b3aa99460562bc042640c599ed08ed3272131f4"
"""The commit (2026-05-14, "added info of the gain used to obtain identification isaaclab") whose log and
identification are the dataset (the log is unchanged since eab38ab, 2026-04-22)."""
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

LEGS = ("FL", "FR", "RL", "RR")
PARTS = ("hip", "thigh", "calf")
ALIENGO_JOINTS = tuple(f"{leg}_{part}_joint" for leg in LEGS for part in PARTS)
"""The log's joints, in its column order (the URDF's names; the URDF lists the legs FR, FL, RR, RL)."""
LABELS = {f"{leg}_{part}_joint": f"{side} {part}" for leg, side in zip(LEGS, ("front left", "front right",
                                                                            "rear left", "rear right"))
          for part in PARTS}
SIGNALS = {"q": "dof_pos", "qd": "dof_vel", "q_des": "des_dof_pos", "qd_des": "des_dof_vel"}
"""Log column prefix -> the .pt's key (N×12)."""
TRAIN_FRACTION = 0.6
"""The first 60 % of the samples is ``train``, the rest ``held_out``."""
PEER_STEP = 0.005
"""The peer's simulation step [s]: ``sim.dt = 0.005`` with ``decimation = 1`` (its
``sysid_isaaclab/tasks/aliengo_pace_env_cfg.py``, lines 150-151): one physics step = one control step = one log
sample (``my_fit.py`` steps the simulation once per sample); its delay counts these steps."""


# ----------------------------------------------------------------------------------------- the .pt, without torch
_STORAGES = {"DoubleStorage": "f8", "FloatStorage": "f4", "HalfStorage": "f2", "LongStorage": "i8",
             "IntStorage": "i4", "ShortStorage": "i2", "CharStorage": "i1", "ByteStorage": "u1", "BoolStorage": "?"}
"""torch's typed storages -> NumPy's type codes (the storage's bytes are these, in the file's byte order)."""


@dataclass(frozen=True)
class _StorageType:
    dtype: str


@dataclass(frozen=True)
class _Storage:
    values: np.ndarray  # 1-D, the storage's elements


def _rebuild_tensor(storage: _Storage, offset: int, size: tuple[int, ...], stride: tuple[int, ...],
                    requires_grad: bool = False, hooks: object = None, metadata: object = None) -> np.ndarray:
    """``torch._utils._rebuild_tensor_v2`` as NumPy: the view ``size``/``stride`` [elements] at ``offset`` of the
    storage, copied."""
    if not isinstance(storage, _Storage):
        raise ValueError(f"a tensor whose storage is a {type(storage).__name__}")
    size, stride = tuple(int(s) for s in size), tuple(int(s) for s in stride)
    if len(size) != len(stride) or any(s < 0 for s in size + stride) or offset < 0:
        raise ValueError(f"a tensor of size {size}, stride {stride}, offset {offset}")
    if 0 in size:
        return np.empty(size, dtype=storage.values.dtype)
    last = offset + sum((n - 1) * s for n, s in zip(size, stride))
    if last >= storage.values.size:
        raise ValueError(f"a tensor of size {size}, stride {stride}, offset {offset} beyond its storage of "
                         f"{storage.values.size} elements")
    item = storage.values.itemsize
    view = np.lib.stride_tricks.as_strided(storage.values[offset:], shape=size, strides=[s * item for s in stride],
                                           writeable=False)
    return np.array(view)


class _Dtype:
    """``numpy.dtype(code, align, copy)`` of a number type; its pickled state sets the byte order."""

    def __init__(self, code: object, align: object = False, copy: object = True) -> None:
        dtype = np.dtype(str(code))
        if dtype.kind not in "biufc":
            raise ValueError(f"a NumPy array of type {code!r} (only numbers are read)")
        self.dtype = dtype

    def __setstate__(self, state: tuple) -> None:
        if isinstance(state, tuple) and len(state) > 1 and state[1] in ("<", ">"):
            self.dtype = self.dtype.newbyteorder(state[1])


class _Array:
    """``numpy.core.multiarray._reconstruct(ndarray, ...)``: an array built from its pickled state."""

    def __init__(self, cls: object, shape: object = (0,), code: object = b"b") -> None:
        if cls is not _NDARRAY:
            raise ValueError("a NumPy object that is not an ndarray")
        self.array = np.empty(0)

    def __setstate__(self, state: tuple) -> None:
        _, shape, dtype, fortran, raw = state
        if not isinstance(dtype, _Dtype) or not isinstance(raw, bytes):
            raise ValueError("a NumPy array that is not of numbers")
        shape = tuple(int(n) for n in shape)
        values = np.frombuffer(raw, dtype=dtype.dtype)
        if values.size != int(np.prod(shape)):
            raise ValueError(f"a NumPy array of shape {shape} holding {values.size} values")
        self.array = values.reshape(shape, order="F" if fortran else "C").astype(dtype.dtype.newbyteorder("="))


_NDARRAY = object()


def _latin1(text: object, encoding: object = "utf-8") -> bytes:
    """``_codecs.encode(text, "latin1")``: how a pickle of protocol 2 stores bytes."""
    if not isinstance(text, str) or encoding != "latin1":
        raise ValueError(f"_codecs.encode of a {type(text).__name__} as {encoding!r}")
    return text.encode("latin1")


_ALLOWED: dict[tuple[str, str], object] = {
    ("torch._utils", "_rebuild_tensor_v2"): _rebuild_tensor,
    ("collections", "OrderedDict"): collections.OrderedDict,  # a tensor's (empty) backward hooks
    ("numpy.core.multiarray", "_reconstruct"): _Array,
    ("numpy._core.multiarray", "_reconstruct"): _Array,
    ("numpy", "ndarray"): _NDARRAY,
    ("numpy", "dtype"): _Dtype,
    ("_codecs", "encode"): _latin1,
} | {("torch", name): _StorageType(code) for name, code in _STORAGES.items()}
"""The only globals a .pt may name (anything else is refused): tensors, their storages, NumPy arrays of numbers."""


class _PtUnpickler(pickle.Unpickler):
    """A restricted unpickler of a torch zip-pickle: tensors from the archive's raw storages (``<root>/data/<key>``),
    NumPy arrays of numbers; no other global."""

    def __init__(self, archive: zipfile.ZipFile, root: str, order: str) -> None:
        super().__init__(archive.open(f"{root}/data.pkl"))
        self.archive, self.root, self.order = archive, root, order
        self.storages: dict[str, _Storage] = {}

    def find_class(self, module: str, name: str) -> Any:
        try:
            return _ALLOWED[(module, name)]
        except KeyError:
            raise pickle.UnpicklingError(f"it names {module}.{name}, which is not read (only tensors and arrays "
                                         "of numbers)") from None

    def persistent_load(self, pid: Any) -> _Storage:
        if not (isinstance(pid, tuple) and len(pid) == 5 and pid[0] == "storage"
                and isinstance(pid[1], _StorageType)):
            raise pickle.UnpicklingError(f"a persistent id {pid!r:.60} that is not a storage")
        _, kind, key, _, numel = pid
        key = str(key)
        if key not in self.storages:
            dtype = np.dtype(kind.dtype).newbyteorder(self.order)
            raw = self.archive.read(f"{self.root}/data/{key}")
            if len(raw) != int(numel) * dtype.itemsize:
                raise pickle.UnpicklingError(f"storage {key}: {len(raw)} bytes, expected {numel} of {dtype.itemsize}")
            self.storages[key] = _Storage(np.frombuffer(raw, dtype=dtype).astype(dtype.newbyteorder("=")))
        return self.storages[key]


def read_pt(path: str | Path) -> dict[str, np.ndarray]:
    """A PyTorch zip-pickle (``torch.save`` of a dict of tensors and NumPy arrays) read without torch.

    The archive holds ``<root>/data.pkl`` (the pickle), ``<root>/byteorder`` (``little`` or ``big``; little when
    missing) and each storage's raw elements in ``<root>/data/<key>``. The pickle is read by a restricted unpickler:
    the only globals it may name are ``torch._utils._rebuild_tensor_v2``, torch's typed storages
    (``torch.FloatStorage``, ...), ``collections.OrderedDict`` and NumPy's array reconstruction of number types,
    each mapped to a function of this module; nothing else is imported or called.

    Returns:
        The dict's entries as NumPy arrays (a tensor's shape and strides honoured, its values copied; native
        byte order).

    Raises:
        InputError: a file that is not a zip archive, has no ``data.pkl``, names another global, a storage the
            archive lacks or of the wrong size, a view beyond its storage, or is not a dict of arrays, naming
            the file.
    """
    path = Path(path)
    try:
        with zipfile.ZipFile(path) as archive:
            pickles = [n for n in archive.namelist() if n.count("/") == 1 and n.endswith("/data.pkl")]
            if len(pickles) != 1:
                raise InputError(f"{path}: not a PyTorch zip-pickle (no <name>/data.pkl in the archive)")
            root = pickles[0].rsplit("/", 1)[0]
            order = {"little": "<", "big": ">"}.get(_entry(archive, f"{root}/byteorder", "little"))
            if order is None:
                raise InputError(f"{path}: not a PyTorch zip-pickle (byteorder is neither little nor big)")
            doc = _PtUnpickler(archive, root, order).load()
    except InputError:
        raise
    except (zipfile.BadZipFile, pickle.UnpicklingError, EOFError, KeyError, ValueError, TypeError, AttributeError,
            IndexError, OSError) as exc:
        raise InputError(f"{path}: not a readable PyTorch zip-pickle ({type(exc).__name__}: "
                         f"{' '.join(str(exc).split())})") from None
    if not isinstance(doc, dict):
        raise InputError(f"{path}: a PyTorch zip-pickle of a {type(doc).__name__}, expected a dict of tensors")
    out = {}
    for key, value in doc.items():
        value = value.array if isinstance(value, _Array) else value
        if not isinstance(value, np.ndarray):
            raise InputError(f"{path}: '{key}' is a {type(value).__name__}, expected a tensor or an array")
        out[str(key)] = value
    return out


def _entry(archive: zipfile.ZipFile, name: str, default: str) -> str:
    try:
        return archive.read(name).decode("ascii").strip()
    except KeyError:
        return default


# ----------------------------------------------------------------------------------------------------- the log
def read_trajectory(path: str | Path) -> dict[str, np.ndarray]:
    """The Aliengo's log (``traj_0.pt``): ``time`` (N,) [s]; ``dof_pos``, ``dof_vel``, ``des_dof_pos``,
    ``des_dof_vel`` (N, 12) [rad, rad/s] in :data:`ALIENGO_JOINTS` order; ``kp``, ``kd`` (12,) [N·m/rad,
    N·m·s/rad]; all float64.

    Raises:
        InputError: what :func:`read_pt` raises; a key missing, an array of another shape, a value that is not
            finite, stamps that do not increase, naming the file and the key.
    """
    doc = read_pt(path)
    n_joints = len(ALIENGO_JOINTS)
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
    :data:`ALIENGO_JOINTS`, ``q.<joint>``, ``qd.<joint>``, ``q_des.<joint>``, ``qd_des.<joint>``."""
    columns: dict[str, np.ndarray] = {"time": trajectory["time"][rows]}
    for prefix, key in SIGNALS.items():
        columns |= {f"{prefix}.{j}": trajectory[key][rows, k] for k, j in enumerate(ALIENGO_JOINTS)}
    return pa.table(columns)


def split_rows(n: int) -> tuple[slice, slice]:
    """The ``train`` (the first :data:`TRAIN_FRACTION` of ``n`` samples, rounded down) and ``held_out`` rows."""
    k = int(n * TRAIN_FRACTION)
    return slice(0, k), slice(k, n)


def _gains_toml(key: str, values: np.ndarray, unit: str) -> list[str]:
    if np.all(values == values[0]):
        return [f"{key} = {float(values[0])!r}   # [{unit}], every joint (the log's '{key}')"]
    table = ", ".join(f"{j} = {float(v)!r}" for j, v in zip(ALIENGO_JOINTS, values))
    return [f"{key} = {{ {table} }}   # [{unit}] (the log's '{key}')"]


CONTINUOUS = tuple(j for j in ALIENGO_JOINTS if "_thigh_" in j)
"""The joints the URDF leaves ``continuous`` (no position limits)."""


def log_range(trajectory: dict[str, np.ndarray], joints: tuple[str, ...]) -> dict[str, tuple[float, float]]:
    """The range [rad] the log's angles and set-points cover, per joint of ``joints``, rounded outward to 0.01 rad."""
    both = np.vstack([trajectory["dof_pos"], trajectory["des_dof_pos"]])
    return {j: (float(np.floor(both[:, k].min() * 100) / 100), float(np.ceil(both[:, k].max() * 100) / 100))
            for j in joints for k in [ALIENGO_JOINTS.index(j)]}


def robot_config(kp: np.ndarray, kd: np.ndarray, urdf: str,
                 angle_limits: dict[str, tuple[float, float]] | None = None) -> str:
    """The Aliengo's configuration (TOML): ``urdf``, a fixed base, the drivers' gains ``kp`` [N·m/rad] and ``kd``
    [N·m·s/rad] (one number when every joint has the same, else a table), no delay, the joints' groups (``hip``,
    ``thigh``, ``calf``: a real driver's noise, :data:`~wbfriction.sim.pd_options.REAL_DRIVER`, is given per group),
    labels, and ``angle_limits`` (joint -> [lower, upper] [rad]) for the joints the URDF leaves continuous."""
    lines = ["# A Unitree Aliengo hung with its base fixed and level, its joints PD-driven, for the iit-DLSLab log",
             "# (wbfriction dataset aliengo).",
             'name = "aliengo"', f'urdf = "{urdf}"   # beside this file (Unitree\'s unitree_ros)',
             "floating_base = false", "",
             "# No torque sensor: each motor driver applies tau = kp (q_des - q) + kd (qd_des - qd), clipped at the",
             "# URDF's effort limits, on its encoder's angle q and its own velocity qd (the log's columns).",
             "[pd]"]
    lines += _gains_toml("kp", kp, "N·m/rad") + _gains_toml("kd", kd, "N·m·s/rad")
    lines += ["delay = 0.0   # [s]: 'wbfriction identify --actuator pd' finds it", "", "[groups]"]
    for part in PARTS:
        members = ", ".join(f'"{j}"' for j in ALIENGO_JOINTS if f"_{part}_" in j)
        lines.append(f"{part} = [{members}]")
    lines += ["", "[labels]"]
    lines += [f'{j} = "{LABELS[j]}"' for j in ALIENGO_JOINTS]
    if angle_limits:
        lines += ["", "# The URDF leaves these joints continuous: their limits are the range the log moved them",
                  "# through (a design, 'wbfriction excite', stays within it)", "[angle_limits]"]
        lines += [f"{j} = [{lo:g}, {hi:g}]" for j, (lo, hi) in angle_limits.items()]
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------------------------------- the peer
@dataclass(frozen=True)
class PeerActuator:
    """The iit-DLSLab identification of this Aliengo (PACE: CMA-ES over Isaac Lab rollouts of the log), as its
    file gives it, per joint name (:data:`ALIENGO_JOINTS`).

    Attributes:
        armature: reflected rotor inertia [kg·m²] (Isaac Lab's joint armature: added to the mass matrix's diagonal,
            as ``[armature]``).
        viscous_friction: [N·m·s/rad] (Isaac Lab's ``viscous_friction``).
        static_friction: [N·m] (Isaac Lab's joint ``friction``, which their assets set equal to
            ``dynamic_friction``: a Coulomb friction).
        bias: the peer's encoder bias [rad], in its sign convention: the simulated (model's) angle minus the
            logged one, ``q_logged = q_model - bias``. In PACE (leggedrobotics/pace-sim2real at f8ec8b8,
            ``source/pace_sim2real/pace_sim2real/``; the same in every version from 2025-11-21 on) the driver's PD
            runs on ``joint_pos - self.encoder_bias`` (``utils/pace_actuator.py`` line 64: the bias is subtracted
            from the simulated joint position to give the encoder's reading, not added to the set-point), the score
            is ``sim_dof_pos - real_dof_pos - bias`` (``optim/cma_es.py`` line 73) and a rollout starts at
            ``initial_position + bias`` (line 119). The lab's own deployed actuator reads it the same way
            (iit-DLSLab/basic-locomotion-isaaclab, ``actuators/pace_actuator.py``: ``joint_pos -
            self.encoder_bias``). wbfriction's offset is therefore ``-bias`` (:attr:`encoder_offset`). The search
            was bounded to ±0.1 rad (``sysid_isaaclab/tasks/aliengo_pace_env_cfg.py`` lines 129-130).
        delay_steps: the peer's delay as published [steps of :data:`PEER_STEP`: physics steps, which with
            ``decimation = 1`` are also its control steps and the log's samples]. PACE delays the PD's torque
            output (``pace_actuator.py`` line 65, Isaac Lab's ``DelayBuffer``, one entry a physics step: the
            feedback as well as the set-point) by ``int(delay)`` steps (``cma_es.py`` line 129, ``.to(torch.int)``:
            truncated, so any value in [2, 3) simulates the same 2 steps).
        kp, kd: the gains it was identified with [N·m/rad, N·m·s/rad].
    """

    armature: dict[str, float]
    viscous_friction: dict[str, float]
    static_friction: dict[str, float]
    bias: dict[str, float]
    delay_steps: float
    kp: float
    kd: float

    @property
    def encoder_offset(self) -> dict[str, float]:
        """wbfriction's encoder offset [rad] (the logged angle minus the model's, ``[encoder_offset]``):
        ``-bias``."""
        return {j: -b for j, b in self.bias.items()}

    @property
    def delay(self) -> float:
        """The published delay in seconds: ``delay_steps`` × :data:`PEER_STEP` [s]."""
        return self.delay_steps * PEER_STEP

    @property
    def applied_delay_steps(self) -> int:
        """The steps its simulation delayed the torque by: ``int(delay_steps)`` (PACE truncates)."""
        return int(self.delay_steps)

    @property
    def applied_delay(self) -> float:
        """:attr:`applied_delay_steps` × :data:`PEER_STEP` [s]."""
        return self.applied_delay_steps * PEER_STEP


_PEER_LISTS = {"armature": "armature", "viscous_friction": "viscous_friction", "static_friction": "static_friction",
               "bias": "bias"}


def read_peer(path: str | Path) -> PeerActuator:
    """The peer's ``isaaclab_identified_parameters.py``: Python source of ``name = [...]`` lists (12 values, in the
    joint order its ``# Order:`` comment gives, else :data:`ALIENGO_JOINTS`' order) and scalars (``delay``,
    ``Kp``, ``Kd``). Each assignment's value is read with :func:`ast.literal_eval`; nothing is executed.

    Raises:
        InputError: a file that does not parse as Python, a statement that is not ``name = literal``, a value
            missing, not a number or of another length, an order naming other joints, naming the file and key.
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    try:
        tree = ast.parse(text, filename=str(path))
    except SyntaxError as exc:
        raise InputError(f"{path}: not Python source (line {exc.lineno}: {exc.msg})") from None
    values: dict[str, object] = {}
    for node in tree.body:
        if not (isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name)):
            raise InputError(f"{path}: line {node.lineno} is not 'name = value'")
        try:
            values[node.targets[0].id] = ast.literal_eval(node.value)
        except ValueError:
            raise InputError(f"{path}: line {node.lineno}: {node.targets[0].id} is not a literal") from None
    joints = _peer_order(path, text)

    def number(key: str) -> float:
        v = values.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InputError(f"{path}: '{key}' must be a number, got {v!r}")
        return float(v)

    lists = {}
    for field_, key in _PEER_LISTS.items():
        v = values.get(key)
        if not isinstance(v, list) or len(v) != len(joints) or any(isinstance(x, bool) or not isinstance(
                x, (int, float)) for x in v):
            raise InputError(f"{path}: '{key}' must be a list of {len(joints)} numbers")
        lists[field_] = {j: float(x) for j, x in zip(joints, v)}
    return PeerActuator(**lists, delay_steps=number("delay"), kp=number("Kp"), kd=number("Kd"))


def _peer_order(path: Path, text: str) -> tuple[str, ...]:
    found = re.search(r"^#\s*Order:\s*(.+)$", text, re.M)
    if found is None:
        return ALIENGO_JOINTS
    joints = tuple(f"{name.strip()}_joint" for name in found.group(1).split(","))
    if sorted(joints) != sorted(ALIENGO_JOINTS):
        raise InputError(f"{path}: its '# Order:' names {', '.join(joints)}, not the Aliengo's 12 joints")
    return joints


def aliengo_peer(files: dict[str, Path] | None = None) -> PeerActuator:
    """The peer's identification (:func:`read_peer` of the dataset's parameters file; ``files``: the dataset's
    files by name, default fetched).

    Raises:
        InputError: a missing, damaged or undownloadable file; a file :func:`read_peer` refuses.
    """
    files = AliengoDataset().fetch() if files is None else files
    return read_peer(files[PEER_FILE])


def peer_config(peer: PeerActuator) -> str:
    """The peer's identification as a robot-TOML fragment: ``[armature]``, ``[encoder_offset]`` (``-bias``) and a
    ``[pd]`` with its gains and the delay its simulation applied (:attr:`PeerActuator.applied_delay`), to the whole
    torque (``delayed = "torque"``, as PACE's actuator holds it)."""
    lines = ["# The iit-DLSLab identification of this Aliengo (PACE: CMA-ES over Isaac Lab rollouts), as a robot-TOML",
             f"# fragment: its tables replace aliengo.toml's. From {REPOSITORY} at {COMMIT[:7]},",
             "# robot_model/aliengo/isaaclab_identified_parameters.py. A peer's result, not ground truth.",
             "[armature]   # [kg·m²]"]
    lines += [f"{j} = {v!r}" for j, v in peer.armature.items()]
    lines += ["", "# The logged angle minus the model's [rad]: their 'bias' with its sign changed (PACE's encoder",
              "# reads the simulated angle minus the bias)."]
    lines += ["[encoder_offset]"] + [f"{j} = {v!r}" for j, v in peer.encoder_offset.items()]
    lines += ["", f"# Their delay: {peer.delay_steps!r} steps of {PEER_STEP} s ({peer.delay:.5f} s), which PACE",
              f"# truncates to {peer.applied_delay_steps} steps and applies to the PD's torque (set-point and feedback "
              "alike): [pd] delayed = \"torque\" (wbfriction.model.pd).",
              "[pd]", f"kp = {peer.kp!r}", f"kd = {peer.kd!r}", f"delay = {peer.applied_delay!r}   # [s]",
              'delayed = "torque"', "",
              "# Their friction (not a robot-TOML table; PeerActuator holds it), per joint: viscous [N·m·s/rad],",
              "# static (Coulomb) [N·m]:"]
    lines += [f"#   {j}: {peer.viscous_friction[j]!r}, {peer.static_friction[j]!r}" for j in peer.armature]
    return "\n".join(lines) + "\n"


# -------------------------------------------------------------------------------------------------- the dataset
LOGS = {"train": ("train.parquet", "the first 60 %"), "held_out": ("held_out.parquet", "the last 40 %, held out")}
"""Role -> (log written, what it is)."""


@register
class AliengoDataset(Dataset):
    """The iit-DLSLab's Unitree Aliengo (module docstring)."""

    name = "aliengo"
    folder = "unitree_aliengo"
    summary = ("the iit-DLSLab's Unitree Aliengo: 23.5 s of triangle ramps on 12 PD-driven joints, hung, no torque "
               "sensor, 200 Hz, 1 MB")
    files = ALIENGO_FILES

    def write(self, directory: str | Path, files: dict[str, Path] | None = None) -> WrittenDataset:
        files = self.fetch() if files is None else files
        trajectory = read_trajectory(files[LOG_FILE])
        peer = read_peer(files[PEER_FILE])
        rows = dict(zip(LOGS, split_rows(len(trajectory["time"]))))
        tables = {role: trajectory_table(trajectory, rows[role]) for role in LOGS}
        folder = make_folder(directory)
        logs = {role: folder / LOGS[role][0] for role in LOGS}
        for role, table in tables.items():
            write_table(table, logs[role])
        urdf, config = folder / URDF_FILE, folder / "aliengo.toml"
        write_atomic(urdf, lambda tmp: tmp.write_bytes(files[URDF_FILE].read_bytes()))
        text = robot_config(trajectory["kp"], trajectory["kd"], urdf.name, log_range(trajectory, CONTINUOUS))
        write_atomic(config, lambda tmp: tmp.write_text(text))
        write_atomic(folder / "peer.toml", lambda tmp: tmp.write_text(peer_config(peer)))
        q = {role: shlex.quote(str(p)) for role, p in logs.items()}
        commands = (f"wbfriction identify {q['train']} --config {shlex.quote(str(config))} --actuator pd "
                    "--config-output aliengo_identified.toml --json aliengo_actuator.json",
                    f"wbfriction estimate {q['train']} --config aliengo_identified.toml --route momentum "
                    "-o train_friction.parquet",
                    "wbfriction fit train_friction.parquet -o aliengo_params.json",
                    f"wbfriction estimate {q['held_out']} --config aliengo_identified.toml --route momentum "
                    "-o held_out_friction.parquet",
                    "wbfriction predict held_out_friction.parquet --params aliengo_params.json",
                    # no F_v of this log is ok: what the drivers' delay holds back is not told, and F_v carries
                    # kp delay (issue 63); the simulator takes the pair written, each fit's status in a comment
                    "wbfriction export aliengo_params.json --config aliengo_identified.toml --include weak,at-bound "
                    "-o aliengo_isaac.yaml -o aliengo.xml",
                    # the exported MJCF refined on its own replay of the training log, checked on the held-out one
                    f"wbfriction refine {q['train']} aliengo.xml --config aliengo_identified.toml "
                    f"-o aliengo_refined.xml --held-out {q['held_out']}")
        return WrittenDataset(self.name, logs, {r: t.num_rows for r, t in tables.items()}, config, commands,
                              {role: what for role, (_, what) in LOGS.items()})
