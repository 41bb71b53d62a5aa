"""What an engine is: a simulator the rigs' motions run in (:mod:`wbfriction.rigs`), chosen per run (``simulate
--simulator``, ``demo --simulator``). A rig says which engines run it (:attr:`Rig.engines
<wbfriction.rigs.base.Rig.engines>`); an engine gives the motions it simulates: a biped's walk (:meth:`Engine.walk`)
and a quadruped's gait (:meth:`Engine.quadruped`).

This module imports nothing heavy: the command line reads the engines' names and options as it is loaded; each
engine imports its simulator when it runs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from collections.abc import Mapping

    from wbfriction.fit.terms import TermFit
    from wbfriction.friction.models import ModelParams
    from wbfriction.model.robot import Robot
    from wbfriction.progress import Progress
    from wbfriction.sim.common import SimulationResult
    from wbfriction.sim.quadruped import QuadrupedOptions, QuadrupedRun
    from wbfriction.walking.quadruped import QuadrupedReference
    from wbfriction.walking.reference import WalkingReference


class Engine:
    """A simulator a rig's motion runs in.

    A subclass names itself (:attr:`name`, what ``--simulator`` takes), places itself among the engines
    (:attr:`precedence`: the one of lowest precedence a rig runs on is its default), says what it is (:attr:`what`)
    and whether its contacts are soft (:attr:`soft_contacts`), gives the options of a walk in it
    (:attr:`walk_options`: a frozen dataclass of :func:`~wbfriction.options.option` fields) and simulates the motions
    it runs (:meth:`walk`, :meth:`quadruped`; not overridden: it does not run that motion).
    """

    name: ClassVar[str]
    """What ``--simulator`` names it by."""
    precedence: ClassVar[float]
    """Its place among the engines: a rig's default engine is the one of lowest precedence it runs on."""
    what: ClassVar[str]
    """What it is, as the help and the messages say it (``ideal (rigid contacts, thesis 6.1)``)."""
    soft_contacts: ClassVar[bool] = False
    """Whether its contacts are soft bodies: a quadruped's feet are spheres (:attr:`Robot.foot_radius
    <wbfriction.model.robot.Robot.foot_radius>`), contact flags are measured from the forces."""
    walk_options: ClassVar[type | None] = None
    """The options a walk in it reads beyond the rig's (a frozen dataclass), or None: none."""

    def walk(self, robot: Robot, reference: WalkingReference, friction: Mapping[str, ModelParams] | None,
             terms: Mapping[str, TermFit] | None, settings: WalkSettings, options: Any,
             progress: Progress | None) -> SimulationResult:
        """Simulate ``robot`` walking ``reference`` with the injected ``friction`` and ``terms`` (None: thesis
        Table 6.1 on the legs), the rig's ``settings`` and the engine's ``options`` (an instance of
        :attr:`walk_options`).

        Raises:
            InputError: options it cannot run with.
        """
        raise NotImplementedError(f"engine '{self.name}' does not simulate a walk")

    def quadruped(self, robot: Robot, reference: QuadrupedReference, options: QuadrupedOptions,
                  progress: Progress | None = None, sensors: Any = None) -> QuadrupedRun:
        """Simulate a quadruped following ``reference`` with ``options``; ``sensors``: the engine's own sensor
        noise (None: its default)."""
        raise NotImplementedError(f"engine '{self.name}' does not simulate a quadruped")

    def runs(self, motion: str) -> bool:
        """Whether it simulates ``motion`` (``"walk"`` or ``"quadruped"``, a method's name): it overrides it."""
        return getattr(type(self), motion) is not getattr(Engine, motion)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"


@dataclass(frozen=True)
class WalkSettings:
    """What a biped's walk asks of every engine.

    Attributes:
        substeps: physics steps per control period; None: the engine's default.
        log_base: write the base pose to the log.
        temperature: the joints' temperature at the log's start and end [°C]; None: not logged.
    """

    substeps: int | None = None
    log_base: bool = True
    temperature: tuple[float, float] | None = None
