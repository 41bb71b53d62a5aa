"""An exported simulator file replayed under a log's set-points, as that simulator runs it (issue 64, item 3): the
check of what a user of ``wbfriction export`` gets.

:mod:`wbfriction.replay.rollout` replays a parameter set on the project's own simulator (its friction drawn as the fit's
model, ``tau_os`` included, the PD law every physics step). What a user simulates is the exported file: MuJoCo's
``frictionloss`` and ``damping`` instead of the model, the drivers as the file's actuators hold them. This module runs
that file (:func:`replay_mjcf`): the robot's PD-driven joints' actuators, each named as its joint (what ``wbfriction
export`` writes; :mod:`wbfriction.export.mjcf`), are sent the log's ``q_des``, each sample held until the next (the
drivers' zero-order hold, :mod:`wbfriction.model.pd`), at the file's own timestep, with the file's gains, offsets,
torque limits and set-point delay (MuJoCo 4's actuator ``delay``, its history filled with the set-points commanded
before the stretch).

**A peer's actuator.** PACE (the peer's method) runs Isaac Lab at the log's rate and delays the PD's whole torque,
feedback and set-point alike, by a whole number of physics steps (:attr:`Replay.torque_delay`): with it, the file's
actuators' law (its gain and bias, clipped at its force range) is computed once a log period on the simulated state,
and its torque applied ``torque_delay`` periods later, held through the period (``qfrc_applied``; the actuators
themselves off). The file's physics step is then the log's period divided into whole steps, the largest at most
the file's. This is how a torque-delayed model, which no MJCF holds, is scored as it was identified.

**Windows.** As in :mod:`wbfriction.replay.rollout`, every ``horizon`` seconds the replay restarts from the log's
state (the model's angle: the logged one less the encoder offset; the logged velocity): 1 s by default, the error
a simulator's user sees over a second of its own motion; ``horizon=None`` replays the stretch in one shot. A log with
gaps is replayed run by run (:func:`~wbfriction.replay.feasibility.log_runs`): a window restarts at each run's first
row too, its history that row's set-point.

**What is refused.** Before any replay (:func:`checked_replay`) the file must be the robot's (its model, joints and
encoder offsets), its timestep must hold the actuators' delay and the log's set-points, the windows two samples,
PACE's torque delay less than a window (:mod:`wbfriction.replay.feasibility`).

Sources: MuJoCo 4.0.0 ``mj_initCtrlHistory`` (the actuator's history), ``actuator_gainprm``/``biasprm`` (the
affine law ``force = gainprm[0] ctrl + biasprm[0] + biasprm[1] qpos + biasprm[2] qvel``); PACE's actuator
(leggedrobotics/pace-sim2real, ``pace_actuator.py``: the PD torque pushed through Isaac Lab's ``DelayBuffer``).
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.export.drive import HOLD_EDGE
from wbfriction.model.robot import Robot
from wbfriction.replay.feasibility import (
    check_history,
    check_robot,
    check_runs,
    check_timestep,
    check_torque_delay,
    check_window,
    log_period,
    run_windows,
    stretch_runs,
    window_rows,
)
from wbfriction.replay.rollout import LogSetpoints, RolloutResult, read_log_setpoints, stretch_rows


@dataclass(frozen=True)
class Replay:
    """How a file is replayed (module docstring).

    Attributes:
        label: what the tables call it (``"ours"``, ``"peer"``).
        horizon: restart from the log's state every so many seconds; None: one shot.
        torque_delay: PACE's actuator: the PD torque computed once a log period and held back so many periods
            (whole, >= 0); None: the file's own actuators (its set-point delay).
        timestep: the physics step [s]; None: the file's (with ``torque_delay``: the log's period in whole steps of
            at most it).
    """

    label: str = "model"
    horizon: float | None = 1.0
    torque_delay: int | None = None
    timestep: float | None = None

    def __post_init__(self) -> None:
        if self.horizon is not None and not (math.isfinite(self.horizon) and self.horizon > 0):
            raise InputError(f"the replay's horizon must be a time > 0 [s], got {self.horizon!r}")
        if self.torque_delay is not None and self.torque_delay < 0:
            raise InputError(f"the replay's torque delay must be a whole number of periods >= 0, got "
                             f"{self.torque_delay}")
        if self.timestep is not None and not (math.isfinite(self.timestep) and self.timestep > 0):
            raise InputError(f"the replay's timestep must be > 0 [s], got {self.timestep!r}")


@dataclass(frozen=True, eq=False)
class _Drives:
    """The file's PD-driven joints: their actuators, qpos and dof addresses, and the law's parameters."""

    acts: np.ndarray
    qpos: np.ndarray
    dofs: np.ndarray
    gain: np.ndarray
    bias: np.ndarray
    limit: np.ndarray


def _drives(model, robot: Robot, source: str) -> _Drives:
    """The actuators of the robot's PD-driven joints in ``model``, each named as its joint and driving it, a position
    actuator (affine bias; not the ``<motor>`` an export writes on a torque-controlled joint)."""
    import mujoco

    if robot.pd is None:
        raise InputError(f"{robot.name}: no PD-driven joints ([pd] in its TOML): nothing to replay set-points on")
    acts, qpos, dofs = [], [], []
    for name in robot.actuated:
        act, joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name), \
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if joint < 0:
            raise InputError(f"{source}: no joint '{name}' (a joint of {robot.name}): not this robot's model")
        if act < 0 or model.actuator_trnid[act, 0] != joint \
                or model.actuator_biastype[act] != mujoco.mjtBias.mjBIAS_AFFINE:  # a motor: a torque-driven export
            raise InputError(f"{source}: no position actuator named '{name}' driving its joint (what 'wbfriction "
                             f"export' writes for a PD-driven joint)")
        acts.append(act)
        qpos.append(model.jnt_qposadr[joint])
        dofs.append(model.jnt_dofadr[joint])
    acts_a = np.array(acts)
    limit = np.where(model.actuator_forcelimited[acts_a] == 1, model.actuator_forcerange[acts_a, 1], np.inf)
    return _Drives(acts_a, np.array(qpos), np.array(dofs), model.actuator_gainprm[acts_a, 0].copy(),
                   model.actuator_biasprm[acts_a, :3].copy(), limit)


def _check_setpoints(data: LogSetpoints, drives: _Drives, source: str) -> None:
    """Refuse a log whose commands the file's position actuators cannot take: a velocity set-point or a
    feed-forward torque (no input there), gains other than the file's."""
    c = data.commands
    for what, values in (("qd_des", c.qd_des), ("tau_ff", c.tau_ff)):
        if np.any(values != 0.0):
            raise InputError(f"{source}: the log's '{what}' columns are not zero; a position actuator has no input for "
                             f"them (the replay sends q_des only)")
    for what, logged, held in (("kp", c.kp, drives.gain), ("kd", c.kd, -drives.bias[:, 2])):
        if logged is not None and not np.allclose(logged, held, rtol=1e-9, atol=0.0):
            raise InputError(f"{source}: the log's '{what}' differs from the file's actuators' ({what} = "
                             f"{', '.join(f'{x:g}' for x in held)}): export with the robot TOML of this log")


@dataclass(frozen=True, eq=False)
class ReplayModel:
    """An MJCF loaded for replays (:func:`load_replay`): the compiled model (its timestep and flags set as
    ``replay`` asks) and its PD-driven joints' actuators."""

    model: Any
    drives: _Drives
    replay: Replay
    source: str

    @property
    def delay(self) -> float:
        """The set-points' delay of the PD-driven joints' actuators [s] (the file's ``delay`` plus
        :data:`~wbfriction.export.drive.HOLD_EDGE`; 0 without a history), their first's."""
        d = float(self.model.actuator_delay[self.drives.acts[0]])
        return d + HOLD_EDGE if d > 0 else 0.0

    @property
    def longest_delay(self) -> float:
        """The longest delay the actuators' history buffers hold at the model's timestep [s] (0 without one)."""
        samples = int(self.model.actuator_history[self.drives.acts, 0].min())
        return max(samples - 1, 0) * float(self.model.opt.timestep)

    def with_parameters(self, armature: np.ndarray, frictionloss: np.ndarray, damping: np.ndarray,
                        bias: np.ndarray, delay: float | None = None) -> ReplayModel:
        """A copy with these (n,) values for the PD-driven joints, in the robot's order: ``dof_armature``
        [kg·m^2], ``dof_frictionloss`` [N·m], ``dof_damping`` [N·m·s/rad] and the actuators' ``biasprm[0]``
        [N·m], and the set-points' ``delay`` [s] (at most :attr:`longest_delay`; None: the file's); the constants
        that depend on them recomputed (``mj_setConst``)."""
        import mujoco

        m = copy.copy(self.model)
        d = self.drives
        m.dof_armature[d.dofs], m.dof_frictionloss[d.dofs], m.dof_damping[d.dofs] = armature, frictionloss, damping
        m.actuator_biasprm[d.acts, 0] = bias
        if delay is not None:
            m.actuator_delay[d.acts] = max(delay - HOLD_EDGE, 0.0)
        mujoco.mj_setConst(m, mujoco.MjData(m))
        drives = dataclasses.replace(d, bias=m.actuator_biasprm[d.acts, :3].copy())
        return ReplayModel(m, drives, self.replay, self.source)

    def run(self, robot: Robot, data: LogSetpoints, start: int, stop: int, horizon: float | None) -> np.ndarray:
        """The simulated logged angles (the model's plus the encoder offset) of rows ``[start, stop)`` of ``data``,
        restarted from the log's state every ``horizon`` seconds (None: one shot) [rad], (stop - start, n).

        Raises:
            SimulationError: the state diverged.
        """
        import mujoco

        from wbfriction.exceptions import SimulationError

        m, drives, replay = self.model, self.drives, self.replay
        period = float(np.median(np.diff(data.time)))
        offset = robot.offset_vector
        q_sim = np.empty((stop - start, robot.n_act))
        d = mujoco.MjData(m)
        run = _actuated if replay.torque_delay is None else functools.partial(_held_torque, delay=replay.torque_delay)
        for first, last in run_windows(data.runs, start, stop, window_rows(horizon, period, (start, stop))):
            mujoco.mj_resetData(m, d)
            d.qpos[drives.qpos], d.qvel[drives.dofs] = data.q[first] - offset, data.qd[first]
            run_start = next(a for a, b in data.runs if a <= first < b)
            q_sim[first - start:last - start] = run(m, d, drives, data, first, last, period, run_start)
            if not np.all(np.isfinite(q_sim[first - start:last - start])):
                raise SimulationError(f"{self.source}: the replay diverged between rows {first} and {last}")
        return q_sim + offset


def load_replay(model: str | Path, robot: Robot, data: LogSetpoints, replay: Replay = Replay()) -> ReplayModel:
    """``model`` (an MJCF) loaded to replay ``data``, a log of ``robot`` (:func:`replay_mjcf`), its timestep set as
    ``replay`` asks, once the file is this robot's and its timestep replays the log (:mod:`.feasibility`: the
    file's model and offsets against the robot TOML's, the timestep against the log period and the actuators'
    history).

    Raises:
        InputError: a file MuJoCo cannot load, a floating-base robot, a joint or actuator the file lacks, a log with
            velocity set-points, feed-forward torques or gains the file does not hold.
        ReplayInfeasible: another robot's file, other encoder offsets, a log without a period, a timestep longer
            than the log period or too short for the actuators' history (:mod:`.feasibility`).
    """
    import mujoco

    source = str(model)
    if robot.floating_base:
        raise InputError(f"{robot.name}: the replay holds the base fixed, as in a hung robot's log; this robot's base "
                         "floats (floating_base = true)")
    try:
        m = mujoco.MjModel.from_xml_path(source)
    except (ValueError, OSError) as err:
        raise InputError(f"{source}: MuJoCo cannot load it: {err}") from None
    check_robot(source, m, robot)
    drives = _drives(m, robot, source)
    _check_setpoints(data, drives, source)
    period = log_period(data.time, data.source)
    if replay.timestep is not None:
        m.opt.timestep = replay.timestep
    if replay.torque_delay is not None:
        m.opt.timestep = period / math.ceil(period / m.opt.timestep - 1e-9)
        m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_ACTUATION
    else:
        check_history(source, m, drives.acts, robot.actuated)
    check_timestep(source, float(m.opt.timestep), period, Path(data.source).name)
    return ReplayModel(m, drives, replay, source)


def checked_replay(model: str | Path, robot: Robot, data: LogSetpoints, replay: Replay = Replay(), *,
                   rows: tuple[int, int] | None = None,
                   times: tuple[float, float] | None = None) -> tuple[ReplayModel, tuple[int, int]]:
    """``model`` loaded to replay a stretch of ``data`` (:func:`load_replay`) and the stretch's rows ``[start,
    stop)`` (rows or times ``[t0, t1)`` [s]; neither: the whole log), once the replay is known feasible there
    (:mod:`.feasibility`): its windows hold two samples at least, one of its runs two rows, PACE's torque delay is
    shorter than a window. What :func:`replay_mjcf` and :func:`~wbfriction.replay.refine.refine_mjcf` start with,
    before any replay.

    Raises:
        what :func:`load_replay` raises; InputError: a stretch out of the log; ReplayInfeasible: the above.
    """
    loaded = load_replay(model, robot, data, replay)
    stretch = stretch_rows(data.time, rows, times)
    period = log_period(data.time, data.source)
    check_window(data.source, replay.horizon, period, stretch)
    check_runs(data.source, data.runs, stretch)
    if replay.torque_delay is not None:
        check_torque_delay(loaded.source, replay.torque_delay, period, window_rows(replay.horizon, period, stretch))
    return loaded, stretch


def replay_mjcf(model: str | Path, robot: Robot, log: pa.Table | str | Path | LogSetpoints, replay: Replay = Replay(),
                *, rows: tuple[int, int] | None = None, times: tuple[float, float] | None = None) -> RolloutResult:
    """Replay an MJCF file under a log's set-points (module docstring).

    Args:
        model: the MJCF file (``wbfriction export -o robot.xml``): its PD-driven joints' actuators named as the joints.
        robot: the robot it was exported for (its TOML): the PD-driven joints, and the encoder offsets that take the
            log's angles to the model's; a fixed base (:attr:`Robot.floating_base` false).
        log: the log (a table, a file, or :func:`~wbfriction.replay.rollout.read_log_setpoints`'s reading of it):
            ``time``, ``q``, ``qd``, ``q_des`` of every PD-driven joint.
        replay: :class:`Replay`.
        rows, times: the stretch, as rows ``[start, stop)`` or times ``[t0, t1)`` [s]; neither: the whole log.

    Returns:
        :class:`~wbfriction.replay.rollout.RolloutResult`: the simulated logged angles (the model's plus the encoder
        offset) against the log's [rad].

    Raises:
        InputError: what :func:`load_replay` refuses, a stretch out of the log.
        ColumnError: a column the replay needs is missing.
        SimulationError: the state diverged.
    """
    data = log if isinstance(log, LogSetpoints) else read_log_setpoints(robot, log)
    loaded, (start, stop) = checked_replay(model, robot, data, replay, rows=rows, times=times)
    q_sim = loaded.run(robot, data, start, stop, replay.horizon)
    return RolloutResult(replay.label, robot.actuated, (start, stop), data.time[start:stop], q_sim,
                         data.q[start:stop].copy(), replay.horizon, runs=stretch_runs(data.runs, (start, stop)))


def _actuated(m, d, drives: _Drives, data: LogSetpoints, first: int, last: int, period: float,
              run_start: int = 0) -> np.ndarray:
    """Samples ``[first, last)`` run by the file's actuators: ``q_des`` held a period each, the history holding
    those commanded before ``first`` (at their times) from the run's first row ``run_start`` on (before it, that
    row's); the model's angles at each sample (last - first, n)."""
    import mujoco

    q_des, n = data.commands.q_des, len(data.time)
    h = m.opt.timestep
    for a, act in enumerate(drives.acts):
        samples = int(m.actuator_history[act, 0])
        if samples:
            times = -h * np.arange(samples - 1, -1, -1, dtype=float)
            held = np.clip(first + np.floor(times / period + 1e-9).astype(int), run_start, n - 1)
            mujoco.mj_initCtrlHistory(m, d, int(act), times.reshape(-1, 1), np.ascontiguousarray(q_des[held, a:a + 1]))
    out = np.empty((last - first, len(drives.acts)))
    out[0] = d.qpos[drives.qpos]
    for k in range(1, last - first):
        while d.time < k * period - 1e-9 * period:
            d.ctrl[drives.acts] = q_des[first + int(math.floor(d.time / period + 1e-9))]
            mujoco.mj_step(m, d)
        out[k] = d.qpos[drives.qpos]
    return out


def _held_torque(m, d, drives: _Drives, data: LogSetpoints, first: int, last: int, period: float,
                 run_start: int = 0, *, delay: int) -> np.ndarray:
    """Samples ``[first, last)`` run by PACE's actuator (module docstring): the law on the state at each sample,
    applied ``delay`` samples later (before then, the first torque); the model's angles at each sample."""
    import mujoco

    q_des = data.commands.q_des
    substeps = int(round(period / m.opt.timestep))
    torques: list[np.ndarray] = []
    out = np.empty((last - first, len(drives.acts)))
    out[0] = d.qpos[drives.qpos]
    for k in range(last - first - 1):
        law = (drives.gain * q_des[first + k] + drives.bias[:, 0] + drives.bias[:, 1] * d.qpos[drives.qpos]
               + drives.bias[:, 2] * d.qvel[drives.dofs])
        torques.append(np.clip(law, -drives.limit, drives.limit))
        d.qfrc_applied[drives.dofs] = torques[max(0, k - delay)]
        for _ in range(substeps):
            mujoco.mj_step(m, d)
        out[k + 1] = d.qpos[drives.qpos]
    return out


@dataclass(frozen=True)
class ReplayCheck:
    """A file replayed two ways over one stretch (:func:`replay_check`): restarted from the log every
    ``horizon`` seconds (``windows``) and in one shot (``whole``), each a
    :class:`~wbfriction.replay.rollout.RolloutResult`."""

    windows: RolloutResult
    whole: RolloutResult

    def table(self) -> pa.Table:
        """A row per joint: ``joint``, ``rms_windows`` and ``rms_whole`` [rad]."""
        return pa.table({"joint": list(self.windows.joints), "rms_windows": self.windows.rms,
                         "rms_whole": self.whole.rms})


def replay_check(model: str | Path, robot: Robot, log: str | Path, replay: Replay = Replay(), *,
                 times: tuple[float, float] | None = None, output: str | Path | None = None) -> ReplayCheck:
    """What ``wbfriction rollout`` runs: ``model`` (an MJCF ``wbfriction export`` wrote for ``robot``) replayed under
    the set-points of ``log`` over ``times`` ([t0, t1) [s]; None: the whole log) in windows of ``replay.horizon``
    and in one shot (:func:`replay_mjcf`); the table (:meth:`ReplayCheck.table`) written to ``output`` where given,
    whole or not at all.

    Raises:
        what :func:`replay_mjcf` raises; InputError: an output that cannot be written.
    """
    from dataclasses import replace

    from wbfriction.logs.tables import write_table

    data = read_log_setpoints(robot, log)
    check = ReplayCheck(replay_mjcf(model, robot, data, replay, times=times),
                        replay_mjcf(model, robot, data, replace(replay, horizon=None), times=times))
    if output is not None:
        write_table(check.table(), output)
    return check
