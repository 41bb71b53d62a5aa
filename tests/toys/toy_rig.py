"""A toy rig, one file: a fixed-base arm (torque-driven, no ``[pd]``) that tracks a sine on each joint, of its own
option ``sine_share`` of each joint's half range (``--rig-option sine_share=0.3``), which no built-in rig reads.

* ``simulate``: the sines integrated with Pinocchio's forward dynamics (``pin.aba``) under a known Coulomb-viscous
  friction, its joint torque sensors logged (``tau.<joint>``) with the true friction (``tau_f_true.<joint>``);
* ``excite``: the sines as set-points (``time``, ``q_des.<joint>``, ``qd_des.<joint>``) and their peak speeds;
* ``identify``: the inertia model's route (the rig does not identify PD drivers);
* ``demo``: simulate, estimate, fit, and each joint's F_c and F_v against the friction injected.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pyarrow as pa

from wbfriction.friction.models import CoulombViscousParams
from wbfriction.logs.metadata import with_metadata
from wbfriction.model.robot import Robot
from wbfriction.options import option
from wbfriction.progress import counted
from wbfriction.report.printed import Printed
from wbfriction.rigs import DemoOutput, DesignOutput, Rig, RigProgress, SimulationOutput
from wbfriction.sim.arm import arm_model

NAME = "toy-arm"
RATE, SUBSTEPS = 1000.0, 10
"""The log's rate [Hz] and the physics steps per period (the torque held over them: ``zoh``)."""


def toy_friction(robot: Robot) -> dict[str, CoulombViscousParams]:
    """The friction injected: joint i (from 0) F_c = 0.8 - 0.05 i [N·m], F_v = 0.4 - 0.03 i [N·m·s/rad]."""
    return {j: CoulombViscousParams(F_v=0.4 - 0.03 * i, F_c=0.8 - 0.05 * i) for i, j in enumerate(robot.actuated)}


@dataclass(frozen=True)
class ToySimulation:
    """``simulate``: ``duration`` [s] of sines at 0.25 + 0.05 i Hz, their phases drawn from ``excitation_seed``, of
    ``sine_share`` of each joint's half range about its middle."""

    duration: float = option(10.0, quantity="duration", motion=True)
    excitation_seed: int = option(0, quantity="seed", motion=True)
    sine_share: float = option(0.35, motion=True)


@dataclass(frozen=True)
class ToyDesign:
    """``excite``: the sines' set-points over ``duration`` [s] at ``rate`` [Hz]."""

    duration: float = option(10.0, quantity="duration")
    rate: float = option(RATE)
    seed: int = option(0, quantity="seed")
    sine_share: float = option(0.35)


@dataclass(frozen=True)
class ToyDemo:
    """``demo``: ``duration`` [s] simulated, estimated and fitted."""

    duration: float = option(6.0, quantity="duration")
    sine_share: float = option(0.35)


def sines(robot: Robot, share: float, seed: int, time: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each joint's sine: q, qd, qdd (N, n) at ``time`` [s]."""
    model = arm_model(robot)
    mid = 0.5 * (model.lowerPositionLimit + model.upperPositionLimit)
    amp = share * 0.5 * (model.upperPositionLimit - model.lowerPositionLimit)
    w = 2 * np.pi * (0.25 + 0.05 * np.arange(model.nv))
    phase = np.random.default_rng(seed).uniform(0, 2 * np.pi, model.nv)
    s = np.outer(time, w) + phase
    return mid + amp * np.sin(s), amp * w * np.cos(s), -amp * w**2 * np.sin(s)


def simulate_toy(robot: Robot, o: ToySimulation, progress: RigProgress) -> pa.Table:
    """The sines tracked under :func:`toy_friction`, as a log table."""
    model = arm_model(robot)
    model.armature = np.array(robot.model.armature[robot.act_v_index], dtype=float)
    data = model.createData()
    truth = toy_friction(robot)
    F_v, F_c = (np.array([getattr(truth[j], k) for j in robot.actuated]) for k in ("F_v", "F_c"))
    n, dt = int(round(o.duration * RATE)), 1.0 / RATE
    time = np.arange(n) * dt
    q_ref, qd_ref, qdd_ref = sines(robot, o.sine_share, o.excitation_seed, time)
    inertia = np.diag(pin.crba(model, data, q_ref[0]))
    kp, kd = inertia * (2 * np.pi * 8.0) ** 2, 2 * inertia * 2 * np.pi * 8.0
    Q, V, T, F = (np.empty((n, model.nv)) for _ in range(4))
    q, v = q_ref[0].copy(), qd_ref[0].copy()
    for k in counted(n, progress.count("simulate", n, "samples")):
        tau = pin.rnea(model, data, q_ref[k], qd_ref[k], qdd_ref[k]) + kp * (q_ref[k] - q) + kd * (qd_ref[k] - v)
        Q[k], V[k], T[k], F[k] = q, v, tau, -(F_v * v + F_c * np.sign(v))
        for _ in range(SUBSTEPS):
            v = v + dt / SUBSTEPS * pin.aba(model, data, q, v, tau - (F_v * v + F_c * np.sign(v)))
            q = q + dt / SUBSTEPS * v
    cols = {"time": time}
    for prefix, x in (("q", Q), ("tau", T), ("tau_f_true", F), ("qd_true", V)):
        cols.update({f"{prefix}.{j}": x[:, i] for i, j in enumerate(robot.actuated)})
    meta = {"generator": f"toy rig {NAME}", "robot": robot.name, "torque_alignment": "zoh",
            "friction_true": {j: p.to_target() for j, p in truth.items()}}
    return with_metadata(pa.table(cols), meta)


class ToyArm(Rig):
    """A fixed-base, torque-driven robot tracking sines (before the built-in arm, which claims every fixed base)."""

    name, precedence = NAME, 25
    simulation, design_options, demo_options = ToySimulation, ToyDesign, ToyDemo

    def what(self, robot: Robot, actuator: str | None = None) -> str:
        return f"robot '{robot.name}' is on the toy arm rig"

    def claims(self, robot: Robot, actuator: str | None) -> bool:
        return not robot.floating_base and robot.pd is None and actuator != "pd"

    def simulate(self, robot: Robot, options: Any, engine: Any, engine_options: Any,
                 progress: RigProgress) -> SimulationOutput:
        table = simulate_toy(robot, options, progress)
        return SimulationOutput(table=table, summary=f"{table.num_rows} samples, {options.duration:g} s, {NAME}")

    def design(self, robot: Robot, options: Any, progress: RigProgress) -> DesignOutput:
        time = np.arange(int(round(options.duration * options.rate))) / options.rate
        q, qd, _ = sines(robot, options.sine_share, options.seed, time)
        cols = {"time": time, **{f"q_des.{j}": q[:, i] for i, j in enumerate(robot.actuated)},
                **{f"qd_des.{j}": qd[:, i] for i, j in enumerate(robot.actuated)}}
        peak = {j: float(np.abs(qd[:, i]).max()) for i, j in enumerate(robot.actuated)}
        table = with_metadata(pa.table(cols), {"generator": f"toy rig {NAME}", "robot": robot.name})
        return DesignOutput(table, {"sine_share": options.sine_share, "peak_velocity": peak}, None,
                            (Printed(f"sines of {options.sine_share:g} of each half range; fastest joint "
                                     f"{max(peak, key=peak.get)} at {max(peak.values()):.2f} rad/s"),))

    def demo(self, robot: Robot, options: Any, engine: Any, output_dir: Path, progress: RigProgress) -> DemoOutput:
        from wbfriction.fit.joints import fit_estimate
        from wbfriction.fit.options import FitOptions
        from wbfriction.friction.estimate import estimate_log
        from wbfriction.logs.source import read_log
        from wbfriction.logs.tables import write_table

        output_dir.mkdir(parents=True, exist_ok=True)
        log = output_dir / "toy.parquet"
        write_table(simulate_toy(robot, ToySimulation(options.duration, 0, options.sine_share), progress), log)
        progress.say("estimating and fitting")
        fits = fit_estimate(estimate_log(robot, read_log(log, robot)), FitOptions(model="coulomb-viscous"))
        truth = toy_friction(robot)
        lines = [f"{f.joint}: F_c {f.params.F_c:.3f} (true {truth[f.joint].F_c:.3f}), F_v {f.params.F_v:.3f} "
                 f"(true {truth[f.joint].F_v:.3f}), {f.verdict().status}" for f in fits if f.params is not None]
        return DemoOutput(tuple(Printed(line) for line in lines), (log,))
