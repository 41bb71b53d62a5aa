"""What an export target is: a file format simulators read, written from the joints' simulator parameters.

Every target writes with one signature, :meth:`ExportTarget.write` ``(path, robot, joints) -> ExportReport``,
from what :func:`~wbfriction.export.mapping.joint_exports` made of the fits: ``joints`` maps each exported joint
to its :class:`~wbfriction.export.mapping.JointExport` (F_v, F_c, F_s, armature, the fit's status), already
checked (dissipative, finite). A target declares the suffixes of the file names it writes
(:attr:`ExportTarget.suffixes`); :mod:`wbfriction.export.registry` picks the target of an output by its suffix.
The built-in targets are the URDF's ``<dynamics>`` (:class:`~wbfriction.export.urdf.UrdfTarget`), a MuJoCo MJCF
(:class:`~wbfriction.export.mjcf.MjcfTarget`) and an Isaac Lab actuator YAML
(:class:`~wbfriction.export.isaac.IsaacTarget`).

A new format plugs in with a subclass and one call::

    class CsvTarget(ExportTarget):
        name, suffixes, description = "csv", (".csv",), "joint, F_c, F_v"

        def write(self, path, robot, joints):
            rows = [f"{n},{e.coulomb!r},{e.viscous!r}" for n, e in joints.items() if e.has_friction]
            write_atomic(path, lambda tmp: tmp.write_text("joint,F_c,F_v\\n" + "\\n".join(rows) + "\\n"))
            return self.report(path, joints)

    register_target(CsvTarget())  # wbfriction.export.registry

A target that takes options (Isaac Lab's physics step, :class:`ExportOptions`) returns a copy of itself set with
them from :meth:`ExportTarget.configure`; the others are used as registered.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from wbfriction.export.catalog import TargetKind
from wbfriction.export.drive import DEFAULT_PHYSICS_DT, delay_steps
from wbfriction.export.mapping import JointExport
from wbfriction.model.robot import Robot


@dataclass(frozen=True)
class ExportReport:
    """What one target wrote.

    Attributes:
        path: the file written.
        target: the target's :attr:`ExportTarget.name` (``urdf``, ``mjcf``, ``isaac``), what ``wbfriction export``
            prints after the file (``wrote talos.xml (mjcf)``).
        joints: the joints whose friction the file holds, in the order of the ``joints`` written (the robot's
            actuated order for an export of :func:`~wbfriction.export.mapping.joint_exports` with a robot).
        warnings: what the file holds less exactly than the robot's values, one line each (a PD driver's delay
            rounded to whole physics steps); ``wbfriction export`` prints them.
    """

    path: Path
    target: str
    joints: tuple[str, ...]
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class ExportOptions:
    """What an export is told besides the robot and its joints (``wbfriction export`` options).

    Attributes:
        physics_dt: the physics step [s] of the simulator that counts a PD driver's delay in steps (Isaac Lab:
            ``min_delay``/``max_delay``; ``--physics-dt``), default
            :data:`~wbfriction.export.drive.DEFAULT_PHYSICS_DT`.

    Raises:
        InputError: a physics step that is not a finite number > 0 (naming ``--physics-dt``).
    """

    physics_dt: float = DEFAULT_PHYSICS_DT

    def __post_init__(self) -> None:
        delay_steps(0.0, self.physics_dt)  # raises on a step that is not > 0


class ExportTarget(ABC):
    """A file format the fitted friction is exported to (module docstring).

    Attributes:
        name: the format's short name, printed after each file written (``mjcf``).
        suffixes: the file-name suffixes it writes, lower case with their dot, the one to name first
            (errors list it) first (``(".xml", ".mjcf")``).
        description: what the file is, a few words for the help and errors (``MuJoCo MJCF: damping, ...``).

    A built-in target takes them from its kind in :mod:`wbfriction.export.catalog` (``class MjcfTarget(ExportTarget,
    kind=MJCF)``), which the help reads without importing the target's module.
    """

    name: ClassVar[str]
    suffixes: ClassVar[tuple[str, ...]]
    description: ClassVar[str]
    reads: ClassVar[tuple[str, ...]] = ()
    """The :class:`ExportOptions` fields :meth:`configure` reads (``export`` refuses an option no output reads)."""

    def __init_subclass__(cls, kind: TargetKind | None = None, **kwargs: Any) -> None:
        """A subclass; with ``kind``, its name, suffixes and description are the kind's."""
        super().__init_subclass__(**kwargs)
        if kind is not None:
            cls.name, cls.suffixes, cls.description = kind.name, kind.suffixes, kind.description

    def configure(self, options: ExportOptions) -> ExportTarget:
        """This target set with ``options`` (a copy when it takes any); the default: itself, unchanged.

        Raises:
            InputError: an option value the target cannot use (naming the option).
        """
        return self

    def check(self, robot: Robot) -> None:
        """Refuse a robot the format cannot be written for, before any parameters are read or file written
        (the default: every robot).

        Raises:
            InputError: the robot cannot be exported in this format (the message names the format).
        """
        return None

    @abstractmethod
    def write(self, path: Path, robot: Robot, joints: Mapping[str, JointExport]) -> ExportReport:
        """Write ``joints`` (joint -> simulator parameters, :func:`~wbfriction.export.mapping.joint_exports`) of
        ``robot`` to ``path``, whole or not at all (:func:`~wbfriction.logs.tables.write_atomic`).

        Returns:
            :class:`ExportReport` (:meth:`report`).

        Raises:
            InputError: values the format cannot hold, an output folder that does not exist.
            OutputError: the system refused the write, nothing written.
        """

    def report(self, path: str | Path, joints: Mapping[str, JointExport],
               warnings: tuple[str, ...] = ()) -> ExportReport:
        """The :class:`ExportReport` of ``joints`` written to ``path`` by this target: the joints with friction, and
        ``warnings``."""
        return ExportReport(Path(path), self.name, tuple(name for name, exp in joints.items() if exp.has_friction),
                            tuple(warnings))
