"""The motor drivers of PD-driven joints (:mod:`wbfriction.model.pd`) as simulators hold them: gains, torque limits,
the set-points' delay, the encoder offset.

A PD-driven joint (Unitree class: no torque sensor, the driver closes a PD loop on the encoder) applies

.. math::

    \\tau(t) = \\mathrm{clip}\\big(k_p\\,(q^{des}(t - d) - q_{enc}) + k_d\\,(\\dot q^{des}(t - d) - \\dot q)
               + \\tau_{ff}(t - d),\\; -\\tau_{max},\\; \\tau_{max}\\big), \\qquad q_{enc} = q + \\text{offset},

``q`` the model's angle, ``q_enc`` the encoder's reading (the logged angle), each set-point held from the instant
it is commanded and applied ``d`` later.

A friction fit of a PD-driven joint has a constant ``tau_os`` (:mod:`wbfriction.friction.models`: the joint gets
``-tau_os`` beside its friction). Such a joint has no torque sensor whose offset it could be: it is a torque the
drive applies and the rigid-body model lacks (``kp`` times an encoder offset the identification left out, a gravity
torque the model misses), and the robot gets it whatever it does. It is exported with the drive, as the set-point
offset that applies it, ``kp (q_des - q_enc - tau_os / kp) = kp (q_des - q_enc) - tau_os`` (issue 64; on the real
Aliengo's held-out stretch it takes the exported MJCF's tracking error from 9.5 to 4.8 mrad,
``docs/measurements/pd-robots.md``). Where each simulator holds it:

======================  ==========================================  ==============================================
driver                  Isaac Lab ``DelayedPDActuatorCfg`` (3.0)    MuJoCo 4 actuator (``<position>`` as ``<general>``)
======================  ==========================================  ==============================================
k_p [N·m/rad]           ``stiffness``                               ``gainprm[0] = kp``, ``biasprm[1] = -kp``
k_d [N·m·s/rad]         ``damping``                                 ``biasprm[2] = -kd`` (``kv``)
tau_max [N·m]           ``actuator_effort_limit``                   ``forcerange = [-tau_max, tau_max]``
d [s]                   ``min_delay = max_delay`` [physics steps]   ``delay = d - 1 ns``, ``interp`` zero-order hold
offset [rad]            no field (a comment: how to apply it)       ``biasprm[0] = -kp * offset``
tau_os [N·m]            no field (a set-point offset ``tau_os/kp``)  ``biasprm[0] -= tau_os``
qd_des, tau_ff          the action's velocity and effort targets    no input (a ``<motor>`` beside it)
======================  ==========================================  ==============================================

Isaac Lab counts the delay in physics steps (``DelayBuffer``, pushed once per physics step, ``sim.dt``; the policy's
decimation does not enter): :func:`delay_steps` rounds ``d / physics_dt`` to the nearest whole step (halves up) and
says so when ``d`` is not a whole number of steps. MuJoCo 4 delays an actuator's control by ``delay`` seconds
(written :data:`HOLD_EDGE`, 1 ns, less: the hold's edge), from a history buffer of ``nsample`` samples
(:func:`history_samples`: enough at the model's timestep and any down to :data:`SMALLEST_TIMESTEP`).

Sources: Isaac Lab 3.0.0 ``isaaclab/actuators/actuator_base_cfg.py`` and ``actuator_pd_cfg.py`` (fields, units),
``actuator_pd.py`` (``DelayedPDActuator``: the position, velocity and effort targets delayed, the PD law on the
simulated state); PACE (leggedrobotics/pace-sim2real, ``pace_actuator.py``: ``encoder_bias`` subtracted from the
simulated angle, so ``encoder_bias = -offset``); MuJoCo 4.0.0's ``MjsActuator`` (``delay``, ``nsample``, ``interp``)
checked on the installed version (``tests/export/test_pd_exports.py``).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.export.mapping import JointExport
from wbfriction.model.robot import Robot

DEFAULT_PHYSICS_DT = 0.005
"""Isaac Lab's physics step of its locomotion tasks [s] (``LocomotionVelocityRoughEnvCfg``: ``sim.dt = 1/200``,
``decimation = 4``; PACE's and the iit-DLSLab identifications also run 200 Hz physics): what ``export
--physics-dt`` counts the delay in by default. Isaac Lab's bare ``SimulationCfg`` default is 1/60 s."""

WHOLE_STEP = 1e-6
"""How close [steps] ``delay / physics_dt`` must come to a whole number to be one (floating-point division:
``0.015 / 0.005 = 2.9999999999999996``)."""


def held_back_warning(robot: Robot) -> str | None:
    """One line when the robot's drivers hold back their whole torque (``[pd] delayed = "torque"``,
    :mod:`wbfriction.model.pd`), which neither target holds: Isaac Lab's ``DelayedPDActuator`` and MuJoCo's actuator
    delay hold back the set-points (PACE's ``PaceDCMotorCfg`` holds the torque); else None."""
    if robot.pd is None or robot.pd.delayed != "torque":
        return None
    return (f"{robot.name}: its drivers hold back their whole torque ([pd] delayed = \"torque\"); this target "
            "delays the set-points only: the delay is written as a set-point delay (PACE's PaceDCMotorCfg "
            "delays the torque)")


@dataclass(frozen=True)
class DelaySteps:
    """A delay counted in physics steps, as Isaac Lab's ``min_delay``/``max_delay`` hold it.

    Attributes:
        delay: the delay [s].
        physics_dt: the physics step [s].
        exact: ``delay / physics_dt`` [steps], not rounded.
        steps: the whole number of steps written: ``exact`` rounded to the nearest (halves up).
    """

    delay: float
    physics_dt: float
    exact: float
    steps: int

    @property
    def whole(self) -> bool:
        """Whether the delay is a whole number of steps (within :data:`WHOLE_STEP`)."""
        return abs(self.exact - self.steps) <= WHOLE_STEP

    @property
    def warning(self) -> str | None:
        """One line when the delay is not a whole number of steps (what was written instead), else None."""
        if self.whole:
            return None
        return (f"the drivers' delay {self.delay:g} s is {self.exact:.3f} physics steps of {self.physics_dt:g} s: "
                f"written as {self.steps} ({self.steps * self.physics_dt:g} s)")


def delay_steps(delay: float, physics_dt: float = DEFAULT_PHYSICS_DT) -> DelaySteps:
    """``delay`` [s] in physics steps of ``physics_dt`` [s], rounded to the nearest whole step, halves up
    (``2.6 -> 3``, ``2.5 -> 3``, ``2.4 -> 2``).

    Raises:
        InputError: a physics step that is not a finite number > 0, a delay that is not a finite number >= 0.
    """
    if not (math.isfinite(physics_dt) and physics_dt > 0):
        raise InputError(f"--physics-dt: {physics_dt!r} is not a physics step > 0 [s]")
    if not (math.isfinite(delay) and delay >= 0):
        raise InputError(f"the drivers' delay {delay!r} is not a delay >= 0 [s]")
    exact = delay / physics_dt
    return DelaySteps(float(delay), float(physics_dt), exact, int(math.floor(exact + 0.5 + WHOLE_STEP)))


HOLD_EDGE = 1e-9
"""What a MuJoCo actuator's ``delay`` is written less than the drivers' [s]. MuJoCo 4's zero-order hold reads the
sample at or before ``time - delay``; a delay that is a whole number of timesteps falls on the sample times, where
the simulation's floating-point time makes it read one sample early or late from step to step (0.013 s at 1 ms:
13 or 14 steps; checked in ``tests/export/test_pd_exports.py``). One nanosecond less reads the sample the driver
applies, every step, for hours of simulated time (the time's rounding stays below 1e-11 s over a delay)."""

SMALLEST_TIMESTEP = 0.0005
"""The smallest MuJoCo timestep [s] an exported actuator's history holds its delay at (2 kHz; the project's hung
simulator steps at 1 ms, MuJoCo's default is 2 ms): a user may lower the file's timestep down to it."""


def history_samples(delay: float, timestep: float) -> int:
    """The ``nsample`` of a MuJoCo actuator whose control is delayed by ``delay`` [s]: the samples its history
    buffer must hold at the model's ``timestep`` [s] or any down to :data:`SMALLEST_TIMESTEP`,
    ``ceil(delay / min(timestep, SMALLEST_TIMESTEP)) + 1`` (one to spare). A shorter buffer makes MuJoCo 4 read its
    oldest sample, silently: a shorter delay (checked in ``tests/export/test_pd_exports.py``)."""
    return int(math.ceil(delay / min(timestep, SMALLEST_TIMESTEP) - WHOLE_STEP)) + 1


@dataclass(frozen=True)
class DriveExport:
    """The drivers of a robot's PD-driven joints, joint by joint, as the exports write them.

    Attributes:
        joints: the PD-driven joints, in :attr:`Robot.actuated` order.
        kp: joint -> position gain [N·m/rad].
        kd: joint -> velocity gain [N·m·s/rad].
        torque_limit: joint -> the torque the driver clips at [N·m] (inf: none).
        delay: the set-points' delay [s], one for the robot.
        encoder_offset: joint -> the logged angle minus the model's [rad] (:attr:`Robot.encoder_offset`), every
            joint the robot gives one for (PD-driven or not).
        armature: joint -> reflected rotor inertia [kg·m^2] of the PD-driven joints that have one: the
            exported one (:attr:`JointExport.armature`), else the robot model's where it is not zero.
        torque_offset: joint -> the constant ``tau_os`` [N·m] of the exported friction fit (the joint gets
            ``-tau_os``; module docstring), the PD-driven joints whose fit has a non-zero one.
    """

    joints: tuple[str, ...]
    kp: Mapping[str, float]
    kd: Mapping[str, float]
    torque_limit: Mapping[str, float]
    delay: float
    encoder_offset: Mapping[str, float]
    armature: Mapping[str, float]
    torque_offset: Mapping[str, float] = field(default_factory=dict)

    def offset(self, joint: str) -> float:
        """The encoder offset of ``joint`` [rad], 0 where none is given."""
        return float(self.encoder_offset.get(joint, 0.0))

    def setpoint_offset(self, joint: str) -> float:
        """What the driver of ``joint`` subtracts from its set-point [rad]: the encoder offset (its PD runs on the
        encoder's angle) and the constant torque as a set-point, ``offset + tau_os / kp`` (module docstring)."""
        return self.offset(joint) + float(self.torque_offset.get(joint, 0.0)) / self.kp[joint]


def model_armature(robot: Robot, joint: str) -> float:
    """The armature [kg·m^2] of ``joint`` in the robot model (``model.armature``: the TOML's ``[armature]``,
    else 0)."""
    model = robot.model
    return float(model.armature[model.idx_vs[model.getJointId(joint)]])


def drive_export(robot: Robot, joints: Mapping[str, JointExport] | None = None) -> DriveExport | None:
    """The drivers of ``robot``'s PD-driven joints (:attr:`Robot.pd`), None for a robot without.

    Args:
        robot: the robot.
        joints: the joints' exported parameters (:func:`~wbfriction.export.mapping.joint_exports`), whose armature
            is taken before the model's.

    Raises:
        InputError: an encoder offset that is not a finite number (naming the joint).
    """
    pd = robot.pd
    if pd is None:
        return None
    joints = joints or {}
    for name, value in robot.encoder_offset.items():
        if not np.isfinite(value):
            raise InputError(f"joint '{name}': encoder offset {value!r} is not a finite angle [rad]")
    armature: dict[str, float] = {}
    for name in pd.joints:
        exp = joints.get(name)
        given = exp.armature if exp is not None else None
        value = given if given is not None else model_armature(robot, name)
        if given is not None or value != 0.0:
            armature[name] = float(value)
    offsets = {n: float(robot.encoder_offset[n]) for n in robot.actuated if n in robot.encoder_offset}
    kp, kd, limit = (dict(zip(pd.joints, map(float, values))) for values in (pd.kp, pd.kd, pd.torque_limit))
    return DriveExport(tuple(pd.joints), kp, kd, limit, float(pd.delay), offsets, armature,
                       torque_offsets(pd.joints, joints))


def torque_offsets(pd_joints: Sequence[str], joints: Mapping[str, JointExport]) -> dict[str, float]:
    """The constant ``tau_os`` [N·m] of each PD-driven joint's exported friction (:attr:`DriveExport.torque_offset`):
    the fit's, with the model it exports (a fit with terms beyond velocity: its velocity model refitted with them).

    Raises:
        InputError: a ``tau_os`` that is not a finite number (naming the joint).
    """
    out = {}
    for name in pd_joints:
        exp = joints.get(name)
        tau_os = float(getattr(exp.params, "tau_os", 0.0)) if exp is not None and exp.has_friction else 0.0
        if not np.isfinite(tau_os):
            raise InputError(f"joint '{name}': tau_os {tau_os!r} is not a finite torque [N·m]")
        if tau_os != 0.0:
            out[name] = tau_os
    return out


def offset_lines(drive: DriveExport) -> list[str]:
    """One line per encoder offset, ``"<joint>": <rad>`` at full precision, in the robot's order."""
    return [f"{json.dumps(name)}: {value!r}" for name, value in drive.encoder_offset.items()]


def setpoint_offset_lines(drive: DriveExport) -> list[str]:
    """One line per joint with a constant torque, ``"<joint>": <rad> (tau_os <N·m> N·m)``: the set-point offset
    :meth:`DriveExport.setpoint_offset` at full precision and the ``tau_os`` it holds, in the robot's order."""
    return [f"{json.dumps(name)}: {drive.setpoint_offset(name)!r} (tau_os {tau_os!r} N·m)"
            for name, tau_os in drive.torque_offset.items()]
