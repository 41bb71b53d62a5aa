"""A biped on its soles (a floating base whose every contact fixes it, thesis 4.4): ``simulate`` walks it, or plays
its one-foot stance (``--play``), in an engine (:mod:`wbfriction.sim.engines`); ``excite`` designs one leg's
excitation while it stands on the other foot (:func:`~wbfriction.excite.one_foot.one_foot_reference`); ``demo`` shows
the thesis's simulation study (Tables 6.1/6.2, Fig. 6.1-6.3; on soft contacts, Fig. 6.4-6.5)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Optional

from wbfriction.exceptions import InputError
from wbfriction.options import option
from wbfriction.report.printed import Printed
from wbfriction.rigs.base import DemoOutput, DesignOutput, Rig, RigProgress, SimulationOutput
from wbfriction.rigs.standing import StandingDesignOptions, require_feet, standing_figure
from wbfriction.sim.engines import WalkSettings
from wbfriction.walking.options import GaitOptions

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.sim.engines import Engine
    from wbfriction.walking.reference import WalkingReference

GAIT = GaitOptions()


@dataclass(frozen=True)
class BipedSimulation:
    """What ``simulate`` reads of a biped in every engine (each engine reads its own beyond these:
    :attr:`Engine.walk_options <wbfriction.sim.engines.Engine.walk_options>`).

    Attributes:
        friction: TOML of the injected friction; None: thesis Table 6.1 on the legs.
        play: a one-foot stance ``excite`` wrote, played instead of a walk.
        substeps: physics steps per control period; None: the engine's default.
        log_base: write the base pose to the log.
        gait: forward, sideways, turning, both or combined; steps: per direction;
            step_length, step_width [m]; turn_angle [rad] per turning step; lift_height: swing-foot apex [m].
    """

    friction: Optional[Path] = option(None)
    play: Optional[Path] = option(None)
    substeps: Optional[int] = option(None, quantity="substeps")
    log_base: bool = option(True)
    gait: str = option(GAIT.gait, motion=True)
    steps: int = option(GAIT.steps, motion=True)
    step_length: float = option(GAIT.step_length, motion=True)
    step_width: float = option(GAIT.step_width, motion=True)
    turn_angle: float = option(GAIT.turn_angle, motion=True)
    lift_height: float = option(GAIT.lift_height, motion=True)

    def walk(self, robot: Robot) -> GaitOptions:
        """The walk these options give.

        Raises:
            InputError: a quadruped's gait (``trot``).
        """
        from wbfriction.walking.options import GAITS
        from wbfriction.walking.quadruped import GAITS as QUADRUPED_GAITS

        if self.gait not in GAITS:
            raise InputError(f"--gait {self.gait}: a quadruped's gait; robot '{robot.name}' walks forward, sideways, "
                             "turning, both or combined" if self.gait in QUADRUPED_GAITS else
                             f"--gait {self.gait}: robot '{robot.name}' walks forward, sideways, turning, both or "
                             "combined")
        return GaitOptions(gait=self.gait, steps=self.steps, step_length=self.step_length,
                           step_width=self.step_width, turn_angle=self.turn_angle, lift_height=self.lift_height)


@dataclass(frozen=True)
class BipedDesignOptions(StandingDesignOptions):
    """What ``excite`` reads of a biped: a standing design's options, and the foot it stands on (``stance``)."""

    stance: Literal["left", "right"] = option("left")


@dataclass(frozen=True)
class BipedDemoOptions:
    """What ``demo`` reads of a biped: steps per direction of the combined walk (on soft contacts: of the forward
    walks of Fig. 6.4-6.5 too, at most 5)."""

    steps: int = option(GAIT.steps)


class BipedRig(Rig):
    """A floating base on soles (every contact fixes the base alone: thesis 4.4), walking in an engine."""

    name, precedence, motion = "biped", 40, "walk"
    simulation, design_options, demo_options = BipedSimulation, BipedDesignOptions, BipedDemoOptions

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' is a biped on {robot.stands_on}"

    def claims(self, robot: Robot, actuator: str | None) -> bool:
        return robot.floating_base and not robot.partial_contacts

    def engine_options(self, engine: Engine | None) -> type | None:
        return None if engine is None else engine.walk_options

    def simulate(self, robot: Robot, options: Any, engine: Engine | None, engine_options: Any,
                 progress: RigProgress) -> SimulationOutput:
        from wbfriction.fit.targets import load_friction_spec

        assert engine is not None  # a rig with a motion has one (Rig.engine)
        o: BipedSimulation = options
        ref = self.reference(robot, o, progress)
        spec = None if o.friction is None else load_friction_spec(o.friction, robot.groups, robot.torque_controlled)
        settings = WalkSettings(substeps=o.substeps, log_base=o.log_base,
                                temperature=None if spec is None else spec.temperature)
        advance = progress.count("simulate", len(ref), "samples")
        result = engine.walk(robot, ref, None if spec is None else spec.params, None if spec is None else spec.terms,
                             settings, engine_options, advance)
        pulls = tuple(f"{p.frame} pulled on the ground from {p.start:.3f} s to {p.end:.3f} s ({p.samples} samples, "
                      f"down to {p.min_force:.1f} N)" for p in result.pulls())
        return SimulationOutput(log=result.log, summary=f"{len(result.log)} samples, {result.log.time[-1]:.1f} s",
                                warnings=pulls)

    @staticmethod
    def reference(robot: Robot, options: BipedSimulation, progress: RigProgress) -> WalkingReference:
        """The reference to simulate: the played table's one-foot stance, else the walk the options give.

        Raises:
            InputError: what those raise; a walk the robot cannot make.
        """
        from wbfriction.rigs.played import played_stance
        from wbfriction.walking.reference import walking_reference

        if options.play is not None:
            progress.say(f"rebuilding the stance of {options.play.name} (its IK at every sample)")
            return played_stance(robot, options.play)
        gait = options.walk(robot)
        progress.say(f"planning {gait.steps} steps ({gait.gait})")
        return walking_reference(robot, gait)

    def design(self, robot: Robot, options: Any, progress: RigProgress) -> DesignOutput:
        from wbfriction.excite.document import one_foot_document, one_foot_setpoints
        from wbfriction.excite.one_foot import OneFootOptions, one_foot_reference, swing_bounds
        from wbfriction.report.excite_tables import swing_printed

        o: BipedDesignOptions = options
        require_feet(robot, 2, "a biped's one-foot stance")
        stance = OneFootOptions(stance=o.stance, design=o.excite(OneFootOptions().design.harmonics))
        progress.say(f"designing the swing leg's series, then the stance on the {stance.stance} foot (its IK at "
                     "every sample)")
        excitation = one_foot_reference(robot, stance)
        doc = one_foot_document(robot, excitation, stance, swing_bounds(robot, excitation, stance))
        table = one_foot_setpoints(robot, excitation, stance)
        figure = standing_figure(robot, excitation, table, doc, f"{robot.name} on its {stance.stance} foot: the swing "
                                 "leg within its posture band; Cramér-Rao bound / weak limit")
        line = (f"ZMP {doc['zmp_margin'] * 1e3:.1f} mm inside the {doc['stance']} sole's edges (at least "
                f"{doc['limits']['zmp_margin'] * 1e3:.0f}); the swing sole {doc['clearance'] * 1e3:.1f} mm above "
                f"the ground (at least {doc['limits']['clearance'] * 1e3:.0f})")
        return DesignOutput(table, doc, figure, (swing_printed(doc, f"The swing leg on the {doc['stance']} foot"),
                                                 Printed(line)))

    def demo(self, robot: Robot, options: Any, engine: Engine | None, output_dir: Path,
             progress: RigProgress) -> DemoOutput:
        from wbfriction.rigs.biped_demo import realistic_demo, thesis_demo

        assert engine is not None
        steps = options.steps
        return (realistic_demo if engine.soft_contacts else thesis_demo)(robot, output_dir, steps, progress)
