"""A PD-driven robot hung, its base fixed: ``simulate`` has its drivers track ramps and chirps
(:func:`~wbfriction.sim.hung.simulate_hung`); ``excite`` designs ramps whose ``identify --actuator pd`` is predicted
to determine every actuator parameter (:func:`~wbfriction.excite.pd_design.design_pd`); ``identify --actuator pd``
identifies its actuators."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Optional

from wbfriction.exceptions import InputError
from wbfriction.excite.options import PD_EXCITE
from wbfriction.options import option
from wbfriction.quantities import check_option
from wbfriction.report.printed import Printed
from wbfriction.rigs.base import DemoOutput, DesignOutput, Rig, RigProgress, SimulationOutput
from wbfriction.sim.options import FrictionMode
from wbfriction.sim.pd_options import DriverNoise, HungOptions, SetpointKind, SetpointOptions

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.sim.engines import Engine

HUNG = HungOptions()
SETPOINTS = SetpointOptions()


@dataclass(frozen=True)
class HungSimulation:
    """What ``simulate`` reads of a hung PD-driven robot.

    Attributes:
        friction: TOML of the injected friction per joint; None: Coulomb-viscous on every joint.
        play: a set-points table ``excite`` wrote, played instead of ramps and chirps.
        substeps: physics steps per control period.
        mujoco_friction: ``model`` (a joint torque) or ``mujoco`` (MuJoCo's frictionloss and damping).
        position_noise, encoder_bits, velocity_noise, noise_seed: the drivers' noise, each overriding
            ``driver_noise``'s level (``real``: :data:`~wbfriction.sim.pd_options.REAL_DRIVER`; ``none``).
        delay: the drivers' set-point delay [ms]; None: the robot's ``[pd]`` delay.
        friction_timeconst: the friction-loss constraint's time constant [s]; None: two physics steps.
        duration: seconds of set-points; excitation_seed: their seed; setpoints: ramps, chirps or both.
    """

    friction: Optional[Path] = option(None)
    play: Optional[Path] = option(None)
    substeps: int = option(HUNG.substeps, quantity="substeps")
    mujoco_friction: FrictionMode = option(HUNG.friction)
    position_noise: Optional[float] = option(None, quantity="position_std")
    encoder_bits: Optional[int] = option(None, quantity="encoder_bits")
    velocity_noise: Optional[float] = option(None, quantity="velocity_std")
    noise_seed: Optional[int] = option(None, quantity="seed")
    driver_noise: Literal["real", "none"] = option("real")
    delay: Optional[float] = option(None, quantity="delay_ms")
    friction_timeconst: Optional[float] = option(None)
    duration: float = option(HUNG.duration, quantity="duration", motion=True)
    excitation_seed: int = option(0, quantity="seed", motion=True)
    setpoints: SetpointKind = option(SETPOINTS.kind, motion=True)

    def drivers(self) -> DriverNoise:
        """The PD drivers' noise: ``driver_noise``'s levels, each option given overriding its level."""
        import math

        from wbfriction.sim.pd_options import REAL_DRIVER

        noise = REAL_DRIVER if self.driver_noise == "real" else DriverNoise()
        resolution = None if self.encoder_bits is None else 2.0 * math.pi / 2.0**self.encoder_bits
        given: dict[str, object] = {"encoder_resolution": resolution, "position_std": self.position_noise,
                                    "velocity_std": self.velocity_noise, "seed": self.noise_seed}
        return dataclasses.replace(noise, **{k: v for k, v in given.items() if v is not None})  # type: ignore[arg-type]

    def run(self) -> HungOptions:
        """The simulation's options (``delay`` in seconds)."""
        return HungOptions(duration=self.duration, substeps=self.substeps,
                           setpoints=SetpointOptions(kind=self.setpoints, seed=self.excitation_seed),
                           noise=self.drivers(), delay=None if self.delay is None else self.delay * 1e-3,
                           friction=self.mujoco_friction, friction_timeconst=self.friction_timeconst)


@dataclass(frozen=True)
class HungDesignOptions:
    """What ``excite`` reads of a hung PD-driven robot (:class:`~wbfriction.excite.options.PdExciteOptions`).

    Attributes:
        duration: the recording [s]; rate: the drivers' rate [Hz].
        amplitude: shares of each joint's half range the search tries.
        torque_share: share of each driver's torque limit the motion may ask.
        velocity: send ``qd_des`` = the set-points' slope (False: zeros).
        seed: the ramps' levels and times.
        after: the parameters JSON ``fit`` wrote of the log recorded: only the joints not ``ok`` move.
    """

    duration: float = option(PD_EXCITE.duration, quantity="duration")
    rate: float = option(PD_EXCITE.rate, quantity="rate")
    amplitude: tuple[float, ...] = option(PD_EXCITE.amplitudes)
    torque_share: float = option(PD_EXCITE.torque_share, quantity="share")
    velocity: bool = option(PD_EXCITE.velocity)
    seed: int = option(PD_EXCITE.seed, quantity="seed")
    after: Optional[Path] = option(None)

    def __post_init__(self) -> None:
        """Each ``amplitude`` a share (:data:`~wbfriction.quantities.RANGES`' ``share``; OptionError: naming
        ``--amplitude``)."""
        for share in self.amplitude:
            check_option("--amplitude", "share", share)


@dataclass(frozen=True)
class HungDemoOptions:
    """What ``demo`` reads of a hung robot: seconds of set-points simulated (ramps, then chirps) and their seed."""

    duration: float = option(HUNG.duration, quantity="duration")
    excitation_seed: int = option(0, quantity="seed")


class HungRig(Rig):
    """A PD-driven robot hung, its base fixed (``--actuator pd``, by default a robot with a ``[pd]`` table); its
    default friction Coulomb-viscous on every joint."""

    name, precedence, identifies_actuators = "hung", 20, True
    simulation, design_options, demo_options = HungSimulation, HungDesignOptions, HungDemoOptions

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' is a hung PD-driven robot (fixed base, {'--actuator pd' if actuator else '[pd]'})"

    def claims(self, robot: Robot, actuator: str | None) -> bool:
        # a robot on point feet walks, PD-driven or not (the quadruped's)
        return not robot.partial_contacts and (actuator == "pd" or (actuator is None and robot.pd is not None))

    def simulate(self, robot: Robot, options: Any, engine: Engine | None, engine_options: Any,
                 progress: RigProgress) -> SimulationOutput:
        from wbfriction.fit.targets import load_friction_spec
        from wbfriction.logs.setpoint_table import read_setpoint_table
        from wbfriction.sim.hung import simulate_hung

        o: HungSimulation = options
        run = o.run()
        spec = None if o.friction is None else load_friction_spec(o.friction, robot.groups, robot.actuated)
        if spec is not None and (spec.terms or spec.temperature is not None):
            raise InputError(f"{o.friction}: a PD-driven robot's simulation takes friction models per joint, without "
                             "terms beyond velocity or a temperature")
        reference = None
        if o.play is not None:
            import numpy as np

            table = read_setpoint_table(o.play, robot)
            velocity = bool(np.any(table.qd_des != 0.0))
            run = dataclasses.replace(run, duration=table.duration, rate=table.rate,
                                      setpoints=dataclasses.replace(run.setpoints, velocity=velocity))
            reference = (table.q_des - robot.offset_vector, table.qd_des)
        advance = progress.count("simulate", int(round(run.duration * run.rate)), "samples")
        result = simulate_hung(robot, run, None if spec is None else spec.params, progress=advance,
                               reference=reference)
        return SimulationOutput(table=result.table, summary=f"{result.table.num_rows} samples, {run.duration:g} s, "
                                                            f"PD set-points; delay {result.driver.delay * 1e3:g} ms, "
                                                            f"physics step {result.physics_step * 1e3:g} ms")

    def design(self, robot: Robot, options: Any, progress: RigProgress) -> DesignOutput:
        from wbfriction.excite.document import next_document, pd_document, pd_setpoints
        from wbfriction.excite.next import fits_after, record_next
        from wbfriction.excite.options import PdExciteOptions
        from wbfriction.excite.pd_design import design_pd
        from wbfriction.report.excite import excite_figure
        from wbfriction.report.excite_tables import design_shares, next_printed, pd_design_printed

        o: HungDesignOptions = options
        excite = PdExciteOptions(duration=o.duration, rate=o.rate, amplitudes=tuple(o.amplitude),
                                 torque_share=o.torque_share, velocity=o.velocity, seed=o.seed)
        fits = fits_after(robot, o.after)
        following = None
        advance = progress.count("design", len(excite.amplitudes) + len(excite.reversals) - 1, "candidates")
        if fits is None:
            design = design_pd(robot, excite, progress=advance)
        else:
            following = record_next(robot, fits, str(o.after), excite, progress=advance)
            design = following.design
        doc = pd_document(design)
        if following is not None:
            doc["after"] = next_document(following, str(o.after))

        def figure(path: Path) -> None:
            lower, upper = robot.angle_limits
            excite_figure(path, design.joints, design.time, design.q_des, lower + robot.offset_vector,
                          upper + robot.offset_vector, design_shares(doc),
                          f"{design.robot}: ramps over {design.chosen.amplitude:g} of each half range, reversing "
                          f"every {design.chosen.reversal[0]:g}-{design.chosen.reversal[1]:g} s; predicted worst "
                          f"{design.worst()[2]:.2f} of its limit")

        printed = pd_design_printed(design, doc)
        if dropped := design.dropped():
            printed.append(Printed(f"{len(dropped)} of {len(design.candidates)} candidates dropped unscored (the "
                                   f"first: amplitude {dropped[0].amplitude:g}, reversals {dropped[0].reversal[0]:g}-"
                                   f"{dropped[0].reversal[1]:g} s: {dropped[0].dropped})"))
        if following is not None and o.after is not None:
            printed += next_printed(following, o.after)
        return DesignOutput(pd_setpoints(design), doc, figure, tuple(printed))

    def demo(self, robot: Robot, options: Any, engine: Engine | None, output_dir: Path,
             progress: RigProgress) -> DemoOutput:
        """The robot hung and simulated (a real driver's noise, the default friction), its actuators identified
        (``identify --actuator pd``): each joint's armature, F_c, F_v and encoder offset, and the drivers' delay,
        against the truth."""
        from wbfriction.actuator.identification import identify_actuators
        from wbfriction.logs.metadata import read_metadata
        from wbfriction.logs.source import read_log
        from wbfriction.logs.tables import write_table
        from wbfriction.report.truth import found_text, not_ok_line, truth_table

        output_dir.mkdir(parents=True, exist_ok=True)
        log = output_dir / "hung.parquet"
        run = HungSimulation(duration=options.duration, excitation_seed=options.excitation_seed)
        table = self.simulate(robot, run, None, None, progress).table
        write_table(table, log)
        truth = read_metadata(table)
        progress.say("identifying the actuators")
        found = identify_actuators(robot, read_log(log, robot))
        rows = {j.joint: [(math.nan, math.inf, t, "not excited") if x is None else (x.value, x.se, t, x.status)
                          for x, t in (
            (j.armature, truth["armature_true"][j.joint]), (j.F_c, truth["friction_true"][j.joint]["F_c"]),
            (j.F_v, truth["friction_true"][j.joint]["F_v"]), (j.offset, truth["encoder_offset_true"][j.joint]))]
            for j in found.joints}
        d = found.delay
        title = f"{robot.name} hung, {options.duration:g} s: identified ± standard error, and the truth"
        columns = (("armature", "g·m²", 1e3), ("F_c", "N·m", 1.0), ("F_v", "N·m·s/rad", 1.0), ("offset", "mrad", 1e3))
        delay = f"delay {found_text(d.value, d.se, 1e3)} ms{'' if d.status == 'ok' else ' (' + d.status + ')'}"
        return DemoOutput((Printed(truth_table(title, columns, rows)), Printed(not_ok_line(columns, rows)),
                           Printed(f"{delay}, truth {truth['delay_true'] * 1e3:g} ms")), (log,))
