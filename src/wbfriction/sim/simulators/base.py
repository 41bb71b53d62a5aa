"""What a simulator is to ``wbfriction simulate``: a kind (:class:`SimulatorKind`) that claims a robot, reads some of
the command's options and runs, giving what to write (:class:`SimulationOutput`); the registry
(:mod:`.registry`) asks the kinds in precedence order.

This module, the registry and the built-in kinds import nothing heavy (no NumPy, Pinocchio, pyarrow or MuJoCo):
each kind imports its simulator when it runs, so that the command line knows the simulators' names (its help,
``--simulator``'s check) without loading them.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from wbfriction.progress import Progress

if TYPE_CHECKING:
    import pyarrow as pa

    from wbfriction.logs.log import Log
    from wbfriction.model.robot import Robot


@dataclass(frozen=True)
class SimulationOutput:
    """What a simulator's run gives the command to write and print.

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


class SimulationProgress:
    """How a run shows its progress; this one shows nothing (the command line's shows a status line and a bar)."""

    @contextmanager
    def stage(self, text: str) -> Iterator[None]:
        """Around a stage without a count (planning a gait): ``text`` says what it does."""
        yield

    @contextmanager
    def steps(self, total: int) -> Iterator[Progress | None]:
        """Around the simulation of ``total`` samples: yields the callable told how many are done since its last
        call (:data:`~wbfriction.progress.Progress`), or None."""
        yield None


class SimulatorKind:
    """A simulator as ``wbfriction simulate`` runs it.

    A subclass names itself (:attr:`name`), says which robots are its own (:meth:`claims`, at its
    :attr:`precedence`: the registered kind of lowest precedence that claims a robot runs it), what a refusal says
    it is (:meth:`what`), which of the command's options it reads (:attr:`options`: any other given is refused
    before the work) and runs (:meth:`run`).
    """

    name: ClassVar[str]
    """The simulator's name: what messages call it, and, if :attr:`chosen`, what ``--simulator`` names it by."""
    options: ClassVar[tuple[str, ...]]
    """The ``simulate`` command's parameters it reads (``duration``, ``excitation_seed``), beyond those every
    simulator reads (the output, the robot, the actuator): the command refuses any other given."""
    precedence: ClassVar[float]
    """Its place among the simulators: the one of lowest precedence that claims a robot runs it."""
    chosen: ClassVar[bool] = True
    """Whether ``--simulator <name>`` chooses it (the built-in ``ideal`` and ``mujoco``); the kinds the robot alone
    chooses (a quadruped, a hung PD-driven robot, an arm) are not ``--simulator`` values."""

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        """What running ``robot`` driven by ``actuator`` (as :meth:`claims` takes it) in it is, as a refusal says it
        (``robot 'panda' is a fixed-base arm ...``)."""
        return f"robot '{robot.name}' runs in simulator '{self.name}'"

    def claims(self, robot: Robot, actuator: str | None, simulator: str) -> bool:
        """Whether it runs ``robot`` driven by ``actuator`` (``--actuator``: ``torque``, ``pd`` or None, not given)
        with ``--simulator`` ``simulator``; by default when ``simulator`` is its name."""
        return simulator == self.name

    def run(self, robot: Robot, values: Mapping[str, Any], friction: Path | None,
            progress: SimulationProgress) -> SimulationOutput:
        """Simulate ``robot`` (a kind of what it claims).

        Args:
            robot: the robot, claimed.
            values: the value of every parameter of the ``simulate`` command by name (those of :attr:`options`
                given or at their defaults; the others at their defaults).
            friction: the ``--friction`` TOML (``[friction.<group or joint>]`` tables), or None: the kind's default
                friction.
            progress: where it shows its progress.

        Raises:
            InputError: options or a friction file it cannot run with.
        """
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"
