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

from bisect import bisect_right
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.config import read_toml
from wbfriction.exceptions import InputError
from wbfriction.logs.log import BASE_COLUMNS
from wbfriction.logs.tables import with_metadata

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


BLOCK_ROWS = 10_000
"""Joint-state samples aligned and handed on at a time by :func:`iter_bag`."""


def _unreadable(path: Path, exc: Exception) -> InputError:
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else repr(exc)
    return InputError(f"{path}: not a readable ROS 2 bag: {text}")


def _messages(path: Path, topics: dict[str, tuple[str, ...]]) -> Iterator[tuple[str, str, int, object]]:
    """(topic, message type, receive time [ns], message) of the mapped topics, in the bag's
    order (receive time), after checking that every topic exists with an expected type."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    folder = path if path.is_dir() else path.parent
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
                yield conn.topic, conn.msgtype, received, reader.deserialize(raw, conn.msgtype)
    except InputError:
        raise
    except Exception as exc:  # rosbags raises its own reader and deserialisation errors
        raise _unreadable(path, exc) from None


@dataclass
class _Series:
    """One aligned topic's messages not yet needed any more: stamps [ns] and values."""

    topic: str
    by_receive: bool = False  # stamped with the receive time (std_msgs/Bool has no header)
    stamps: list[int] = field(default_factory=list)
    values: list = field(default_factory=list)
    count: int = 0  # messages seen
    first: int | None = None

    def add(self, path: Path, stamp: int, value) -> None:
        self.count += 1
        if self.stamps and stamp < self.stamps[-1]:
            raise InputError(f"{path}: topic '{self.topic}': the stamp of message {self.count} goes back in time "
                             f"({(self.stamps[-1] - stamp) * 1e-6:.3f} ms)")
        if self.stamps and stamp == self.stamps[-1]:  # the later of two messages with one stamp
            self.values[-1] = value
            return
        self.first = stamp if self.first is None else self.first
        self.stamps.append(stamp)
        self.values.append(value)

    def trim(self, before: int) -> None:
        """Forget the messages older than the last one at or before ``before``."""
        k = max(bisect_right(self.stamps, before) - 1, 0)
        del self.stamps[:k], self.values[:k]


def _interpolate_pose(stamps: np.ndarray, poses: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Base poses (M, 7: x y z qx qy qz qw) at ``at`` [ns] from poses at ``stamps`` (K,):
    linear in the position, slerp in the orientation, between the two messages around each
    stamp (``stamps[0] <= at <= stamps[-1]``). Fractions come from integer nanoseconds, so
    the result does not depend on which messages are at hand."""
    from scipy.spatial.transform import Rotation

    quat = poses[:, 3:] / np.linalg.norm(poses[:, 3:], axis=1, keepdims=True)
    if len(stamps) == 1:
        return np.column_stack([np.repeat(poses[:, :3], len(at), axis=0), np.repeat(quat, len(at), axis=0)])
    i = np.clip(np.searchsorted(stamps, at, side="right") - 1, 0, len(stamps) - 2)
    alpha = ((at - stamps[i]) / (stamps[i + 1] - stamps[i]))[:, None]
    xyz = poses[i, :3] + alpha * (poses[i + 1, :3] - poses[i, :3])
    r0, r1 = Rotation.from_quat(quat[i]), Rotation.from_quat(quat[i + 1])
    rot = r0 * Rotation.from_rotvec(alpha * (r0.inv() * r1).as_rotvec())
    return np.column_stack([xyz, rot.as_quat()])


def iter_bag(path: str | Path, bag_map: BagMap, block_rows: int = BLOCK_ROWS) -> Iterator[pa.Table]:
    """A ROS 2 bag as consecutive tables in the log format (:mod:`wbfriction.logs.log`) of about
    ``block_rows`` rows, aligned on the joint-state stamps (module docstring), read in one
    pass: memory holds a block and the messages that arrive ahead of it, not the bag.

    A sample is handed on once every aligned topic has a message after it (with a stamp at
    or after it for the base pose), so a topic that stops publishing holds samples back
    until the end of the bag. The first table's metadata records the bag and the absolute
    first stamp (``time_origin_ns``); ``time`` counts from it in every table.

    Raises:
        InputError: unreadable bag, a missing or empty topic, a topic of another type, a
            wrench topic without a threshold, a joint-state message naming a joint that
            the first one did not, stamps that go back in time within a topic, or no
            joint-state sample where every topic has data.
    """
    path = Path(path)
    topics = {bag_map.joint_states: (JOINT_STATE,)}
    for c in bag_map.contacts:
        topics[c.topic] = (WRENCH, BOOL)
    if bag_map.base:
        topics[bag_map.base] = (ODOMETRY, POSE)
    contacts = {c.topic: _Series(c.topic) for c in bag_map.contacts}
    base = _Series(bag_map.base) if bag_map.base else None
    series = [*contacts.values(), *([base] if base else [])]
    by_topic = {c.topic: c for c in bag_map.contacts}
    columns: dict[str, int] = {}  # model joint -> column, from the first joint-state message
    has_effort = False
    js_count = 0
    pending: list[tuple[int, np.ndarray, np.ndarray]] = []  # joint-state samples: stamp [ns], q, tau
    received = -1  # the latest receive time: no Bool message before it is still to come
    origin: int | None = None
    rows = 0

    def horizon() -> float:
        """Samples stamped before this can be aligned now [ns]."""
        h = float("inf")
        for s in series:
            if not s.stamps:
                return -1.0
            h = min(h, received if s.by_receive else s.stamps[-1])
        return h

    def emit(final: bool) -> pa.Table | None:
        nonlocal origin, rows
        stamps = np.array([p[0] for p in pending], dtype=np.int64)
        ready = len(stamps) if final else int(np.searchsorted(stamps >= horizon(), True))
        if ready == 0:
            return None
        at = stamps[:ready]
        q = np.array([p[1] for p in pending[:ready]])
        tau = np.array([p[2] for p in pending[:ready]])
        del pending[:ready]
        keep = np.ones(ready, dtype=bool)
        for s in series:
            keep &= at >= (s.first if s.first is not None else np.iinfo(np.int64).max)
        if final and base is not None and base.stamps:
            keep &= at <= base.stamps[-1]
        at, q, tau = at[keep], q[keep], tau[keep]
        if len(at) == 0:
            return None
        origin = int(at[0]) if origin is None else origin
        table = {"time": (at - origin) * 1e-9}
        for name, i in columns.items():
            table[f"q.{name}"] = q[:, i]
        if has_effort:
            for name, i in columns.items():
                table[f"tau.{name}"] = tau[:, i]
        for c in bag_map.contacts:
            s = contacts[c.topic]
            flags = np.array([bool(v) for v in s.values], dtype=np.int8)
            table[f"contact.{c.frame}"] = flags[np.searchsorted(np.array(s.stamps), at, side="right") - 1]
        if base is not None:
            pose = _interpolate_pose(np.array(base.stamps, dtype=np.int64), np.array(base.values), at)
            table.update(dict(zip(BASE_COLUMNS, pose.T)))
        for s in series:
            s.trim(int(at[-1]))
        out = pa.table(table)
        if rows == 0:
            out = with_metadata(out, {"source_bag": str(path), "time_origin_ns": origin,
                                      "alignment": "contacts: zero-order hold; base: linear + slerp"})
        rows += len(at)
        return out

    for topic, msgtype, recv, msg in _messages(path, topics):
        received = max(received, recv)
        if topic == bag_map.joint_states:
            names = [bag_map.rename.get(n, n) for n in msg.name]
            if not columns:
                columns = {n: i for i, n in enumerate(dict.fromkeys(names))}
                has_effort = len(msg.effort) == len(names)
            js_count += 1
            unknown = next((n for n in names if n not in columns), None)
            if unknown is not None:
                raise InputError(f"{path}: joint-state message {js_count} names joint '{unknown}', which the "
                                 "first message did not")
            stamp = _stamp(msg)
            if pending and stamp < pending[-1][0]:
                raise InputError(f"{path}: topic '{topic}': the stamp of message {js_count} goes back in time")
            q = np.full(len(columns), np.nan)
            tau = np.full(len(columns), np.nan)
            idx = [columns[n] for n in names]
            if len(msg.position) == len(idx):
                q[idx] = msg.position
            if len(msg.effort) == len(idx):
                tau[idx] = msg.effort
            pending.append((stamp, q, tau))
            if len(pending) >= block_rows:
                block = emit(final=False)
                if block is not None:
                    yield block
        elif topic in by_topic:
            c = by_topic[topic]
            if msgtype == BOOL:
                contacts[topic].by_receive = True
                contacts[topic].add(path, recv, bool(msg.data))
            else:
                if c.threshold is None:
                    raise InputError(f"{path}: contact topic '{topic}' is a wrench: give its threshold [N] in the map")
                contacts[topic].add(path, _stamp(msg), abs(getattr(msg.wrench.force, c.axis)) > c.threshold)
        else:
            p = msg.pose.pose if hasattr(msg.pose, "pose") else msg.pose
            base.add(path, _stamp(msg), (p.position.x, p.position.y, p.position.z, p.orientation.x,
                                          p.orientation.y, p.orientation.z, p.orientation.w))
    if js_count == 0:
        raise InputError(f"{path}: topic '{bag_map.joint_states}' has no message")
    for s in series:
        if s.count == 0:
            raise InputError(f"{path}: topic '{s.topic}' has no message")
    block = emit(final=True)
    if block is not None:
        yield block
    if rows < 2:
        raise InputError(f"{path}: no joint-state sample lies where every mapped topic has data")


def read_bag(path: str | Path, bag_map: BagMap) -> pa.Table:
    """A ROS 2 bag as one table in the log format (:func:`iter_bag`). Validation against a
    robot is left to :func:`~wbfriction.logs.log.log_from_table`.

    Raises:
        InputError: see :func:`iter_bag`.
    """
    blocks = list(iter_bag(path, bag_map))
    return pa.concat_tables(blocks).replace_schema_metadata(blocks[0].schema.metadata)
