"""A toy simulator, one file: a fixed-base arm (``--simulator toy-arm``) tracking a sine on each joint, integrated
with Pinocchio's forward dynamics (``pin.aba``) under a known Coulomb-viscous friction, its joint torque sensors
logged (``tau.<joint>``) with the true friction (``tau_f_true.<joint>``)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pyarrow as pa

from wbfriction.friction.models import CoulombViscousParams
from wbfriction.logs.metadata import with_metadata
from wbfriction.model.robot import Robot
from wbfriction.progress import counted
from wbfriction.sim.arm import arm_model
from wbfriction.sim.simulators import SimulationOutput, SimulationProgress, SimulatorKind

NAME = "toy-arm"
RATE, SUBSTEPS = 1000.0, 10
"""The log's rate [Hz] and the physics steps per period (the torque held over them: ``zoh``)."""


def toy_friction(robot: Robot) -> dict[str, CoulombViscousParams]:
    """The friction injected: joint i (from 0) F_c = 0.8 - 0.05 i [N·m], F_v = 0.4 - 0.03 i [N·m·s/rad]."""
    return {j: CoulombViscousParams(F_v=0.4 - 0.03 * i, F_c=0.8 - 0.05 * i) for i, j in enumerate(robot.actuated)}


class ToyArm(SimulatorKind):
    """``--simulator toy-arm`` on a fixed-base, torque-driven robot: a sine of 0.35 of each joint's half range about
    its middle, at 0.25 + 0.05 i Hz, its phases drawn from ``--excitation-seed``, for ``--duration`` seconds."""

    name, precedence = NAME, 25  # before the built-in arm (30), which claims every fixed base
    options = ("simulator", "duration", "excitation_seed")

    def what(self, robot, actuator=None):
        return f"robot '{robot.name}' runs in the toy arm simulator (--simulator {NAME})"

    def claims(self, robot, actuator, simulator):
        return simulator == NAME and not robot.floating_base and actuator != "pd"

    def run(self, robot: Robot, values: Mapping[str, Any], friction: Path | None,
            progress: SimulationProgress) -> SimulationOutput:
        model = arm_model(robot)
        model.armature = np.array(robot.model.armature[robot.act_v_index], dtype=float)
        data = model.createData()
        truth = toy_friction(robot)
        F_v, F_c = (np.array([getattr(truth[j], k) for j in robot.actuated]) for k in ("F_v", "F_c"))
        mid = 0.5 * (model.lowerPositionLimit + model.upperPositionLimit)
        amp = 0.35 * 0.5 * (model.upperPositionLimit - model.lowerPositionLimit)
        w = 2 * np.pi * (0.25 + 0.05 * np.arange(model.nv))
        phase = np.random.default_rng(values.get("excitation_seed", 0)).uniform(0, 2 * np.pi, model.nv)
        n, dt = int(round((values.get("duration") or 10.0) * RATE)), 1.0 / RATE
        time = np.arange(n) * dt
        inertia = np.diag(pin.crba(model, data, mid))
        kp, kd = inertia * (2 * np.pi * 8.0) ** 2, 2 * inertia * 2 * np.pi * 8.0
        Q, V, T, F = (np.empty((n, model.nv)) for _ in range(4))
        q, v = mid + amp * np.sin(phase), amp * w * np.cos(phase)
        with progress.steps(n) as advance:
            for k in counted(n, advance):
                s = w * time[k] + phase
                q_ref, qd_ref, qdd_ref = mid + amp * np.sin(s), amp * w * np.cos(s), -amp * w**2 * np.sin(s)
                tau = pin.rnea(model, data, q_ref, qd_ref, qdd_ref) + kp * (q_ref - q) + kd * (qd_ref - v)
                Q[k], V[k], T[k], F[k] = q, v, tau, -(F_v * v + F_c * np.sign(v))
                for _ in range(SUBSTEPS):
                    v = v + dt / SUBSTEPS * pin.aba(model, data, q, v, tau - (F_v * v + F_c * np.sign(v)))
                    q = q + dt / SUBSTEPS * v
        cols = {"time": time}
        for prefix, x in (("q", Q), ("tau", T), ("tau_f_true", F), ("qd_true", V)):
            cols.update({f"{prefix}.{j}": x[:, i] for i, j in enumerate(robot.actuated)})
        meta = {"generator": f"toy simulator {NAME}", "robot": robot.name, "torque_alignment": "zoh",
                "friction_true": {j: p.to_target() for j, p in truth.items()}}
        table = with_metadata(pa.table(cols), meta)
        return SimulationOutput(table=table, summary=f"{n} samples, {n * dt:g} s, {NAME}")
