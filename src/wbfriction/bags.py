"""ROS 2 bags as logs: read without a ROS installation (``rosbags``), MCAP or sqlite3.

A small TOML map names the topics and, where they differ, the joints::

    [joint_states]                  # sensor_msgs/JointState: positions and efforts by name
    topic = "/joint_states"
    rename = { leg_left_1 = "leg_left_1_joint" }   # optional: message name -> model name

    [[contacts]]                    # one per contact frame of the robot
    frame = "left_sole_link"
    topic = "/left_ankle_ft"        # geometry_msgs/WrenchStamped ...
    threshold = 50.0                # ... in contact while |force.<axis>| > threshold [N]
    axis = "z"                      # optional, default z

    [[contacts]]
    frame = "right_sole_link"
    topic = "/right_foot_contact"   # ... or std_msgs/Bool

    [base]                          # optional: nav_msgs/Odometry or geometry_msgs/PoseStamped
    topic = "/odom"

**Time and alignment.** The log's samples are the joint-state messages, at their header
stamps (``time`` in seconds from the first one; the absolute first stamp is kept in the
metadata as ``time_origin_ns``). The other topics are aligned on those stamps:

* contacts: **zero-order hold**: the most recent message at or before the stamp (a
  contact flag is a state, not a signal to interpolate); header stamps for wrenches, the
  bag's receive time for ``Bool`` (it has no header);
* base pose: **linear interpolation** of the position and **spherical linear
  interpolation** of the orientation (``scipy.spatial.transform.Slerp``) between the two
  messages around the stamp.

Joint-state samples before the first message of every aligned topic, or after the last
base pose, cannot be aligned and are dropped (the log starts and ends where every
source has data).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa

from .config import read_toml
from .exceptions import InputError
from .log import BASE_COLUMNS, with_metadata

JOINT_STATE = "sensor_msgs/msg/JointState"
WRENCH = "geometry_msgs/msg/WrenchStamped"
BOOL = "std_msgs/msg/Bool"
ODOMETRY = "nav_msgs/msg/Odometry"
POSE = "geometry_msgs/msg/PoseStamped"
AXES = ("x", "y", "z")


@dataclass(frozen=True)
class ContactTopic:
    """Where one contact frame's flag comes from.

    Attributes:
        frame: contact frame of the robot.
        topic: a ``geometry_msgs/WrenchStamped`` or ``std_msgs/Bool`` topic.
        threshold: force above which a wrench means contact [N] (wrench topics only).
        axis: force component compared with the threshold, in absolute value.
    """

    frame: str
    topic: str
    threshold: float | None = None
    axis: str = "z"


@dataclass(frozen=True)
class BagMap:
    """Topics and names of a bag (module docstring).

    Attributes:
        joint_states: the ``sensor_msgs/JointState`` topic.
        rename: message joint name -> model joint name (others are kept as they are).
        contacts: one :class:`ContactTopic` per contact frame.
        base: an ``nav_msgs/Odometry`` or ``geometry_msgs/PoseStamped`` topic, or None.
    """

    joint_states: str
    contacts: tuple[ContactTopic, ...]
    rename: dict[str, str] = field(default_factory=dict)
    base: str | None = None


def load_bag_map(path: str | Path) -> BagMap:
    """Read a bag map TOML.

    Raises:
        InputError: unreadable file, or a missing or ill-typed key (named).
    """
    doc = read_toml(path)
    js = doc.get("joint_states")
    if not isinstance(js, dict) or not isinstance(js.get("topic"), str):
        raise InputError(f"{path}: [joint_states] needs topic = \"/...\"")
    rename = js.get("rename", {})
    if not isinstance(rename, dict) or not all(isinstance(v, str) for v in rename.values()):
        raise InputError(f"{path}: [joint_states] rename must map message names to model joint names")
    contacts = []
    for k, c in enumerate(doc.get("contacts", [])):
        if not isinstance(c, dict) or not isinstance(c.get("frame"), str) or not isinstance(c.get("topic"), str):
            raise InputError(f"{path}: [[contacts]] entry {k + 1} needs frame and topic")
        threshold = c.get("threshold")
        if threshold is not None and not isinstance(threshold, (int, float)):
            raise InputError(f"{path}: [[contacts]] entry {k + 1}: threshold must be a number [N]")
        axis = c.get("axis", "z")
        if axis not in AXES:
            raise InputError(f"{path}: [[contacts]] entry {k + 1}: axis must be x, y or z, got {axis!r}")
        contacts.append(ContactTopic(c["frame"], c["topic"], None if threshold is None else float(threshold), axis))
    if not contacts:
        raise InputError(f"{path}: no [[contacts]] entry: each contact frame needs a topic")
    base = doc.get("base")
    if base is not None and (not isinstance(base, dict) or not isinstance(base.get("topic"), str)):
        raise InputError(f"{path}: [base] needs topic = \"/...\"")
    return BagMap(js["topic"], tuple(contacts), dict(rename), None if base is None else base["topic"])


def is_bag(path: str | Path) -> bool:
    """A ROS 2 bag: a folder with ``metadata.yaml``, or a ``.mcap`` / ``.db3`` file in one."""
    path = Path(path)
    if path.is_dir():
        return (path / "metadata.yaml").is_file()
    return path.suffix.lower() in (".mcap", ".db3")


def _stamp(msg) -> int:
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def _read_topics(path: Path, topics: dict[str, tuple[str, ...]]) -> dict[str, list]:
    """Messages of each topic as (stamp_ns, message), checking the message types."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    folder = path if path.is_dir() else path.parent
    out: dict[str, list] = {t: [] for t in topics}
    try:
        with AnyReader([folder], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
            conns = {c.topic: c for c in reader.connections}
            for topic, types in topics.items():
                if topic not in conns:
                    raise InputError(f"{path}: no topic '{topic}' in the bag (it has {', '.join(sorted(conns)) or 'none'})")
                if conns[topic].msgtype not in types:
                    raise InputError(f"{path}: topic '{topic}' carries {conns[topic].msgtype}, expected "
                                     f"{' or '.join(types)}")
            wanted = [c for c in reader.connections if c.topic in topics]
            for conn, received, raw in reader.messages(connections=wanted):
                msg = reader.deserialize(raw, conn.msgtype)
                out[conn.topic].append((received if conn.msgtype == BOOL else _stamp(msg), msg))
    except InputError:
        raise
    except Exception as exc:  # rosbags raises its own reader and deserialisation errors
        raise InputError(f"{path}: not a readable ROS 2 bag: {str(exc).strip().splitlines()[0] if str(exc) else exc!r}") from None
    for topic, msgs in out.items():
        if not msgs:
            raise InputError(f"{path}: topic '{topic}' has no message")
        msgs.sort(key=lambda m: m[0])
    return out


def _joint_columns(msgs: list, rename: dict[str, str]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Stamps (N,) and ``q.<joint>``/``tau.<joint>`` columns from JointState messages,
    by name in each message (NaN where a message lacks the joint)."""
    stamps = np.array([s for s, _ in msgs], dtype=np.int64)
    names: dict[str, int] = {}
    for _, m in msgs:
        for n in m.name:
            names.setdefault(rename.get(n, n), len(names))
    q = np.full((len(msgs), len(names)), np.nan)
    tau = np.full((len(msgs), len(names)), np.nan)
    for k, (_, m) in enumerate(msgs):
        cols = [names[rename.get(n, n)] for n in m.name]
        if len(m.position) == len(cols):
            q[k, cols] = m.position
        if len(m.effort) == len(cols):
            tau[k, cols] = m.effort
    columns = {}
    for n, i in names.items():
        columns[f"q.{n}"] = q[:, i]
        if np.isfinite(tau[:, i]).any():
            columns[f"tau.{n}"] = tau[:, i]
    return stamps, columns


def _hold(stamps: np.ndarray, at: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Zero-order hold of ``values`` (at ``stamps``) at the times ``at`` (all >= stamps[0])."""
    return values[np.searchsorted(stamps, at, side="right") - 1]


def _base_columns(stamps: np.ndarray, msgs: list, at: np.ndarray) -> dict[str, np.ndarray]:
    from scipy.spatial.transform import Rotation, Slerp

    poses = [m.pose.pose if hasattr(m.pose, "pose") else m.pose for _, m in msgs]
    pos = np.array([[p.position.x, p.position.y, p.position.z] for p in poses])
    quat = np.array([[p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w] for p in poses])
    t = (stamps - stamps[0]) * 1e-9
    x = (at - stamps[0]) * 1e-9
    xyz = np.column_stack([np.interp(x, t, pos[:, i]) for i in range(3)])
    if len(t) > 1:
        rot = Slerp(t, Rotation.from_quat(quat))(x).as_quat()
    else:
        rot = np.repeat(quat / np.linalg.norm(quat), len(x), axis=0)
    return dict(zip(BASE_COLUMNS, [*xyz.T, *rot.T]))


def read_bag(path: str | Path, bag_map: BagMap) -> pa.Table:
    """A ROS 2 bag as a table in the log format (:mod:`wbfriction.log`), aligned on the
    joint-state stamps (module docstring). Validation against a robot is left to
    :func:`~wbfriction.log.log_from_table`.

    Raises:
        InputError: unreadable bag, a missing or empty topic, a topic of another type, a
            wrench topic without a threshold, or no joint-state sample where every topic
            has data.
    """
    path = Path(path)
    topics = {bag_map.joint_states: (JOINT_STATE,)}
    for c in bag_map.contacts:
        topics[c.topic] = (WRENCH, BOOL)
    if bag_map.base:
        topics[bag_map.base] = (ODOMETRY, POSE)
    msgs = _read_topics(path, topics)
    stamps, columns = _joint_columns(msgs[bag_map.joint_states], bag_map.rename)
    first = max(m[0][0] for m in msgs.values())
    last = msgs[bag_map.base][-1][0] if bag_map.base else stamps[-1]
    keep = (stamps >= first) & (stamps <= last)
    if keep.sum() < 2:
        raise InputError(f"{path}: no joint-state sample lies where every mapped topic has data")
    stamps = stamps[keep]
    table = {"time": (stamps - stamps[0]) * 1e-9}
    table.update({k: v[keep] for k, v in columns.items()})
    for c in bag_map.contacts:
        cm = msgs[c.topic]
        ts = np.array([s for s, _ in cm], dtype=np.int64)
        if hasattr(cm[0][1], "wrench"):
            if c.threshold is None:
                raise InputError(f"{path}: contact topic '{c.topic}' is a wrench: give its threshold [N] in the map")
            force = np.array([abs(getattr(m.wrench.force, c.axis)) for _, m in cm])
            flag = force > c.threshold
        else:
            flag = np.array([bool(m.data) for _, m in cm])
        table[f"contact.{c.frame}"] = _hold(ts, stamps, flag).astype(np.int8)
    if bag_map.base:
        bm = msgs[bag_map.base]
        table.update(_base_columns(np.array([s for s, _ in bm], dtype=np.int64), bm, stamps))
    return with_metadata(pa.table(table), {"source_bag": str(path), "time_origin_ns": int(stamps[0]),
                                           "alignment": "contacts: zero-order hold; base: linear + slerp"})
