"""The rollout check of a PD-driven robot's identified model (issue 55, item 6): the model replayed on MuJoCo under
a log's set-points, its joints' angles against the log's.

A parameter set (:class:`ActuatorParams`: friction per joint, and the armature, encoder offsets and drivers' delay,
each the robot TOML's unless given) runs on the robot's MuJoCo model (:mod:`wbfriction.sim.pd_robot`, the hung
simulator's: one way to build and run a PD-driven robot) from the log's state at the start of a stretch (the model's
angle: the logged one less the encoder offset; the logged velocity), its drivers sent the log's set-points
(``q_des``, ``qd_des``, ``tau_ff``, and ``kp``/``kd`` where logged; the ones commanded before the stretch feed the
delay), noise-free. The tracking error of each joint is the RMS over the stretch of the simulated logged angle
(``q + offset``) less the log's ``q`` [rad] (:class:`RolloutResult`); two parameter sets replayed on one stretch
(ours, a peer's) compare side by side (:func:`rollout_table`).

**Shooting.** By default one shot over the whole stretch (``horizon = None``): a PD-driven joint tracks its
set-point, so a model's error does not grow without bound; it stays at what the model gets wrong (the friction's
lag at every reversal, the armature's and the delay's phase), which is what the check measures. With a
``horizon`` of K seconds the replay restarts from the log's state every K seconds (multiple shooting): for long logs
where a model's slow drift (a joint that sticks in the model and not on the robot) would otherwise dominate. Each
restart takes the log's velocity, the driver's noisy one (0.08 rad/s on a real driver), so short horizons add a
transient of that noise to every shot. Measured on the hung Go2 (25 s, a real driver's noise, the true parameters):
2.3e-4 rad RMS at worst in one shot, 5.6e-4 restarting every 2 s, 8.0e-4 every 0.5 s; with wrong parameters the
three agree within 10 %. A horizon must hold two of the log's samples, and a log with gaps is replayed run by run,
each run's set-points only (:mod:`wbfriction.replay.feasibility`).

**A peer's delay.** PACE (the peer's method) delays the PD's torque, its feedback with its set-point
(:attr:`ActuatorParams.torque_delay`), where wbfriction's driver delays the set-points: replay a parameter set the
way it was identified. On the real Aliengo's last 40 % the peer's parameters track at 0.005-0.012 rad RMS with their
2 steps (10 ms) on the torque, at 0.015-0.024 with 10 ms on the set-points (their best set-point delay there: none,
0.010-0.013).
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.friction.models import ModelParams, ModelParamsBase
from wbfriction.logs.tables import numeric_columns, read_table
from wbfriction.model.robot import Robot
from wbfriction.replay.feasibility import (
    check_runs,
    check_torque_delay,
    check_window,
    log_runs,
    run_windows,
    stretch_runs,
    window_rows,
)
from wbfriction.sim.options import FrictionMode
from wbfriction.sim.pd_robot import Commands, PdMujocoRobot, PdRun, build_pd_robot, joint_values


@dataclass(frozen=True)
class ActuatorParams:
    """One parameter set of a PD-driven robot's drives, as the rollout replays it.

    Attributes:
        friction: per joint, parameters of any friction family the registry knows
            (:class:`~wbfriction.friction.families.params.ModelParamsBase`) or a fit holding them (``.params``:
            :class:`~wbfriction.fit.result.FitResult`, what :func:`~wbfriction.fit.params_file.read_params` reads; a
            fit without parameters: no friction), or the path of a parameters JSON; joints not named: none.
        armature: per joint [kg·m^2] (joints not named: 0); None: the robot's ``[armature]``.
        encoder_offset: per joint [rad] (joints not named: 0); None: the robot's ``[encoder_offset]``.
        delay: the drivers' delay [s]; None: the robot's ``[pd]`` delay.
        torque_delay: the delay holds back the PD's torque (its feedback and set-point alike, in whole physics
            steps), as PACE's actuator does (a peer's model), instead of the set-points (wbfriction's driver,
            :mod:`wbfriction.model.pd`); None: as the robot's ``[pd] delayed`` says.
        label: what the tables call the set (``"ours"``, ``"peer"``).
    """

    friction: Mapping[str, Any] | str | Path
    armature: Mapping[str, float] | None = None
    encoder_offset: Mapping[str, float] | None = None
    delay: float | None = None
    torque_delay: bool | None = None
    label: str = "model"


@dataclass(frozen=True, eq=False)
class RolloutResult:
    """A parameter set replayed over a stretch of a log (module docstring).

    Attributes:
        label: the parameter set's (:attr:`ActuatorParams.label`).
        joints: the joints, in the robot's order.
        rows: the stretch, rows ``[start, stop)`` of the log.
        time: the stretch's sample times (M,) [s].
        q_sim: the simulated logged angles (M, n) [rad] (the model's angle plus the encoder offset).
        q_log: the log's angles (M, n) [rad].
        horizon: the shots' length [s] (None: one shot).
        no_friction: joints replayed without friction (a fit without parameters, or none given).
        runs: the log's evenly sampled runs within the stretch, rows ``[a, b)`` each, each replayed on its own (one:
            the stretch; :mod:`wbfriction.replay.feasibility`); empty: not recorded.
    """

    label: str
    joints: tuple[str, ...]
    rows: tuple[int, int]
    time: np.ndarray
    q_sim: np.ndarray
    q_log: np.ndarray
    horizon: float | None
    no_friction: tuple[str, ...] = ()
    runs: tuple[tuple[int, int], ...] = ()

    @property
    def error(self) -> np.ndarray:
        """The simulated less the logged angles (M, n) [rad]."""
        return self.q_sim - self.q_log

    @property
    def rms(self) -> np.ndarray:
        """Each joint's RMS tracking error over the stretch (n,) [rad]."""
        return np.sqrt(np.mean(self.error**2, axis=0))

    def by_joint(self) -> dict[str, float]:
        """:attr:`rms` by joint name [rad]."""
        return {j: float(e) for j, e in zip(self.joints, self.rms)}


def rollout_table(results: Sequence[RolloutResult]) -> pa.Table:
    """Parameter sets replayed on one stretch, side by side: a row per joint, ``joint`` and ``rms.<label>`` [rad] per
    set (the labels distinct).

    Raises:
        InputError: no result, results of other joints or stretches, a label twice.
    """
    if not results:
        raise InputError("rollout_table: no rollout to tabulate")
    labels = [r.label for r in results]
    if len(set(labels)) != len(labels):
        raise InputError(f"rollout_table: the labels must differ, got {labels}")
    first = results[0]
    if any(r.joints != first.joints or r.rows != first.rows for r in results):
        raise InputError("rollout_table: the rollouts must be of the same joints over the same stretch")
    return pa.table({"joint": list(first.joints), **{f"rms.{r.label}": r.rms for r in results}})


def _friction(robot: Robot, given: Mapping[str, Any] | str | Path) -> tuple[dict[str, ModelParams], tuple[str, ...]]:
    """The friction parameters per joint of :attr:`ActuatorParams.friction`, and the joints without any."""
    if isinstance(given, (str, Path)):
        from wbfriction.fit.params_file import read_robot_params
        given = read_robot_params(given, robot.name, robot.actuated, robot.urdf)
    out: dict[str, ModelParams] = {}
    for joint, value in given.items():
        if joint not in robot.actuated:
            raise InputError(f"friction given for '{joint}', which is not a joint of {robot.name}")
        params = value if isinstance(value, ModelParamsBase) else getattr(value, "params", value)
        if params is None:
            continue
        if not isinstance(params, ModelParamsBase):
            raise InputError(f"friction of '{joint}': a friction family's parameters are replayed, got "
                             f"{type(params).__name__}")
        out[joint] = params  # type: ignore[assignment]  # any family's (the simulator asks the registry)
    return out, tuple(j for j in robot.actuated if j not in out)


@dataclass(frozen=True, eq=False)
class LogSetpoints:
    """What the rollout reads of a PD-driven robot's log (every joint, in the robot's order): ``time`` (N,) [s], the
    logged angles ``q`` and velocities ``qd`` (N, n), the :class:`~wbfriction.sim.pd_robot.Commands`, and the log's
    ``source`` (its file, or ``<table>``)."""

    time: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    commands: Commands
    source: str = "<table>"

    @functools.cached_property
    def runs(self) -> tuple[tuple[int, int], ...]:
        """The log's evenly sampled runs, rows ``[a, b)`` (:func:`~wbfriction.replay.feasibility.log_runs`: one
        without gaps).

        Raises:
            ReplayInfeasible: a time without a period."""
        return log_runs(self.time, self.source)


def read_log_setpoints(robot: Robot, log: pa.Table | str | Path) -> LogSetpoints:
    """The columns a rollout needs of a log (a table, or a file in any log format): ``time``, ``q.<joint>``,
    ``qd.<joint>`` (the driver's velocity; without it the angles' central difference), ``q_des.<joint>``, and where
    logged ``qd_des``, ``tau_ff`` (default 0), ``kp``, ``kd`` (default the robot's ``[pd]``).

    Raises:
        ColumnError: a required column missing, an optional one logged for some joints only.
        InputError: a file that cannot be read.
    """
    source = str(log) if isinstance(log, (str, Path)) else "<table>"
    table = read_table(log) if isinstance(log, (str, Path)) else log
    names = set(table.column_names)

    def group(prefix: str, required: bool) -> np.ndarray | None:
        cols = [f"{prefix}.{j}" for j in robot.actuated]
        there = [c in names for c in cols]
        if not any(there) and not required:
            return None
        if not all(there):
            missing = cols[there.index(False)]
            raise ColumnError(source, missing, None, f"missing column '{missing}' (the rollout replays every joint)")
        return numeric_columns(table, cols, source)

    if "time" not in names:
        raise ColumnError(source, "time", None, "missing column 'time'")
    time = numeric_columns(table, ["time"], source)[:, 0]
    q = group("q", True)
    q_des = group("q_des", True)
    assert q is not None and q_des is not None
    qd = group("qd", False)
    qd = np.gradient(q, time, axis=0) if qd is None else qd
    zeros = np.zeros_like(q)
    qd_des, tau_ff = group("qd_des", False), group("tau_ff", False)
    commands = Commands(q_des, zeros if qd_des is None else qd_des, zeros if tau_ff is None else tau_ff,
                        group("kp", False), group("kd", False))
    return LogSetpoints(time, q, qd, commands, source)


def stretch_rows(time: np.ndarray, rows: tuple[int, int] | None, times: tuple[float, float] | None) -> tuple[int, int]:
    """Rows ``[start, stop)`` of a stretch given by rows or by times [s] (``[t0, t1)``), at least two samples."""
    if rows is not None and times is not None:
        raise InputError("a rollout's stretch is given by rows or by times, not both")
    n = len(time)
    start, stop = (0, n) if rows is None else rows
    if times is not None:
        start, stop = (int(np.searchsorted(time, t, side="left")) for t in times)
    if not 0 <= start < stop <= n or stop - start < 2:
        where = "" if times is None else (f" (times {_time_text(times[0], 'start')} to {_time_text(times[1], 'end')}; "
                                          f"the log's run from {time[0]:g} to {time[-1]:g} s)")
        raise InputError(f"the replay's stretch (rows {start} to {stop}{where}) must hold at least two of the log's "
                         f"{n} rows")
    return start, stop


def _time_text(t: float, side: str) -> str:
    return f"{t:g} s" if np.isfinite(t) else f"the log's {side}"


def rollout(robot: Robot, log: pa.Table | str | Path | LogSetpoints, params: ActuatorParams, *,
            rows: tuple[int, int] | None = None, times: tuple[float, float] | None = None,
            horizon: float | None = None, substeps: int = 5, friction_mode: FrictionMode = "model",
            mjr: PdMujocoRobot | None = None) -> RolloutResult:
    """Replay a parameter set under a log's set-points (module docstring).

    Args:
        robot: the robot (URDF, ``[pd]`` gains, limits; the armature, encoder offsets and delay where ``params``
            gives none): a fixed base, every joint PD-driven.
        log: the log (a table, a file, or :func:`read_log_setpoints`'s reading of it).
        params: :class:`ActuatorParams`.
        rows: the stretch as rows ``[start, stop)``; times: as times ``[t0, t1)`` [s]; neither: the whole log.
        horizon: restart from the log's state every so many seconds (multiple shooting); None: one shot.
        substeps: physics steps per log period (5: 1 ms at 200 Hz).
        friction_mode: ``"model"`` or ``"mujoco"`` (:mod:`wbfriction.sim.pd_robot`).
        mjr: the robot's MuJoCo model, if already built.

    Returns:
        :class:`RolloutResult`.

    Raises:
        InputError: a stretch out of the log, a horizon <= 0, values for unknown joints, friction that is no family's
            parameters, a robot that is not a fixed-base PD-driven one.
        ReplayInfeasible: a horizon of fewer than two samples, a stretch without two rows a period apart, a torque
            delay as long as a horizon (:mod:`wbfriction.replay.feasibility`), before any replay.
        UnknownFamilyError: parameters of a family the registry does not know.
        ColumnError: a column the replay needs is missing.
    """
    mjr = mjr or build_pd_robot(robot)
    data = log if isinstance(log, LogSetpoints) else read_log_setpoints(robot, log)
    start, stop = stretch_rows(data.time, rows, times)
    if horizon is not None and not horizon > 0:
        raise InputError(f"the rollout's horizon must be > 0 s, got {horizon}")
    friction, bare = _friction(robot, params.friction)
    armature = joint_values(robot, params.armature, dict(zip(robot.actuated, robot.model.armature[robot.act_v_index])),
                          "armature")
    offset = joint_values(robot, params.encoder_offset, robot.encoder_offset, "encoder offset")
    driver = mjr.driver if params.delay is None else mjr.driver.with_delay(params.delay)
    period = float(np.median(np.diff(data.time)))
    run = PdRun(mjr, period, substeps, driver, armature, offset, friction, friction_mode,
                torque_delay=params.torque_delay)
    shot = window_rows(horizon, period, (start, stop))
    check_window(data.source, horizon, period, (start, stop))
    check_runs(data.source, data.runs, (start, stop))
    if run.torque_delay is not None:
        check_torque_delay(data.source, run.torque_delay / substeps, period, shot)
    q_sim = np.empty((stop - start, robot.n_act))
    for first, last in run_windows(data.runs, start, stop, shot):
        a, b = next(r for r in data.runs if r[0] <= first < r[1])  # the run's set-points only: none across a gap
        trajectory = run.run(_rows(data.commands, a, b), first - a, last - a, data.q[first] - offset, data.qd[first])
        q_sim[first - start:last - start] = trajectory.q + offset
    return RolloutResult(params.label, robot.actuated, (start, stop), data.time[start:stop], q_sim,
                         data.q[start:stop].copy(), horizon, bare, stretch_runs(data.runs, (start, stop)))


def _rows(commands: Commands, a: int, b: int) -> Commands:
    """The commands of rows ``[a, b)`` (views)."""
    c = commands
    return Commands(c.q_des[a:b], c.qd_des[a:b], c.tau_ff[a:b], None if c.kp is None else c.kp[a:b],
                    None if c.kd is None else c.kd[a:b])
