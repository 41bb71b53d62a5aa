"""A fixed-base arm, torque-driven: ``simulate`` tracks an excitation trajectory and logs its motor currents
(:func:`~wbfriction.sim.arm.simulate_arm`); ``excite`` designs a Fourier excitation whose ``estimate`` and ``fit``
determine each joint's friction (:func:`~wbfriction.excite.arm_design.design_arm`)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional

from wbfriction.excite.options import ARM_PERIOD, ARM_RATE, PD_EXCITE
from wbfriction.options import option
from wbfriction.report.printed import Printed
from wbfriction.rigs.base import DemoOutput, DesignOutput, Rig, RigProgress, SimulationOutput
from wbfriction.sim.noise_options import SensorNoiseOptions

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot
    from wbfriction.sim.engines import Engine


@dataclass(frozen=True)
class ArmSimulation(SensorNoiseOptions):
    """What ``simulate`` reads of an arm, beyond the sensor noise (encoder bits 19 where not given).

    Attributes:
        friction: TOML of the injected friction (``[friction.<group or joint>]``); None:
            :func:`~wbfriction.sim.arm.default_arm_friction`.
        play: a set-points table ``excite`` wrote for the arm, played instead of a random excitation.
        duration: seconds of excitation trajectory.
        excitation_seed: seed of its Fourier coefficients.
    """

    friction: Optional[Path] = option(None)
    play: Optional[Path] = option(None)
    duration: float = option(10.0, quantity="duration", motion=True)
    excitation_seed: int = option(0, quantity="seed", motion=True)


@dataclass(frozen=True)
class ArmDesignOptions:
    """What ``excite`` reads of an arm.

    Attributes:
        duration: the recording [s]; rate: its samples per second [Hz].
        period: the Fourier series' period [s] (a whole number of them per recording).
        torque_share: share of each joint's torque limit the motion may ask.
        seed: seed of the design's starts.
        after: the parameters JSON ``fit`` wrote of the log recorded: only the joints not ``ok`` move.
    """

    duration: float = option(PD_EXCITE.duration, quantity="duration")
    rate: float = option(ARM_RATE, quantity="rate")
    period: float = option(ARM_PERIOD, quantity="period")
    torque_share: float = option(PD_EXCITE.torque_share, quantity="share")
    seed: int = option(PD_EXCITE.seed, quantity="seed")
    after: Optional[Path] = option(None)


@dataclass(frozen=True)
class ArmDemoOptions:
    """What ``demo`` reads of an arm: seconds of excitation trajectory simulated, and its seed."""

    duration: float = option(10.0, quantity="duration")
    excitation_seed: int = option(0, quantity="seed")


class ArmRig(Rig):
    """A fixed-base robot (torque-driven): an arm; its default friction :func:`~wbfriction.sim.arm.
    default_arm_friction`."""

    name, precedence = "arm", 30
    simulation, design_options, demo_options = ArmSimulation, ArmDesignOptions, ArmDemoOptions

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' is a fixed-base arm (torque-driven, an excitation trajectory)"

    def claims(self, robot: Robot, actuator: str | None) -> bool:
        return not robot.floating_base

    def simulate(self, robot: Robot, options: Any, engine: Engine | None, engine_options: Any,
                 progress: RigProgress) -> SimulationOutput:
        from wbfriction.fit.targets import load_friction_spec
        from wbfriction.rigs.played import played_arm
        from wbfriction.sim.arm import ArmOptions, ExcitationOptions, default_arm_friction, simulate_arm

        o: ArmSimulation = options
        run = ArmOptions(duration=o.duration, encoder_bits=19 if o.encoder_bits is None else o.encoder_bits,
                         position_std=0.0 if o.position_noise is None else o.position_noise,
                         torque_std=0.0 if o.torque_noise is None else o.torque_noise,
                         seed=0 if o.noise_seed is None else o.noise_seed,
                         excitation=ExcitationOptions(seed=o.excitation_seed))
        spec = None if o.friction is None else load_friction_spec(o.friction, robot.groups, robot.torque_controlled)
        params = default_arm_friction(robot) if spec is None else spec.params
        if spec is not None and spec.temperature is not None:
            run = dataclasses.replace(run, temperature=spec.temperature)
        trajectory = None
        if o.play is not None:
            table, trajectory = played_arm(robot, o.play)
            run = dataclasses.replace(run, duration=table.duration, rate=table.rate)
        advance = progress.count("simulate", int(run.duration * run.rate), "samples")
        result = simulate_arm(robot, params, options=run, progress=advance,
                              terms=None if spec is None else spec.terms, trajectory=trajectory)
        return SimulationOutput(table=result.table, summary=f"{result.table.num_rows} samples, "
                                                            f"{run.duration:g} s, motor currents")

    def design(self, robot: Robot, options: Any, progress: RigProgress) -> DesignOutput:
        from wbfriction.excite.arm_design import design_arm
        from wbfriction.excite.design import ExciteOptions
        from wbfriction.excite.document import arm_document, arm_setpoints, next_document
        from wbfriction.excite.next import fits_after, record_next_arm, undetermined
        from wbfriction.fit.status import WEAK
        from wbfriction.report.excite import excite_figure
        from wbfriction.report.excite_tables import arm_design_printed, design_shares, next_printed

        o: ArmDesignOptions = options
        excite = ExciteOptions(duration=o.duration, rate=o.rate, period=o.period, torque_share=o.torque_share,
                               seed=o.seed)
        fits = fits_after(robot, o.after)
        following = None
        total = robot.n_act if fits is None else len(undetermined(robot, fits, str(o.after)))
        advance = progress.count("design", total, "joints")
        if fits is None:
            design = design_arm(robot, excite, progress=advance)
        else:
            following = record_next_arm(robot, fits, str(o.after), excite, progress=advance)
            design = following.design
        progress.say("predicting what estimate and fit will report (two simulated recordings)")
        doc = arm_document(design)
        if following is not None:
            doc["after"] = next_document(following, str(o.after))

        def figure(path: Path) -> None:
            lower, upper = robot.angle_limits
            excite_figure(path, design.design.joints, design.time, design.q_des + robot.offset_vector,
                          lower + robot.offset_vector, upper + robot.offset_vector, design_shares(doc),
                          f"{robot.name}: Fourier excitation; predicted worst {doc['worst']['share']:.2f} of the "
                          "weak limit")

        printed = arm_design_printed(doc, design.design.margins.least(), WEAK)
        if following is not None and o.after is not None:
            printed += next_printed(following, o.after)
        return DesignOutput(arm_setpoints(design, robot.offset_vector), doc, figure, tuple(printed))


    def demo(self, robot: Robot, options: Any, engine: Engine | None, output_dir: Path,
             progress: RigProgress) -> DemoOutput:
        """The arm simulated with its default friction (a random excitation, motor currents logged), estimated and
        fitted (the model chosen per joint): each joint's F_c and F_v against the friction injected."""
        from wbfriction.fit.joints import fit_estimate
        from wbfriction.friction.estimate import estimate_log
        from wbfriction.logs.source import read_log
        from wbfriction.logs.tables import write_table
        from wbfriction.report.truth import not_ok_line, truth_table

        output_dir.mkdir(parents=True, exist_ok=True)
        log = output_dir / "arm.parquet"
        run = ArmSimulation(duration=options.duration, excitation_seed=options.excitation_seed)
        write_table(self.simulate(robot, run, None, None, progress).table, log)
        progress.say("estimating and fitting (the model chosen per joint)")
        fits = fit_estimate(estimate_log(robot, read_log(log, robot)))
        rows = {}
        for f in fits:
            if f.params is None or f.target is None:
                continue
            truth, se = f.target.values_in(f.model), f.read_stderr()
            rows[f.joint] = [(getattr(f.params, n), se.get(n, math.inf), truth[n], f.verdict().status)
                             for n in ("F_c", "F_v")]
        title = f"{robot.name}, {options.duration:g} s of excitation: fitted friction ± standard error, and the truth"
        columns = (("F_c", "N·m", 1.0), ("F_v", "N·m·s/rad", 1.0))
        return DemoOutput((Printed(truth_table(title, columns, rows)), Printed(not_ok_line(columns, rows))), (log,))
