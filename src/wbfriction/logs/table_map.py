"""The ``--map`` TOML of a bag applied to a table log (Parquet, CSV, HDF5): joint names and contact flags.

A table log whose columns do not use the robot's joint names, or that has a foot's measured force
instead of a contact flag, is read through the same map TOML as a ROS 2 bag
(:func:`wbfriction.logs.bags.load_bag_map`), its keys read the same way, a column standing for a topic::

    [joint_states]
    rename = { LLeg_knee = "leg_left_4_joint" }   # log name -> model joint name, in every <kind>.<name> column
    [[contacts]]                                  # one per contact frame without a contact.<frame> column
    frame = "left_sole_link"
    column = "lf_ft.fz"                           # a force column [N]: in contact while |force| > threshold
    threshold = 50.0                              # without threshold: the column is a 0/1 flag already

A bag's ``topic`` keys, its ``[[contacts]]`` entries with a ``topic`` and no ``column``, and its ``[base]``
table are not used for a table (a map may serve both). The
force column stays in the log (a ``wrench.<sensor>.fz`` column is still a sensor's reading); the derived
flag is ``contact.<frame>`` (int8, 1 in contact), exactly as a bag's wrench topic gives it. A NaN or
inf in a contact column is refused (a force not measured is not "no contact"), naming the log, the
column and the row.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.config import read_toml
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.model.robot import Robot


@dataclass(frozen=True)
class ContactColumn:
    """Where one contact frame's flag comes from in a table log.

    Attributes:
        frame: contact frame of the robot.
        column: the log column: a force [N] (with ``threshold``) or a 0/1 flag (without).
        threshold: force above which the frame is in contact, ``|force| > threshold`` [N]; None: a flag.
    """

    frame: str
    column: str
    threshold: float | None = None


@dataclass(frozen=True)
class TableMap:
    """A map TOML as it applies to a table log (module docstring).

    Attributes:
        path: the map file (named in every message).
        rename: log joint name -> model joint name.
        contacts: one :class:`ContactColumn` per contact frame the map derives.
    """

    path: Path
    rename: dict[str, str] = field(default_factory=dict)
    contacts: tuple[ContactColumn, ...] = ()

    def check(self, robot: Robot) -> None:
        """Every renamed joint is one of ``robot``'s (actuated or locked), every frame one of its contact frames.

        Raises:
            InputError: naming the map file and the key.
        """
        joints = set(robot.actuated) | set(robot.locked_joints)
        for old, new in self.rename.items():
            if new not in joints:
                raise InputError(f"{self.path}: [joint_states] rename {old} = '{new}': not a joint of robot "
                                 f"'{robot.name}'")
        for k, c in enumerate(self.contacts):
            if c.frame not in robot.contact_frames:
                raise InputError(f"{self.path}: [[contacts]] entry {k + 1}: frame '{c.frame}' is not a contact "
                                 f"frame of robot '{robot.name}' ({', '.join(robot.contact_frames)})")

    def check_columns(self, names: list[str], log: str | Path) -> None:
        """Every renamed joint and every contact column is in the log's columns ``names``, and no derived
        flag is there already.

        Raises:
            InputError: naming the map file, the key and the log.
        """
        items = {c.partition(".")[2] for c in names if "." in c}
        for old in self.rename:
            if old not in items:
                raise InputError(f"{self.path}: [joint_states] rename {old}: no column '<kind>.{old}' (q.{old}, "
                                 f"tau.{old}, ...) in {log}")
        for k, c in enumerate(self.contacts):
            if c.column not in names:
                raise InputError(f"{self.path}: [[contacts]] entry {k + 1}: column '{c.column}' is not in {log}")
            if f"contact.{c.frame}" in names:
                raise InputError(f"{self.path}: [[contacts]] entry {k + 1}: {log} has its own column "
                                 f"'contact.{c.frame}' already")

    def apply(self, table: pa.Table, log: str | Path, first_row: int = 0) -> pa.Table:
        """``table`` (a block of the log, starting at the file's row ``first_row``) with its columns renamed
        and the contact flags added (metadata kept).

        Raises:
            InputError: see :meth:`check_columns`; a contact column that is not numbers.
            ColumnError: a contact column holding NaN or inf (a force that was not measured cannot
                say "no contact", nor a flag "contact"), naming ``log``, the column and its first such
                row, counted from the file's first data row.
        """
        names = list(table.column_names)
        self.check_columns(names, log)
        renamed = []
        for name in names:
            kind, dot, item = name.partition(".")
            renamed.append(f"{kind}.{self.rename[item]}" if dot and item in self.rename else name)
        out = table.rename_columns(renamed)
        for k, c in enumerate(self.contacts):
            try:
                values = np.asarray(table.column(c.column).to_numpy(zero_copy_only=False), dtype=float)
            except (pa.ArrowException, TypeError, ValueError):
                raise InputError(f"{self.path}: [[contacts]] entry {k + 1}: column '{c.column}' of {log} is not "
                                 "numbers") from None
            bad = np.flatnonzero(~np.isfinite(values))
            if bad.size:
                row = first_row + int(bad[0])
                raise ColumnError(str(log), c.column, row, f"column '{c.column}' has a non-finite value (NaN or "
                                  f"inf) at row {row}: it cannot say whether frame '{c.frame}' is in contact "
                                  f"({self.path}, [[contacts]] entry {k + 1})")
            flags = (np.abs(values) > c.threshold) if c.threshold is not None else (values != 0)
            out = out.append_column(f"contact.{c.frame}", pa.array(flags.astype(np.int8)))
        return out.replace_schema_metadata(table.schema.metadata)


def load_table_map(path: str | Path) -> TableMap:
    """The map TOML's ``[joint_states] rename`` and ``[[contacts]]`` (``frame``, ``column``, ``threshold``; an
    entry with only a bag's ``topic`` is skipped) for a table log (module docstring).

    Raises:
        InputError: an unreadable file, a ``[[contacts]]`` entry without ``frame`` or ``column``, a
            threshold that is not a number >= 0, a rename that is not name = "joint", naming the file and key.
    """
    path = Path(path)
    doc = read_toml(path)
    js = doc.get("joint_states", {})
    rename = js.get("rename", {}) if isinstance(js, dict) else None
    if not isinstance(rename, dict) or not all(isinstance(v, str) for v in rename.values()):
        raise InputError(f"{path}: [joint_states] rename must map log names to model joint names")
    contacts = []
    entries = doc.get("contacts", [])
    for k, c in enumerate(entries if isinstance(entries, list) else [entries]):
        if not isinstance(c, dict) or not isinstance(c.get("frame"), str):
            raise InputError(f"{path}: [[contacts]] entry {k + 1} needs frame = \"...\"")
        if "column" not in c and "topic" in c:
            continue  # a bag's contact: not read from a table
        if not isinstance(c.get("column"), str):
            raise InputError(f"{path}: [[contacts]] entry {k + 1} (frame '{c['frame']}'): a table log needs "
                             "column = \"...\" (a force column [N] with threshold, or a 0/1 flag)")
        threshold = c.get("threshold")
        if threshold is not None and (isinstance(threshold, bool) or not isinstance(threshold, (int, float))
                                      or not threshold >= 0):
            raise InputError(f"{path}: [[contacts]] entry {k + 1}: threshold must be a number >= 0 [N], "
                             f"got {threshold!r}")
        contacts.append(ContactColumn(c["frame"], c["column"], None if threshold is None else float(threshold)))
    return TableMap(path, dict(rename), tuple(contacts))
