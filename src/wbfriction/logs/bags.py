"""ROS 2 bags as logs: read without a ROS installation (``rosbags``), MCAP or sqlite3.

A small TOML map names the topics and, where they differ, the joints::

    [joint_states]                  # sensor_msgs/JointState: positions and efforts by name
    topic = "/joint_states"
    rename = { leg_left_1 = "leg_left_1_joint" }   # optional: message name -> model name

    [[contacts]]                    # one per contact frame of the robot
    frame = "left_sole_link"
    topic = "/left_ankle_ft"        # geometry_msgs/WrenchStamped ...
    threshold = 50.0                # ... in contact while |force.<axis>| > threshold [N] (NaN: refused)
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
from typing import Any

import numpy as np
import pyarrow as pa

from wbfriction.config import read_toml
from wbfriction.exceptions import InputError
from wbfriction.logs.columns import BASE_COLUMNS
from wbfriction.logs.metadata import with_metadata

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
                    raise InputError(f"{path}: no topic '{topic}' in the bag "
                                     f"(it has {', '.join(sorted(conns)) or 'none'})")
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


def _topics(bag_map: BagMap) -> dict[str, tuple[str, ...]]:
    """The mapped topics and the message types each may carry."""
    topics: dict[str, tuple[str, ...]] = {bag_map.joint_states: (JOINT_STATE,)}
    for c in bag_map.contacts:
        topics[c.topic] = (WRENCH, BOOL)
    if bag_map.base:
        topics[bag_map.base] = (ODOMETRY, POSE)
    return topics


class _BagAligner:
    """A bag's messages aligned on its joint-state stamps, handed on in blocks (:func:`iter_bag`).

    Holds the joint-state samples not yet handed on (stamp [ns], q, tau), the aligned
    topics' messages still needed (:class:`_Series`), and what the blocks share (the
    joint columns, the time origin, the rows handed on so far).
    """

    def __init__(self, path: Path, bag_map: BagMap, block_rows: int) -> None:
        self.path = path
        self.bag_map = bag_map
        self.block_rows = block_rows
        self.topics = _topics(bag_map)
        self.contacts = {c.topic: _Series(c.topic) for c in bag_map.contacts}
        self.base = _Series(bag_map.base) if bag_map.base else None
        self.series = [*self.contacts.values(), *([self.base] if self.base else [])]
        self.by_topic = {c.topic: c for c in bag_map.contacts}
        self.columns: dict[str, int] = {}  # model joint -> column, from the first joint-state message
        self.has_effort = False
        self.js_count = 0
        self.pending: list[tuple[int, np.ndarray, np.ndarray]] = []  # joint-state samples: stamp [ns], q, tau
        self.received = -1  # the latest receive time: no Bool message before it is still to come
        self.origin: int | None = None
        self.rows = 0

    # ------------------------------------------------------------- messages in
    def add(self, topic: str, msgtype: str, recv: int, msg: Any) -> pa.Table | None:
        """Take one message of the bag; the block it completes (a joint-state message filling one), if any."""
        self.received = max(self.received, recv)
        if topic == self.bag_map.joint_states:
            self.add_joint_state(topic, msg)
            return self.block() if len(self.pending) >= self.block_rows else None
        if topic in self.by_topic:
            self.add_contact(topic, msgtype, recv, msg)
        else:
            self.add_base(msg)
        return None

    def add_joint_state(self, topic: str, msg: Any) -> None:
        """Queue a joint-state message as a sample: its stamp, q and tau by model joint (NaN where absent)."""
        names = [self.bag_map.rename.get(n, n) for n in msg.name]
        if not self.columns:
            self.columns = {n: i for i, n in enumerate(dict.fromkeys(names))}
            self.has_effort = len(msg.effort) == len(names)
        self.js_count += 1
        unknown = next((n for n in names if n not in self.columns), None)
        if unknown is not None:
            raise InputError(f"{self.path}: joint-state message {self.js_count} names joint '{unknown}', which the "
                             "first message did not")
        stamp = _stamp(msg)
        if self.pending and stamp < self.pending[-1][0]:
            raise InputError(f"{self.path}: topic '{topic}': the stamp of message {self.js_count} goes back in time")
        q = np.full(len(self.columns), np.nan)
        tau = np.full(len(self.columns), np.nan)
        idx = [self.columns[n] for n in names]
        if len(msg.position) == len(idx):
            q[idx] = msg.position
        if len(msg.effort) == len(idx):
            tau[idx] = msg.effort
        self.pending.append((stamp, q, tau))

    def add_contact(self, topic: str, msgtype: str, recv: int, msg: Any) -> None:
        """Record a contact flag: a ``Bool`` at its receive time, a wrench's force over the threshold at its stamp."""
        c = self.by_topic[topic]
        if msgtype == BOOL:
            self.contacts[topic].by_receive = True
            self.contacts[topic].add(self.path, recv, bool(msg.data))
        else:
            if c.threshold is None:
                raise InputError(f"{self.path}: contact topic '{topic}' is a wrench: give its threshold [N] in the map")
            force = float(getattr(msg.wrench.force, c.axis))
            if not np.isfinite(force):  # not measured: neither "contact" nor "no contact"
                raise InputError(f"{self.path}: topic '{topic}': message {self.contacts[topic].count + 1} has a "
                                 f"non-finite force.{c.axis} ({force}): it cannot say whether frame '{c.frame}' is "
                                 "in contact")
            self.contacts[topic].add(self.path, _stamp(msg), abs(force) > c.threshold)

    def add_base(self, msg: Any) -> None:
        """Record a base pose (x y z qx qy qz qw) of an ``Odometry`` or ``PoseStamped`` message at its stamp."""
        p = msg.pose.pose if hasattr(msg.pose, "pose") else msg.pose
        assert self.base is not None  # only the mapped base topic's messages come here
        self.base.add(self.path, _stamp(msg), (p.position.x, p.position.y, p.position.z, p.orientation.x,
                                               p.orientation.y, p.orientation.z, p.orientation.w))

    # ------------------------------------------------------------- blocks out
    def block(self) -> pa.Table | None:
        """The block that can be handed on now (the samples every topic has data after), if any."""
        return self.emit(final=False)

    def last_block(self) -> pa.Table | None:
        """The block left at the end of the bag, after checking that every topic had a message."""
        if self.js_count == 0:
            raise InputError(f"{self.path}: topic '{self.bag_map.joint_states}' has no message")
        for s in self.series:
            if s.count == 0:
                raise InputError(f"{self.path}: topic '{s.topic}' has no message")
        return self.emit(final=True)

    def check_rows(self) -> None:
        """Refuse a bag of which fewer than two samples could be aligned."""
        if self.rows < 2:
            raise InputError(f"{self.path}: no joint-state sample lies where every mapped topic has data")

    def horizon(self) -> float:
        """Samples stamped before this can be aligned now [ns]."""
        h = float("inf")
        for s in self.series:
            if not s.stamps:
                return -1.0
            h = min(h, self.received if s.by_receive else s.stamps[-1])
        return h

    def emit(self, final: bool) -> pa.Table | None:
        """The pending samples that can be aligned (all of them at the end, ``final``) as a table, if any."""
        taken = self._take(final)
        if taken is None:
            return None
        at, q, tau = taken
        self.origin = int(at[0]) if self.origin is None else self.origin
        table = {"time": (at - self.origin) * 1e-9, **self._joint_columns(q, tau), **self._contact_columns(at)}
        if self.base is not None:
            table.update(self._base_columns(at))
        for s in self.series:
            s.trim(int(at[-1]))
        out = pa.table(table)
        if self.rows == 0:
            out = with_metadata(out, {"source_bag": str(self.path), "time_origin_ns": self.origin,
                                      "alignment": "contacts: zero-order hold; base: linear + slerp"})
        self.rows += len(at)
        return out

    def _take(self, final: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Remove the ready samples from the pending ones: stamps [ns], q, tau of those every topic covers."""
        stamps = np.array([p[0] for p in self.pending], dtype=np.int64)
        ready = len(stamps) if final else int(np.searchsorted(stamps >= self.horizon(), True))
        if ready == 0:
            return None
        at = stamps[:ready]
        q = np.array([p[1] for p in self.pending[:ready]])
        tau = np.array([p[2] for p in self.pending[:ready]])
        del self.pending[:ready]
        keep = np.ones(ready, dtype=bool)
        for s in self.series:
            keep &= at >= (s.first if s.first is not None else np.iinfo(np.int64).max)
        if final and self.base is not None and self.base.stamps:
            keep &= at <= self.base.stamps[-1]
        at, q, tau = at[keep], q[keep], tau[keep]
        if len(at) == 0:
            return None
        return at, q, tau

    def _joint_columns(self, q: np.ndarray, tau: np.ndarray) -> dict[str, np.ndarray]:
        """The ``q.<joint>`` columns, then the ``tau.<joint>`` ones if the messages carry efforts."""
        table = {f"q.{name}": q[:, i] for name, i in self.columns.items()}
        if self.has_effort:
            table.update({f"tau.{name}": tau[:, i] for name, i in self.columns.items()})
        return table

    def _contact_columns(self, at: np.ndarray) -> dict[str, np.ndarray]:
        """The ``contact.<frame>`` flags at the stamps ``at`` [ns]: the latest message at or before each."""
        table = {}
        for c in self.bag_map.contacts:
            s = self.contacts[c.topic]
            flags = np.array([bool(v) for v in s.values], dtype=np.int8)
            table[f"contact.{c.frame}"] = flags[np.searchsorted(np.array(s.stamps), at, side="right") - 1]
        return table

    def _base_columns(self, at: np.ndarray) -> dict[str, np.ndarray]:
        """The ``base.*`` columns at the stamps ``at`` [ns], interpolated between the base poses."""
        assert self.base is not None  # called when the map has a base topic
        pose = _interpolate_pose(np.array(self.base.stamps, dtype=np.int64), np.array(self.base.values), at)
        return dict(zip(BASE_COLUMNS, pose.T))


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
            wrench topic without a threshold or with a non-finite force (naming the topic and
            the message), a joint-state message naming a joint that
            the first one did not, stamps that go back in time within a topic, or no
            joint-state sample where every topic has data.
    """
    path = Path(path)
    aligner = _BagAligner(path, bag_map, block_rows)
    for topic, msgtype, recv, msg in _messages(path, aligner.topics):
        block = aligner.add(topic, msgtype, recv, msg)
        if block is not None:
            yield block
    block = aligner.last_block()
    if block is not None:
        yield block
    aligner.check_rows()


def read_bag(path: str | Path, bag_map: BagMap) -> pa.Table:
    """A ROS 2 bag as one table in the log format (:func:`iter_bag`). Validation against a
    robot is left to :func:`~wbfriction.logs.log.log_from_table`.

    Raises:
        InputError: see :func:`iter_bag`.
    """
    blocks = list(iter_bag(path, bag_map))
    return pa.concat_tables(blocks).replace_schema_metadata(blocks[0].schema.metadata)
