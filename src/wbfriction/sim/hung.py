"""A PD-driven robot hung with its base fixed, on MuJoCo: known armature, friction, encoder offsets, delay, gains,
torque limits and drivers' noise, its joints tracking ramps and chirps (the ground truth of a PD-driven robot's
identification, issue 55, item 5).

The robot (the built-in ``go2``: Unitree's Go2 welded to the world at its base, as a quadruped identified on a
stand; any fixed-base robot whose joints are all PD-driven) runs on :mod:`wbfriction.sim.pd_robot`: its drivers'
PD law at every physics step (1 ms by default: 5 per period of the 200 Hz log) on the encoder's reading and the
driver's velocity, the set-points commanded at the log's samples, held and applied ``delay`` later, the torque
clipped at the limits, friction of any family on every joint, the armature in the dynamics:

.. math::

    (M(q) + \\mathrm{diag}(I_a))\\,\\ddot q + h(q, \\dot q) = \\tau + \\tau_f, \\qquad \\tau_f = -f(\\dot q), \\qquad
    q_{logged} = q + b

**Set-points** (:func:`setpoints`, :class:`~wbfriction.sim.pd_options.SetpointOptions`): each joint about a
standing leg's posture (the robot's reference angles), triangle ramps reversing every 0.2-1.5 s (the real Aliengo
log's, there all joints in phase between two postures; here each joint its own times and levels, so that no two
joints move alike), then chirps; commanded in the encoder's coordinates (the posture plus the offset ``b``), with
``qd_des`` zero (as the real log) or the set-point's slope.

**The log** (the project's log format, a fixed base: no ``contact.*``, no ``base.*``), at the samples (the physics
step starting at each): ``time``, ``q.<joint>`` (the encoder: ``q + b``, its noise and rounding), ``qd.<joint>`` (the
driver's velocity), ``q_des.<joint>``, ``qd_des.<joint>`` (as commanded at the sample), and the truth:
``tau_true.<joint>`` (the torque the driver applied over the step, clipped), ``tau_f_true.<joint>`` (the friction
applied over it), ``qd_true.<joint>``, ``qdd_true.<joint>`` (the step's acceleration). The metadata (``wbfriction``
key) names everything injected: friction, armature, encoder offsets, delay, gains, torque limits, physics step, noise.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.friction.models import CoulombViscousParams, ModelParams
from wbfriction.logs.tables import with_metadata
from wbfriction.model.pd import PdDriver
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.sim.pd_options import DriverNoise, HungOptions, PerJoint, SetpointOptions
from wbfriction.sim.pd_robot import (
    Commands,
    PdMujocoRobot,
    PdRun,
    PdTrajectory,
    StepNoise,
    build_pd_robot,
    joint_values,
)

GENERATOR = "wbfriction.sim.hung.simulate_hung"
BAND_MARGIN = 0.05
"""Share of each joint's range the set-points keep off either limit."""


def per_joint(value: PerJoint, robot: Robot, what: str) -> np.ndarray:
    """A level per joint (n_act,) in :attr:`Robot.actuated` order: one number for all, or a mapping of joint or group
    names (a joint named once, directly or through one of its groups) to numbers.

    Raises:
        InputError: a name that is neither a joint nor a group, a joint named twice or not at all.
    """
    if not isinstance(value, Mapping):
        return np.full(robot.n_act, float(value))
    out: dict[str, float] = {}
    for name, v in value.items():
        members = robot.groups.get(name, (name,) if name in robot.actuated else None)
        if members is None:
            raise InputError(f"{what}: '{name}' is neither a joint nor a joint group of robot '{robot.name}'")
        for joint in members:
            if joint in out:
                raise InputError(f"{what}: joint '{joint}' is given twice (by '{name}')")
            out[joint] = float(v)
    missing = [j for j in robot.actuated if j not in out]
    if missing:
        raise InputError(f"{what}: no value for joint '{missing[0]}' of robot '{robot.name}'")
    return np.array([out[j] for j in robot.actuated])


def default_hung_friction(robot: Robot) -> dict[str, ModelParams]:
    """Friction :func:`simulate_hung` injects when none is given: Coulomb-viscous on every joint, each its own (joint
    ``i``: F_c = 0.30 + 0.025 i [N·m], F_v = 0.20 + 0.01 i [N·m·s/rad]; 0.30-0.58 and 0.20-0.31 on a quadruped's
    twelve joints, the range of the peer's identification of the real Aliengo), no offset."""
    return {j: CoulombViscousParams(F_v=0.20 + 0.01 * i, F_c=0.30 + 0.025 * i) for i, j in enumerate(robot.actuated)}


def setpoint_band(robot: Robot, amplitude: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each joint's posture and band [rad] (n_act,): the reference angle (else the middle of the range) and
    ``posture +- amplitude * range / 2``, kept :data:`BAND_MARGIN` of the range off the limits (model angles)."""
    lo, hi = robot.angle_limits
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise InputError(f"robot '{robot.name}': the set-points need every joint's position limits in the URDF")
    margin = BAND_MARGIN * (hi - lo)
    middle = 0.5 * (lo + hi) if robot.q_reference is None else robot.reference_angles
    posture = np.clip(middle, lo + margin, hi - margin)
    half = 0.5 * amplitude * (hi - lo)
    return posture, np.maximum(posture - half, lo + margin), np.minimum(posture + half, hi - margin)


def _ramps(rng: np.random.Generator, end: float, posture: float, low: float, high: float,
           reversal: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Knot times [s] and levels [rad] of one joint's triangle ramps from the posture at 0 back to it at ``end``:
    each segment ``reversal`` long (random), to a random level in the far half of the band on its side."""
    times, levels = [0.0], [posture]
    up = bool(rng.integers(2))
    while True:
        duration = rng.uniform(*reversal)
        if times[-1] + duration > end - reversal[0]:
            times.append(end)
            levels.append(posture)
            return np.array(times), np.array(levels)
        far = high if up else low
        times.append(times[-1] + duration)
        levels.append(posture + (far - posture) * rng.uniform(0.5, 1.0))
        up = not up


def setpoints(robot: Robot, time: np.ndarray, options: SetpointOptions = SetpointOptions()
              ) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's set-point (model angles) [rad] and its slope [rad/s] at ``time`` (N,), each (N, n_act)
    (:class:`~wbfriction.sim.pd_options.SetpointOptions`; module docstring), each held over ``options.hold``
    samples."""
    rng = np.random.default_rng(options.seed)
    posture, low, high = setpoint_band(robot, options.amplitude)
    duration = float(time[-1]) + (float(time[1] - time[0]) if len(time) > 1 else 0.0)
    split = {"ramps": duration, "chirps": 0.0, "both": 0.5 * duration}[options.kind]
    q = np.tile(posture, (len(time), 1))
    qd = np.zeros_like(q)
    ramp, chirp = time < split, time >= split
    for j in range(robot.n_act):
        if split > 0:
            knots, levels = _ramps(rng, split, posture[j], low[j], high[j], options.reversal)
            q[ramp, j] = np.interp(time[ramp], knots, levels)
            segment = np.clip(np.searchsorted(knots, time[ramp], side="right") - 1, 0, len(knots) - 2)
            qd[ramp, j] = np.diff(levels)[segment] / np.diff(knots)[segment]
        if split < duration:
            scale, sign = rng.uniform(0.8, 1.2), rng.choice([-1.0, 1.0])
            f0, f1 = scale * options.chirp[0], scale * options.chirp[1]
            t = time[chirp] - split
            span = duration - split
            phase = 2.0 * np.pi * (f0 * t + 0.5 * (f1 - f0) * t**2 / span)
            a = sign * min(high[j] - posture[j], posture[j] - low[j])
            q[chirp, j] = posture[j] + a * np.sin(phase)
            qd[chirp, j] = a * np.cos(phase) * 2.0 * np.pi * (f0 + (f1 - f0) * t / span)
    held = np.arange(len(time)) // options.hold * options.hold
    return q[held], qd[held]


@dataclass
class HungSimulation:
    """What :func:`simulate_hung` produced.

    Attributes:
        table: the log (module docstring), metadata included.
        time: the sample times (N,) [s].
        trajectory: the run at the samples (:class:`~wbfriction.sim.pd_robot.PdTrajectory`: true angles, velocities,
            accelerations, the readings, the torque and friction applied).
        commands: the set-points commanded (encoder coordinates).
        driver: the drivers simulated (the delay injected).
        armature: per joint (n,) [kg·m^2]; encoder_offset: per joint (n,) [rad].
        friction: the friction injected per joint.
        physics_step: [s].
    """

    table: pa.Table
    time: np.ndarray
    trajectory: PdTrajectory
    commands: Commands
    driver: PdDriver
    armature: np.ndarray
    encoder_offset: np.ndarray
    friction: dict[str, ModelParams]
    physics_step: float


def step_noise(robot: Robot, noise: DriverNoise, n_steps: int) -> StepNoise:
    """The drivers' errors at ``n_steps`` physics steps (drawn from ``noise.seed``: position, then velocity; None
    where off)."""
    rng = np.random.default_rng(noise.seed)
    std_q = per_joint(noise.position_std, robot, "position_std")
    std_v = per_joint(noise.velocity_std, robot, "velocity_std")
    position = rng.normal(0.0, 1.0, (n_steps, robot.n_act)) * std_q if std_q.any() else None
    velocity = rng.normal(0.0, 1.0, (n_steps, robot.n_act)) * std_v if std_v.any() else None
    resolution = (None if noise.encoder_resolution is None
                  else per_joint(noise.encoder_resolution, robot, "encoder_resolution"))
    return StepNoise(position, velocity, resolution)


def simulate_hung(robot: Robot, options: HungOptions = HungOptions(),
                  friction: Mapping[str, ModelParams] | None = None, progress: Progress | None = None,
                  mjr: PdMujocoRobot | None = None,
                  reference: tuple[np.ndarray, np.ndarray] | None = None) -> HungSimulation:
    """Simulate ``robot`` hung with its base fixed, its PD drivers tracking ramps and chirps (module docstring).

    Args:
        robot: a fixed-base robot whose joints are all PD-driven (``[pd]``), e.g. the built-in ``go2``.
        options: :class:`~wbfriction.sim.pd_options.HungOptions` (the delay, armature and encoder offsets: the
            robot's own unless given).
        friction: parameters of any family per joint (joints not named: none); None: :func:`default_hung_friction`.
        progress: optional callable receiving numbers of samples done.
        mjr: the robot's MuJoCo model, if already built (:func:`~wbfriction.sim.pd_robot.build_pd_robot`).
        reference: the set-points to send instead of :attr:`HungOptions.setpoints`' ramps and chirps: the model's
            angles (N, n_act) [rad] at the samples and their slope (N, n_act) [rad/s] (a designed excitation,
            :mod:`wbfriction.excite`), ``N = round(duration x rate)``.

    Returns:
        :class:`HungSimulation` with ``round(duration * rate)`` samples.

    Raises:
        InputError: a robot that is not a hung PD-driven one, values for unknown joints, a negative armature,
            MuJoCo's friction with Stribeck or offset parameters, a noise level naming no joint or group.
        SimulationError: the simulation diverged.
    """
    mjr = mjr or build_pd_robot(robot)
    friction = dict(default_hung_friction(robot) if friction is None else friction)
    n = int(round(options.duration * options.rate))
    if n < 2:
        raise InputError(f"a hung simulation needs at least two samples: duration x rate = {n}")
    period = 1.0 / options.rate
    time = np.arange(n) * period
    driver = mjr.driver if options.delay is None else mjr.driver.with_delay(options.delay)
    armature = joint_values(robot, options.armature, dict(zip(robot.actuated, robot.model.armature[robot.act_v_index])),
                       "armature")
    offset = joint_values(robot, options.encoder_offset, robot.encoder_offset, "encoder offset")
    if reference is None:
        q_model, slope = setpoints(robot, time, options.setpoints)
    else:
        q_model, slope = (np.asarray(x, dtype=float) for x in reference)
        if q_model.shape != (n, robot.n_act) or slope.shape != q_model.shape:
            raise InputError(f"a hung simulation's reference must be ({n}, {robot.n_act}) set-points and slopes "
                             f"(duration x rate, the robot's joints), got {q_model.shape} and {slope.shape}")
    commands = Commands(q_model + offset, slope if options.setpoints.velocity else np.zeros_like(slope),
                        np.zeros_like(slope))
    run = PdRun(mjr, period, options.substeps, driver, armature, offset, friction, options.friction,
                options.friction_timeconst)
    noise = step_noise(robot, options.noise, n * options.substeps)
    trajectory = run.run(commands, 0, n, q_model[0], np.zeros(robot.n_act), noise, progress)
    result = HungSimulation(pa.table({}), time, trajectory, commands, driver, armature, offset, friction, run.h)
    result.table = _table(robot, result, options, noise)
    return result


def _table(robot: Robot, sim: HungSimulation, options: HungOptions, noise: StepNoise) -> pa.Table:
    """The log of a run (module docstring), its metadata naming what was injected."""
    tr, joints = sim.trajectory, robot.actuated
    cols: dict[str, np.ndarray] = {"time": sim.time}
    for prefix, x in (("q", tr.q_encoder), ("qd", tr.qd_driver), ("q_des", sim.commands.q_des),
                      ("qd_des", sim.commands.qd_des), ("tau_true", tr.tau), ("tau_f_true", tr.tau_f),
                      ("qd_true", tr.qd), ("qdd_true", tr.qdd)):
        cols.update({f"{prefix}.{j}": x[:, i] for i, j in enumerate(joints)})
    by_joint = lambda x: {j: float(v) for j, v in zip(joints, x)}  # noqa: E731
    d = sim.driver
    meta = {"generator": GENERATOR, "options": asdict(options), "robot": robot.name, "urdf": Path(robot.urdf).name,
            "actuator": "pd", "friction_mode": options.friction,
            "dynamics": "(M(q) + diag(armature)) qdd + h(q, qd) = tau + tau_f; tau_f = -f(qd); q_logged = q + "
                        "encoder_offset; tau = clip(kp (q_des(t - delay) - q_logged) + kd (qd_des(t - delay) - "
                        "qd_logged), -torque_limit, torque_limit), the set-points held from their sample",
            "friction_true": {j: p.to_target() for j, p in sim.friction.items()},
            "armature_true": by_joint(sim.armature), "encoder_offset_true": by_joint(sim.encoder_offset),
            "delay_true": d.delay,
            "pd_true": {"kp": by_joint(d.kp), "kd": by_joint(d.kd), "delay": d.delay,
                        "torque_limit": {j: (float(v) if np.isfinite(v) else None)
                                         for j, v in zip(joints, d.torque_limit)}},
            "physics_step": sim.physics_step,
            "driver_noise": {"encoder_resolution": None if noise.resolution is None else by_joint(noise.resolution),
                             "position_std": by_joint(per_joint(options.noise.position_std, robot, "position_std")),
                             "velocity_std": by_joint(per_joint(options.noise.velocity_std, robot, "velocity_std")),
                             "seed": options.noise.seed, "drawn": "at every physics step"}}
    return with_metadata(pa.table(cols), meta)
