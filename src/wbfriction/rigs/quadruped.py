"""A quadruped on point feet (a floating base whose contacts do not fix it alone): ``simulate`` walks its gait, or
plays its three-feet stance (``--play``), in an engine (:mod:`wbfriction.sim.engines`); ``excite`` designs one leg's
excitation while it stands on the other three (:func:`~wbfriction.excite.tripod.tripod_reference`); ``demo`` shows
what a gait gives each joint (:func:`~wbfriction.studies.quadruped.run_quadruped`)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Optional

from wbfriction.exceptions import InputError, OptionError
from wbfriction.options import option
from wbfriction.report.printed import Printed
from wbfriction.rigs.base import DemoOutput, DesignOutput, Rig, RigProgress, SimulationOutput
from wbfriction.rigs.standing import StandingDesignOptions, require_feet, standing_figure
from wbfriction.sim.noise_options import SensorsFileOptions

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.sim.engines import Engine
    from wbfriction.sim.logger import LoggerOptions
    from wbfriction.sim.quadruped_mujoco import QuadrupedNoise
    from wbfriction.walking.quadruped import QuadrupedReference

PLAYED_SUBSTEPS = 8
"""The physics steps per 2 ms period when a three-feet stance is played and ``--substeps`` is not given: 0.25 ms
(4 kHz). At the gaits' 0.5 ms the explicit integration of the injected Coulomb term chatters about zero velocity on
the light calf and the front right calf's F_v comes out 4.5 % low; at 0.25 ms every swing joint's F_c and F_v within
0.6 % (``tests/excite/test_tripod.py``)."""
STANDING_RATE = 500.0
"""A quadruped's default set-points rate [Hz]: its simulators' control rate (:class:`~wbfriction.excite.tripod.
TripodOptions`' own)."""


@dataclass(frozen=True)
class QuadrupedSimulation(SensorsFileOptions):
    """What ``simulate`` reads of a quadruped, beyond the sensor noise (no delay: its drivers' is the robot's
    ``[pd]`` delay).

    Attributes:
        actuator: how its joints are driven: torque (None: the default) or pd (its drivers sent the set-points).
        friction: TOML of the injected friction per joint; None: the simulator's default.
        play: a three-feet stance ``excite`` wrote, played instead of a gait.
        substeps: physics steps per 2 ms period; None: 4 (8 playing a stance, :data:`PLAYED_SUBSTEPS`).
        foot_forces: the feet's force columns logged: none, normal or 3d.
        gait: stand, step, trot or walk; duration [s] of gait; speed: forward speed [m/s]; each None: the gait's
            default (:class:`~wbfriction.walking.quadruped.GaitOptions`); excitation_seed: its swings and sway.
        sensor_noise: ``none`` (the options' noise alone) or ``unitree``: on an engine with sensors of its own
            (MuJoCo) a Unitree-like robot's (:data:`~wbfriction.sim.quadruped_mujoco.UNITREE_NOISE`; a raw log's
            IMU orientation within :data:`~wbfriction.sim.logger.ORIENTATION_STD`, its foot counts within the foot
            forces' 2 N), seeded by ``noise_seed``.
        logger: ``full`` (the project's log: every column the simulator knows) or ``raw`` (the log a robot's logger
            writes, the truth beside it: :func:`~wbfriction.sim.logger.write_raw_log`).
        logger_period, imu_period: the raw logger's and the IMU's periods [ms]; angles: ``angles`` or ``cos-sin``;
            kt_error: the torque constants' error bound (a share); foot_counts: raw foot-force counts logged; each
            None: :class:`~wbfriction.sim.logger.LoggerOptions`' default (raw only; the draws seeded by
            ``noise_seed``).
        contacts: a soft-contact engine's (MuJoCo's) feet: ``soft`` (its default contacts: a stance foot creeps
            about 1.5 cm/s) or ``firm`` (feet that hold: :func:`~wbfriction.sim.quadruped_mjcf.firm_contacts`).
    """

    actuator: Optional[Literal["torque", "pd"]] = option(None)
    friction: Optional[Path] = option(None)
    play: Optional[Path] = option(None)
    substeps: Optional[int] = option(None, quantity="substeps")
    foot_forces: Literal["none", "normal", "3d"] = option("none")
    gait: Optional[str] = option(None, motion=True)
    duration: Optional[float] = option(None, quantity="duration", motion=True)
    excitation_seed: int = option(0, quantity="seed", motion=True)
    speed: Optional[float] = option(None, motion=True)
    sensor_noise: Literal["none", "unitree"] = option("none")
    logger: Literal["full", "raw"] = option("full")
    logger_period: Optional[float] = option(None)
    imu_period: Optional[float] = option(None)
    angles: Optional[Literal["angles", "cos-sin"]] = option(None)
    kt_error: Optional[float] = option(None)
    foot_counts: Optional[bool] = option(None)
    contacts: Literal["soft", "firm"] = option("soft")

    def logger_options(self, robot: Robot) -> LoggerOptions | None:
        """The raw logger's options (None: the full log), checked with the robot before any simulation.

        Raises:
            InputError: a raw logger's option with ``logger = "full"``; what
                :func:`~wbfriction.sim.logger.check_raw_robot` refuses.
            OptionError: what :class:`~wbfriction.sim.logger.LoggerOptions` refuses.
        """
        from wbfriction.sim.logger import ORIENTATION_STD, LoggerOptions, check_raw_robot
        from wbfriction.sim.quadruped_mujoco import UNITREE_NOISE

        given = {"period": self.logger_period, "imu_period": self.imu_period, "angles": self.angles,
                 "kt_error": self.kt_error, "foot_counts": self.foot_counts}
        flags = {"period": "--logger-period", "imu_period": "--imu-period", "angles": "--angles",
                 "kt_error": "--kt-error", "foot_counts": "--foot-counts"}
        if self.logger == "full":
            named = [flags[k] for k, v in given.items() if v is not None]
            if named:
                raise InputError(f"{named[0]}: an option of the raw log (--logger raw); the full log has none")
            return None
        check_raw_robot(robot)
        values: dict[str, Any] = {k: v for k, v in given.items() if v is not None}
        for k in ("period", "imu_period"):  # given in ms
            if k in values:
                if not values[k] > 0:
                    raise OptionError(flags[k], values[k], "> 0 [ms]")
                values[k] = values[k] * 1e-3
        if self.sensor_noise == "unitree":
            values.update(orientation_std=ORIENTATION_STD, count_std=UNITREE_NOISE.force_std)
        return LoggerOptions(seed=self.noise_seed or 0, **values)

    def engine_noise(self, engine: Engine) -> QuadrupedNoise | None:
        """The engine's own sensor noise (``sensor_noise``; None: the options' noise alone).

        Raises:
            InputError: ``unitree`` on an engine without sensors of its own, or with a noise option it replaces.
        """
        from wbfriction.sim.quadruped_mujoco import UNITREE_NOISE

        if self.sensor_noise == "none":
            return None
        if not engine.soft_contacts:
            raise InputError(f"--sensor-noise {self.sensor_noise}: engine '{engine.name}' has no sensors of its own "
                             "(its noise: --position-noise, --encoder-bits, --torque-noise); use --simulator mujoco")
        replaced = [f for f, v in (("--sensors", self.sensors), ("--position-noise", self.position_noise),
                                   ("--encoder-bits", self.encoder_bits), ("--torque-noise", self.torque_noise))
                    if v is not None]
        if replaced:
            raise InputError(f"{replaced[0]}: --sensor-noise {self.sensor_noise} gives every sensor's noise "
                             "(only --noise-seed with it)")
        return replace(UNITREE_NOISE, seed=self.noise_seed or 0)


@dataclass(frozen=True)
class QuadrupedDesignOptions(StandingDesignOptions):
    """What ``excite`` reads of a quadruped: a standing design's options (its rate its simulators' control rate),
    and the leg lifted (``swing``: FL, FR, RL, RR or its foot frame's name)."""

    rate: float = option(STANDING_RATE, quantity="rate")
    swing: str = option("FR")


@dataclass(frozen=True)
class QuadrupedDemoOptions:
    """What ``demo`` reads of a quadruped (:class:`~wbfriction.studies.quadruped.QuadrupedCase`): the gait, the
    drive (torque or pd), the feet's forces logged, a real robot's sensor noise, the simulated time [s] and the
    seed."""

    gait: Literal["stand", "step", "trot", "walk"] = option("trot")
    drive: Literal["torque", "pd"] = option("torque")
    foot_forces: Literal["none", "normal", "3d"] = option("none")
    noise: bool = option(False)
    duration: float = option(8.0, quantity="duration")
    seed: int = option(0, quantity="seed")


class QuadrupedRig(Rig):
    """A floating base on point feet (contacts that do not fix the base alone), walking in an engine."""

    name, precedence, motion = "quadruped", 10, "quadruped"
    simulation, design_options, demo_options = QuadrupedSimulation, QuadrupedDesignOptions, QuadrupedDemoOptions

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' stands on {robot.stands_on} (a walking quadruped)"

    def claims(self, robot: Robot, actuator: str | None) -> bool:
        return robot.floating_base and robot.partial_contacts

    def simulate(self, robot: Robot, options: Any, engine: Engine | None, engine_options: Any,
                 progress: RigProgress) -> SimulationOutput:
        from wbfriction.sim.quadruped import QuadrupedOptions

        assert engine is not None  # a rig with a motion has one (Rig.engine)
        o: QuadrupedSimulation = options
        logger, sensors = o.logger_options(robot), o.engine_noise(engine)  # refused before the simulation
        if o.contacts == "firm" and not engine.soft_contacts:
            raise InputError(f"--contacts {o.contacts}: engine '{engine.name}' welds the standing feet (no soft "
                             "contacts to firm up); use --simulator mujoco")
        opts = QuadrupedOptions(**self.run_options(robot, options), contacts=o.contacts)
        ref, motion = self.reference(robot, options, progress)
        run = engine.quadruped(robot, ref, opts, progress=progress.count("simulate", len(ref), "samples"),
                               sensors=sensors)
        drive = "PD set-points" if opts.drive == "pd" else "joint torques"
        normal = run.force[..., 2][run.log.contact]
        pulled = () if not normal.size or normal.min() >= 0 else \
            (f"a foot pulled on the ground at {int((normal < 0).sum())} samples (down to {normal.min():.1f} N)",)
        if logger is not None:
            from wbfriction.sim.logger import logged_summary, write_raw_log

            table = write_raw_log(run, robot, logger)
            return SimulationOutput(table=table, summary=logged_summary(table, f"{len(ref) * ref.dt:g} s, {motion}"),
                                    warnings=pulled)
        return SimulationOutput(log=run.log, summary=f"{len(run.log)} samples, {len(ref) * ref.dt:g} s, {motion}, "
                                                     f"{drive}", warnings=pulled)

    @staticmethod
    def run_options(robot: Robot, o: QuadrupedSimulation) -> dict[str, Any]:
        """The :class:`~wbfriction.sim.quadruped.QuadrupedOptions` fields the options give: ``drive`` (the
        ``actuator``), the sensor noise, ``foot_forces``, ``physics_dt`` (2 ms periods over ``substeps``) and the
        friction; the torque drive's gains ``kp``, ``kd``, the defaults' scaled to the robot's size
        (:func:`~wbfriction.walking.scale.robot_scale`: the Go2's as they are).

        Raises:
            InputError: a sensor delay; a friction file with terms beyond velocity or a temperature; a gait of a
                walk.
        """
        from wbfriction.fit.targets import load_friction_spec
        from wbfriction.sim.quadruped import QuadrupedOptions
        from wbfriction.walking.quadruped import GAITS
        from wbfriction.walking.scale import robot_scale

        noise, lag = o.noise()
        if lag:
            raise InputError(f"{o.sensors}: delay: a walking quadruped's simulation has no measurement delay (its "
                             "drivers' is the robot's [pd] delay)")
        substeps = PLAYED_SUBSTEPS if o.substeps is None and o.play is not None else o.substeps
        if o.gait is not None and o.gait not in GAITS:
            raise InputError(f"--gait {o.gait}: robot '{robot.name}' stands on {robot.stands_on}: its gaits are "
                             f"{', '.join(GAITS)}")
        spec = None if o.friction is None else load_friction_spec(o.friction, robot.groups, robot.actuated)
        if spec is not None and (spec.terms or spec.temperature is not None):
            raise InputError(f"{o.friction}: a walking quadruped's simulation takes friction models per joint, "
                             "without terms beyond velocity or a temperature")
        scale = robot_scale(robot)
        return {"drive": o.actuator or "torque", "noise": noise, "foot_forces": o.foot_forces,
                "kp": QuadrupedOptions.kp * scale.torque, "kd": QuadrupedOptions.kd * scale.damping,
                **({} if substeps is None else {"physics_dt": 0.002 / substeps}),
                "friction": None if spec is None else spec.params}

    @staticmethod
    def reference(robot: Robot, o: QuadrupedSimulation, progress: RigProgress) -> tuple[QuadrupedReference, str]:
        """The reference to simulate and its name: the played table's three-feet stance, else the gait planned."""
        from wbfriction.rigs.played import played_tripod
        from wbfriction.walking.quadruped import quadruped_reference
        from wbfriction.walking.scale import scaled_gait

        if o.play is not None:
            progress.say(f"rebuilding the stance of {o.play.name} (its IK at every sample)")
            ref = played_tripod(robot, o.play)
            return ref, f"{robot.contact_frames[int(ref.contact[0].argmin())]} swung on three feet"
        given: dict[str, Any] = {"gait": o.gait, "duration": o.duration, "speed": o.speed}  # None: its default
        gait = scaled_gait(robot, given, o.excitation_seed)  # the defaults to the robot's size
        progress.say(f"planning {gait.duration:g} s ({gait.gait})")
        return quadruped_reference(robot, gait), gait.gait

    def design(self, robot: Robot, options: Any, progress: RigProgress) -> DesignOutput:
        from wbfriction.excite.document import tripod_document, tripod_setpoints
        from wbfriction.excite.tripod import TripodOptions, swing_bounds, tripod_reference
        from wbfriction.report.excite_tables import swing_printed

        o: QuadrupedDesignOptions = options
        require_feet(robot, 4, "a quadruped's stance on three of four point feet", model="point")
        tripod = TripodOptions(swing=o.swing, design=o.excite(TripodOptions().design.harmonics))
        progress.say("designing the swing leg's series, then the stance on the three other feet (its IK at every "
                     "sample)")
        excitation = tripod_reference(robot, tripod)
        doc = tripod_document(robot, excitation, tripod, swing_bounds(robot, excitation, tripod))
        leg = doc["swing_foot"].split("_")[0]
        table = tripod_setpoints(robot, excitation, tripod)
        figure = standing_figure(robot, excitation, table, doc, f"{robot.name} on three feet, its {leg} leg swung "
                                 "within its posture band; Cramér-Rao bound / weak limit")
        mm = {n: f"{doc[n] * 1e3:.1f} mm (at least {doc['limits'][n] * 1e3:.0f})"
              for n in ("com_margin", "zmp_margin", "clearance", "spacing")}
        return DesignOutput(table, doc, figure, (
            swing_printed(doc, f"The {leg} leg swung, on {', '.join(f.split('_')[0] for f in doc['stance_feet'])}"),
            Printed(f"centre of mass {mm['com_margin']} and ZMP {mm['zmp_margin']} inside the stance triangle's "
                    f"edges; the swing foot {mm['clearance']} above the ground, {mm['spacing']} from the other legs")))

    def demo(self, robot: Robot, options: Any, engine: Engine | None, output_dir: Path,
             progress: RigProgress) -> DemoOutput:
        from rich.markup import escape

        from wbfriction.report.terminal import determination_table
        from wbfriction.studies.quadruped import QuadrupedCase, case_robot, fits_markdown, run_quadruped, write_study

        assert engine is not None
        o: QuadrupedDemoOptions = options
        case = QuadrupedCase(simulator=engine.name, gait=o.gait, drive=o.drive, foot_forces=o.foot_forces,
                             noise=o.noise, duration=o.duration, seed=o.seed)
        r = case_robot(robot, case)
        study = run_quadruped(r, case, progress=progress.say)
        files = write_study(r, study, output_dir)
        return DemoOutput((Printed(determination_table(study.shares)),
                           Printed(escape(fits_markdown(study)), soft_wrap=True)), tuple(files))
