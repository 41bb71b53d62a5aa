"""What a rig is: a robot's set-up (a fixed-base arm, a hung PD-driven robot, a biped on its soles, a quadruped on
point feet), decided once per robot (:func:`~wbfriction.rigs.registry.rig_for`), with its operations: what ``simulate``
runs (:meth:`Rig.simulate`), what ``excite`` designs (:meth:`Rig.design`), the identification route ``identify``
takes (:attr:`Rig.identifies_actuators`) and what ``demo`` shows (:meth:`Rig.demo`). Each operation reads a frozen
dataclass of options (:func:`~wbfriction.options.option` fields): the command line builds it from the options given
and refuses any other.

This module imports nothing heavy: the command line reads the rigs' options as it is loaded; each rig imports what
it runs when it runs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from wbfriction.exceptions import InputError
from wbfriction.progress import Progress, StageProgress, Steps
from wbfriction.report.printed import Printed

if TYPE_CHECKING:
    import pyarrow as pa

    from wbfriction.logs.log import Log
    from wbfriction.model.robot import Robot
    from wbfriction.sim.engines import Engine


@dataclass(frozen=True)
class SimulationOutput:
    """What a rig's simulation gives the command to write and print.

    Attributes:
        log: a :class:`~wbfriction.logs.log.Log` written with :func:`~wbfriction.logs.log.write_log` (a walk), or
            None.
        table: else a table in the log format (:doc:`log format </reference/log-format>`), its metadata included,
            written as it is (:func:`~wbfriction.logs.tables.write_table`).
        summary: what the line ``wrote <file> (<summary>)`` says of it: samples, seconds, what it logs.
        warnings: lines printed after it, each as ``warning: <line>``.
    """

    log: Log | None = None
    table: pa.Table | None = None
    summary: str = ""
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if (self.log is None) == (self.table is None):
            raise ValueError("a simulation's output is a log or a table, one of the two")


@dataclass(frozen=True)
class DesignOutput:
    """What a rig's design of an excitation gives the command to write and print.

    Attributes:
        table: the set-points (:mod:`wbfriction.logs.setpoint_table`), written to every ``-o``.
        document: the prediction (JSON-ready), written to ``--json``.
        figure: writes the figure to the path it is given (``--figure``); None: the rig draws none.
        printed: what is printed (:class:`Printed`), in order.
    """

    table: pa.Table
    document: dict
    figure: Callable[[Path], None] | None
    printed: tuple[Printed, ...] = ()


@dataclass(frozen=True)
class DemoOutput:
    """What a rig's demo gives the command to print: :class:`Printed` items in order and the files it wrote."""

    printed: tuple[Printed, ...] = ()
    files: tuple[Path, ...] = ()


def _quiet(label: str) -> None:
    """Shows nothing."""


def _uncounted(label: str, total: int, unit: str) -> Progress:
    """Counts nothing."""
    return lambda done: None


@dataclass(frozen=True)
class RigProgress:
    """How an operation shows its progress: ``say`` starts a stage of no counted items (its label), ``count`` one of
    a known number (:data:`~wbfriction.progress.Steps`: label, total, unit; it returns the
    :data:`~wbfriction.progress.Progress` told of the items done). The default shows nothing; the command line's
    shows a status line and a bar (:class:`~wbfriction.cli.stages.Stages`, both at once)."""

    say: StageProgress = _quiet
    count: Steps = _uncounted


class Rig:
    """A robot's set-up.

    A subclass names itself (:attr:`name`), says which robots are its own (:meth:`claims`, at its
    :attr:`precedence`: the registered rig of lowest precedence that claims a robot is its rig), what a refusal says
    it is (:meth:`what`), the options of each operation (:attr:`simulation`, :attr:`design_options`,
    :attr:`demo_options`; None: it has no such operation) and the operations.
    """

    name: ClassVar[str]
    """The rig's name, for messages and the registry."""
    precedence: ClassVar[float]
    """Its place among the rigs: the one of lowest precedence that claims a robot is its rig."""
    simulation: ClassVar[type | None] = None
    """The options ``simulate`` reads (a frozen dataclass of :func:`~wbfriction.options.option` fields)."""
    design_options: ClassVar[type | None] = None
    """The options ``excite`` reads; None: no design."""
    demo_options: ClassVar[type | None] = None
    """The options ``demo`` reads; None: no demo."""
    motion: ClassVar[str | None] = None
    """The motion an engine simulates for it (an :class:`~wbfriction.sim.engines.Engine` method: ``walk``,
    ``quadruped``); None: it runs its own simulator, no engine."""
    identifies_actuators: ClassVar[bool] = False
    """The identification route ``identify`` takes: the PD drivers' actuators (``--actuator pd``: armature,
    friction, encoder offsets, delay; a hung robot) or, False, the inertia model and the friction (thesis 2.4)."""

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        """What ``robot`` on this rig is, as a refusal says it (``robot 'panda' is a fixed-base arm ...``)."""
        return f"robot '{robot.name}' is on rig '{self.name}'"

    def claims(self, robot: Robot, actuator: str | None) -> bool:
        """Whether ``robot`` driven by ``actuator`` (``--actuator``: ``torque``, ``pd`` or None, not given) is its."""
        raise NotImplementedError

    def engines(self) -> tuple[Engine, ...]:
        """The registered engines that simulate its :attr:`motion`, in precedence order (none without one)."""
        from wbfriction.sim.engines import engines

        return () if self.motion is None else tuple(e for e in engines() if e.runs(self.motion))

    def engine(self, robot: Robot, name: str | None) -> Engine | None:
        """The engine ``--simulator`` ``name`` names (None: the first of :meth:`engines`), None for a rig without
        one.

        Raises:
            InputError: an engine that does not simulate the rig's motion (naming those that do).
        """
        runs = self.engines()
        if not runs:
            return None
        found = runs[0] if name is None else next((e for e in runs if e.name == name), None)
        if found is None:
            raise InputError(f"--simulator {name}: {self.what(robot)}: it runs on {', '.join(e.name for e in runs)}")
        return found

    def engine_options(self, engine: Engine | None) -> type | None:
        """The options ``engine`` reads for this rig beyond :attr:`simulation` (a frozen dataclass), or None."""
        return None

    def simulate(self, robot: Robot, options: Any, engine: Engine | None, engine_options: Any,
                 progress: RigProgress) -> SimulationOutput:
        """Simulate ``robot`` with known friction.

        Args:
            robot: the robot, claimed.
            options: an instance of :attr:`simulation`.
            engine: the engine (:meth:`engine`), None for a rig without one.
            engine_options: an instance of :meth:`engine_options`, or None.
            progress: where it shows its progress.

        Raises:
            InputError: options or a friction file it cannot run with.
        """
        raise InputError(f"{self.what(robot)}: simulate runs no such set-up")

    def design(self, robot: Robot, options: Any, progress: RigProgress) -> DesignOutput:
        """The motion to record, designed so that its identification determines every parameter (``options``: an
        instance of :attr:`design_options`).

        Raises:
            InputError: a robot or options it cannot design for.
        """
        raise InputError(f"{self.what(robot)}: excite designs no motion for it")

    def demo(self, robot: Robot, options: Any, engine: Engine | None, output_dir: Path,
             progress: RigProgress) -> DemoOutput:
        """Its study in a few minutes: simulate, estimate, fit, against the truth, into ``output_dir``."""
        raise InputError(f"{self.what(robot)}: demo shows nothing of it")

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"
