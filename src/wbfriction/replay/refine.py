"""The exported simulator's parameters refined on its own tracking error (issue 64, item 2).

The regression (``identify --actuator pd``, ``estimate``, ``fit``) fits torque residuals; what a simulator's user
judges is whether the simulator, driven by the logged set-points, moves as the robot did. :func:`refine_mjcf` starts
from an exported MJCF (``wbfriction export``) and moves four values of each PD-driven joint, the ones MuJoCo holds
for its friction and drive:

* ``armature`` [kg·m^2] (``dof_armature``),
* ``F_c`` [N·m] (``dof_frictionloss``: MuJoCo's Coulomb friction, a soft constraint),
* ``F_v`` [N·m·s/rad] (``dof_damping``),
* ``tau_os`` [N·m]: the drive's constant torque (``biasprm[0] = -kp offset - tau_os``, the encoder offset the
  robot TOML's; :mod:`wbfriction.export.drive`),

and the set-points' delay (the actuators' ``delay``, one for all), to minimise the replay's error
(:mod:`wbfriction.replay.mjcf`, as the file runs: its timestep, gains and limits) over a training stretch: every
joint's simulated less logged angle, in windows restarted from the log every ``horizon`` seconds, each joint's error
divided by its RMS (the joints weigh alike, each weighted error of unit variance).

**The values** at a given delay: SciPy's ``least_squares`` (trust-region reflective; armature, F_c, F_v >= 0) with
a finite-difference Jacobian. A hung robot's joints on different branches from the fixed base do not move one
another: a joint's error depends only on its own branch's values (a leg's), so the Jacobian's columns of different
branches are taken in one replay (its sparsity given to SciPy): a step costs ``4 x`` (the joints of the longest
branch) replays, at most :data:`MAX_REPLAYS` a solve.

**The delay** acts in whole timesteps (MuJoCo's history holds one set-point a step, read with a zero-order hold), so
it is profiled, not differentiated: the values are solved at each delay a pattern search visits (from the file's,
steps of a log period in whole timesteps, halved down to one; each solve started from the nearest delay's), and the
delay of the least error kept. Delay, armature and damping trade off against one another (each shifts the joint's
phase): refining the values at the file's delay alone leaves the file's delay error in them (the hung Go2 with
MuJoCo's friction: F_v 30-40 % low at the identified 16 ms, within 2 % at the 12 ms profiled). The values are then
solved once more with each joint's weight its refined RMS.

**Standard errors.** Each window is one rollout restarted from the log: the windows' errors are independent draws
(the restart resets the error), a window's correlated over its length. The sandwich of the weighted errors
(:func:`wbfriction.actuator.solve.sandwich`) sums each window's scores (cluster-robust: Cameron and Miller, "A
Practitioner's Guide to Cluster-Robust Inference", 2015), each variance the least squares' or larger, the delay's
column (central differences of one timestep) beside the values'. At the optimum the ``G`` windows' scores sum to
zero: the variance has ``G - 1`` degrees of freedom, and the standard errors are put on the normal scale
(:func:`window_scale`: ``sqrt(G / (G - 1))`` and ``t_{G-1}``'s quantile over the normal's; 1.9 at four windows, 1.14
at fourteen); a stretch of one window (``horizon=None``, or a stretch no longer than ``horizon``) estimates no
variance, and its standard errors are infinite. A solve stopped by its budget (:data:`MAX_REPLAYS`) has the values'
remaining Gauss-Newton step (how far they would still move) added in quadrature.

**Statuses** are ``identify --actuator pd``'s, by the same functions (:func:`judged_value`): a value's own
(:func:`~wbfriction.actuator.identification.parameter_status`): ``not excited`` where the replay does not depend on
it, ``at bound`` on its floor of zero where the error presses it there, ``weak`` where its standard error is above
:data:`~wbfriction.fit.status.WEAK` of it (for ``tau_os``: of the larger of it and ``F_c``) or infinite; then what
the stretch does not determine (:func:`~wbfriction.actuator.identification.judged`): a joint that hardly moved over
the stretch leaves its values ``not excited``, one that moved one way its F_c and ``tau_os`` ``weak``
(:func:`~wbfriction.actuator.excitation.stretch_motion`: the balance's windows of the logged angles), and a delay
at the longest the file's history holds leaves every value fitted under it ``at bound`` (the delay may be longer,
and the values then hold what it leaves). The delay's own status is
:func:`~wbfriction.actuator.identification.delay_status`'s: ``at bound`` at zero or at the history's longest,
``weak`` with a standard error above :data:`~wbfriction.fit.status.WEAK` of it and a log period.

**What it is not.** The refined values are MuJoCo's: they make this file track, including what the file does
otherwise than the robot (its timestep, its soft friction constraint, its implicit damping, a delay in another form
than the robot's). They are not the robot's friction law; the regression's fits (``fit``) remain that. On the hung
Go2 with MuJoCo's own friction, noise-free, the refinement finds F_c and F_v within 0.06 %, the delay to the step,
and the armature less ``h F_v`` (MuJoCo's Euler step integrates ``dof_damping`` implicitly, an inertia of
``h F_v`` that the simulator's explicit damping does not have). The encoder offsets stay the robot TOML's (an
offset's error, seen by gravity, goes into ``tau_os`` and the armature). The held-out stretch (``wbfriction
rollout``, ``refine --held-out``) says whether the refinement generalises.

Sources: Gauss-Newton on rollout (shooting) errors as in output-error identification (Ljung, *System
Identification*, 2nd ed., ch. 7); PACE (leggedrobotics/pace-sim2real) fits the same objective by CMA-ES over GPU
rollouts.
"""

from __future__ import annotations

import time as clock
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from wbfriction.actuator.excitation import JointMotion, stretch_motion
from wbfriction.actuator.identification import Identified, fitted_under, judged, parameter_status
from wbfriction.actuator.identification import delay_status as identified_delay_status
from wbfriction.actuator.solve import sandwich
from wbfriction.exceptions import InputError
from wbfriction.export.drive import HOLD_EDGE
from wbfriction.fit.block_spread import t_scale
from wbfriction.model.robot import Robot
from wbfriction.replay.mjcf import Replay, ReplayModel, checked_replay
from wbfriction.replay.rollout import LogSetpoints, read_log_setpoints

PARAMETERS = ("armature", "F_c", "F_v", "tau_os")
"""The refined values of each joint, in the order of :attr:`Refinement.value`'s rows."""
UNITS = {"armature": "kg·m²", "F_c": "N·m", "F_v": "N·m·s/rad", "tau_os": "N·m"}
MAX_REPLAYS = 200
"""A solve's budget of replays (a step costs ``4 x`` a branch's joints, 12 for a leg of 3): 15 steps. The hung
Go2's solves stop within it; most of the Aliengo's stop at it, and a budget of 400 leaves its refined file's
held-out error where it was (4.24 mrad both; measured)."""


@dataclass(frozen=True)
class Refinement:
    """A refined MJCF's parameters (:func:`refine_mjcf`).

    Attributes:
        joints: the PD-driven joints, in the robot's order (n).
        start: the values read from the file (4, n), rows as :data:`PARAMETERS`.
        value: the refined values (4, n).
        stderr: their standard errors (4, n) (module docstring); inf where the replay does not depend on one.
        status: each value's status (4 tuples of n).
        rms_start: each joint's RMS tracking error over the training stretch, at the start [rad] (n,).
        rms: the same at the refined values [rad] (n,).
        rows: the training stretch, rows ``[start, stop)`` of the log.
        replays: how many replays the refinement took.
        seconds: how long it took [s].
        converged: whether SciPy's least squares met a tolerance (not its budget, :data:`MAX_REPLAYS`).
        delay_start: the file's set-points' delay [s].
        delay: the refined delay [s] (:func:`delay_grid`'s best).
        delay_se: its standard error [s] (nan where not refined).
        delay_status: its status; ``not refined`` where :func:`delay_grid` is empty, ``at bound`` at the grid's end.
        reason: why each value is not ``ok`` (4 tuples of n; "" where it is), as :attr:`status`; empty for a
            refinement built without them.
    """

    joints: tuple[str, ...]
    start: np.ndarray
    value: np.ndarray
    stderr: np.ndarray
    status: tuple[tuple[str, ...], ...]
    rms_start: np.ndarray
    rms: np.ndarray
    rows: tuple[int, int]
    replays: int
    seconds: float
    converged: bool
    delay_start: float
    delay: float
    delay_se: float
    delay_status: str
    reason: tuple[tuple[str, ...], ...] = ()

    def table(self) -> pa.Table:
        """A row per joint and value: ``joint``, ``parameter`` (:data:`PARAMETERS`, then ``delay``, each joint's
        actuator's), ``unit``, ``start`` (the file's), ``value``, ``stderr``, ``status``."""
        n = len(self.joints)
        names = (*PARAMETERS, "delay")
        start = np.vstack([self.start, np.full(n, self.delay_start)])
        value = np.vstack([self.value, np.full(n, self.delay)])
        stderr = np.vstack([self.stderr, np.full(n, self.delay_se)])
        status = (*self.status, (self.delay_status,) * n)
        return pa.table({"joint": [j for _ in names for j in self.joints],
                         "parameter": [p for p in names for _ in range(n)],
                         "unit": [{**UNITS, "delay": "s"}[p] for p in names for _ in range(n)],
                         "start": start.ravel(), "value": value.ravel(), "stderr": stderr.ravel(),
                         "status": [s for row in status for s in row]})


def branches(loaded: ReplayModel) -> np.ndarray:
    """Each PD-driven joint's branch (n,): the index of its topmost moving ancestor's dof; two joints of different
    branches do not move one another on a fixed base."""
    parent = loaded.model.dof_parentid
    top = []
    for dof in loaded.drives.dofs:
        while parent[dof] >= 0:
            dof = parent[dof]
        top.append(int(dof))
    return np.array(top)


def actuator_bias(gain: np.ndarray | float, offset: np.ndarray | float, tau_os: np.ndarray | float) -> Any:
    """The actuator's ``biasprm[0]`` [N·m] of a drive of gain ``gain`` [N·m/rad], encoder offset ``offset`` [rad]
    and constant torque ``tau_os`` [N·m]: ``-kp offset - tau_os`` (:mod:`wbfriction.export.drive`)."""
    return -gain * offset - tau_os


def file_parameters(loaded: ReplayModel, robot: Robot) -> np.ndarray:
    """The file's :data:`PARAMETERS` of each PD-driven joint (4, n)."""
    m, d = loaded.model, loaded.drives
    tau_os = actuator_bias(d.gain, robot.offset_vector, 0.0) - m.actuator_biasprm[d.acts, 0]  # its inverse
    return np.stack([m.dof_armature[d.dofs], m.dof_frictionloss[d.dofs], m.dof_damping[d.dofs], tau_os])


@dataclass(frozen=True, eq=False)
class _Problem:
    """The training stretch's replay errors as a function of the refined values."""

    loaded: ReplayModel
    robot: Robot
    data: LogSetpoints
    rows: tuple[int, int]
    horizon: float | None

    @property
    def period(self) -> float:
        """The log's sample period [s]."""
        return float(np.median(np.diff(self.data.time)))

    def error(self, x: np.ndarray, delay: float | None) -> np.ndarray:
        """The simulated less logged angles (N, n) [rad] at the values ``x`` (4, n) and ``delay`` [s]."""
        bias = actuator_bias(self.loaded.drives.gain, self.robot.offset_vector, x[3])
        model = self.loaded.with_parameters(x[0], x[1], x[2], bias, delay)
        return model.run(self.robot, self.data, *self.rows, self.horizon) - self.data.q[self.rows[0]:self.rows[1]]


def delay_grid(loaded: ReplayModel) -> np.ndarray:
    """The delays the refinement may choose [s]: whole timesteps (MuJoCo's history holds one set-point a step, read
    with a zero-order hold: a delay acts as the whole steps it reaches, ``ceil(delay / h) h``), from zero to what the
    history holds; empty where the file has no delay to refine (no history, one shorter than a step, or PACE's torque
    delay replayed)."""
    step = float(loaded.model.opt.timestep)
    if loaded.longest_delay <= 0 or loaded.replay.torque_delay is not None:
        return np.empty(0)
    grid = step * np.arange(int(np.floor(loaded.longest_delay / step + 1e-9)) + 1)
    return grid if grid.size > 1 else np.empty(0)


def refine_mjcf(model: str | Path, robot: Robot, log: pa.Table | str | Path | LogSetpoints, replay: Replay = Replay(),
                *, times: tuple[float, float] | None = None) -> Refinement:
    """Refine an exported MJCF's armature, friction, drive constant and delay on its replay's error (module
    docstring).

    Args:
        model: the MJCF (``wbfriction export``): its PD-driven joints' actuators named as the joints.
        robot: the robot it was exported for (its TOML, a fixed base): the encoder offsets.
        log: the training log (a table, a file, or its :func:`~wbfriction.replay.rollout.read_log_setpoints`).
        replay: how the file is replayed (:class:`~wbfriction.replay.mjcf.Replay`: its windows' ``horizon``, the
            timestep, PACE's torque delay); ``horizon=None``: one shot.
        times: the training stretch ``[t0, t1)`` [s]; None: the whole log.

    Returns:
        :class:`Refinement`; :func:`write_refined` writes it into the file.

    Raises:
        what :func:`~wbfriction.replay.mjcf.replay_mjcf` raises (a stretch of less than two samples among them;
        ReplayInfeasible: a replay that cannot replay the log, :mod:`wbfriction.replay.feasibility`), before any
        replay.
    """
    began = clock.perf_counter()
    data = log if isinstance(log, LogSetpoints) else read_log_setpoints(robot, log)
    loaded, rows = checked_replay(model, robot, data, replay, times=times)  # feasible, before any replay
    problem = _Problem(loaded, robot, data, rows, replay.horizon)
    grid = delay_grid(loaded)
    x0, d0 = file_parameters(loaded, robot), loaded.delay
    rms0 = np.sqrt(np.mean(problem.error(x0, None) ** 2, axis=0))
    weight = _weights(rms0)
    if grid.size:
        solutions = _profile(problem, x0, grid, weight)
        best = min(solutions, key=lambda k: solutions[k].cost)
        x, delay, replays = solutions[best].x, float(grid[best]), 1 + sum(s.replays for s in solutions.values())
    else:
        x, delay, replays = x0, None, 1
    sol = _least_squares(problem, x, delay, _weights(np.sqrt(np.mean(problem.error(x, delay) ** 2, axis=0))))
    return _refinement(problem, x0, d0, sol, delay, rms0, grid, replays + 1 + sol.replays,
                       clock.perf_counter() - began)


def _weights(rms: np.ndarray) -> np.ndarray:
    """Each joint's weight (n,): one over its tracking error's RMS [1/rad], so that every joint's weighted error has
    a unit variance (what :func:`~wbfriction.actuator.solve.sandwich`'s least-squares covariance assumes); a joint
    that tracks exactly weighs as the best of the others."""
    good = rms[rms > 0]
    return 1.0 / np.where(rms > 0, rms, good.min() if good.size else 1.0)


def _profile(problem: _Problem, x0: np.ndarray, grid: np.ndarray, weight: np.ndarray) -> dict[int, _Solution]:
    """The values refined at the delays of ``grid`` a pattern search visits (module docstring): from the file's
    delay, steps of a log period in whole timesteps, then halved down to one timestep, each refinement started from
    the nearest delay's; the refined solutions by grid index."""
    step = float(problem.loaded.model.opt.timestep)
    solutions: dict[int, _Solution] = {}

    def cost(k: int) -> float:
        if k not in solutions:
            near = min(solutions, key=lambda j: abs(j - k), default=None)
            start = x0 if near is None else solutions[near].x
            solutions[k] = _least_squares(problem, start, float(grid[k]), weight)
        return solutions[k].cost

    k = min(int(np.ceil(problem.loaded.delay / step - 1e-6)), grid.size - 1)  # the file's delay, as it acts
    stride = max(1, int(round(problem.period / step)))
    while stride >= 1:
        moved = True
        while moved:
            moved = False
            for c in (k - stride, k + stride):
                if 0 <= c < grid.size and cost(c) < cost(k):
                    k, moved = c, True
                    break
        stride //= 2
    return solutions


@dataclass(frozen=True)
class _Solution:
    x: np.ndarray
    weight: np.ndarray
    fun: np.ndarray
    jac: np.ndarray
    at_floor: np.ndarray
    replays: int
    converged: bool

    @property
    def cost(self) -> float:
        """The weighted errors' sum of squares."""
        return float(np.sum(self.fun**2))


def _least_squares(problem: _Problem, x: np.ndarray, delay: float | None, weight: np.ndarray) -> _Solution:
    """SciPy's least squares of the weighted errors over the values, from ``x`` at ``delay`` [s] (None: the
    file's) (module docstring)."""
    from scipy.optimize import least_squares

    n = problem.robot.n_act
    scale = _scales(x)
    top = branches(problem.loaded)
    same = top[:, None] == top[None, :]
    sparsity = np.tile(np.tile(same, (1, 4)), (problem.rows[1] - problem.rows[0], 1))
    columns = 4 * int(same.sum(axis=1).max())

    def residual(z: np.ndarray) -> np.ndarray:
        return (problem.error(z.reshape(4, n) * scale, delay) * weight).ravel()

    lower = np.concatenate([np.zeros(3 * n), np.full(n, -np.inf)])
    sol = least_squares(residual, (x / scale).ravel(), jac_sparsity=sparsity, bounds=(lower, np.inf), method="trf",
                        diff_step=1e-3, max_nfev=max(2, MAX_REPLAYS // (1 + columns)))
    jac = sol.jac.toarray() if hasattr(sol.jac, "toarray") else np.asarray(sol.jac)
    at_floor = sol.active_mask.reshape(4, n) < 0
    x = np.where(at_floor, 0.0, sol.x.reshape(4, n) * scale)  # on its floor: zero, not SciPy's 1e-10 inside it
    return _Solution(x, weight, sol.fun, jac / scale.ravel()[None, :], at_floor, int(sol.nfev + sol.njev * columns),
                     sol.status > 0)


def _refinement(problem: _Problem, x0: np.ndarray, d0: float, sol: _Solution, delay: float | None,
                rms0: np.ndarray, grid: np.ndarray, replays: int, seconds: float) -> Refinement:
    """The refinement's values, their standard errors (the delay's column by central differences of one timestep
    beside the values' Jacobian, in one sandwich of the windows: module docstring) and statuses."""
    start, stop = problem.rows
    n = problem.robot.n_act
    jac, x = sol.jac, sol.x
    if delay is not None:
        step = float(problem.loaded.model.opt.timestep)
        low, high = max(delay - step, float(grid[0])), min(delay + step, float(grid[-1]))  # within the history
        column = (problem.error(x, high) - problem.error(x, low)) * sol.weight
        jac = np.hstack([jac, (column.ravel() / (high - low))[:, None]])
        replays += 2
    shot = stop - start if problem.horizon is None else max(1, int(round(problem.horizon / problem.period)))
    window = np.arange(stop - start) // shot  # each row's window: one rollout restarted from the log
    bound = np.sqrt(np.diag(sandwich(jac, sol.fun, np.repeat(window, n), lags=0)))  # inf: not determined
    scale = window_scale(int(window[-1]) + 1)
    se = np.hypot(scale * bound[:4 * n], _remaining(sol)).reshape(4, n)
    delay_se = float(scale * bound[-1]) if delay is not None else float("nan")
    rms = np.sqrt(np.mean((sol.fun.reshape(stop - start, n) / sol.weight) ** 2, axis=0))
    under = ""
    if delay is None:
        delay, delay_status = d0, "not refined"
    else:
        delay_status = identified_delay_status(delay, delay_se, float(grid[-1]), problem.period, float(bound[-1]))[0]
        under = fitted_under(Identified(delay, delay_se, float(bound[-1]), delay_status), float(grid[-1]),
                             "the longest the file's actuator history holds, its nsample")
    motion = stretch_motion(problem.data.time[start:stop], problem.data.q[start:stop])
    judged = [[judged_value(kind, x[k, j], se[k, j], bound[k * n + j], sol.at_floor[k, j], x[1, j], motion[j], under)
               for j in range(n)] for k, kind in enumerate(PARAMETERS)]
    return Refinement(problem.robot.actuated, x0, x, se, tuple(tuple(p.status for p in row) for row in judged), rms0,
                      rms, (start, stop), replays, seconds, sol.converged, d0, delay, delay_se, delay_status,
                      tuple(tuple(p.reason for p in row) for row in judged))


def window_scale(windows: int) -> float:
    """The factor on a sandwich's standard errors from ``windows`` independent windows (module docstring):
    ``sqrt(G / (G - 1))`` (its scores sum to zero at the optimum: ``G - 1`` degrees of freedom) times ``t_{G-1}``'s
    97.5 % quantile over the normal's (:func:`~wbfriction.fit.block_spread.t_scale`), inf below two windows (no
    variance to estimate)."""
    if windows < 2:
        return float("inf")
    return float(np.sqrt(windows / (windows - 1)) * t_scale(windows))


def _remaining(sol: _Solution) -> np.ndarray:
    """How far each value (4 n,) would still move [its unit]: the Gauss-Newton step from where the solve stopped
    (the values off their floor), zero where it converged; what a solve stopped by its budget
    (:data:`MAX_REPLAYS`) leaves undetermined."""
    free = ~sol.at_floor.ravel()
    step = np.zeros(sol.jac.shape[1])
    if free.any():
        step[free] = np.linalg.lstsq(sol.jac[:, free], sol.fun, rcond=None)[0]
    return np.abs(step)


def judged_value(kind: str, value: float, se: float, bound: float, at_floor: bool, f_c: float,
                 motion: JointMotion, under: str) -> Identified:
    """One refined value's status by ``identify --actuator pd``'s rule
    (:func:`~wbfriction.actuator.identification.parameter_status`, then
    :func:`~wbfriction.actuator.identification.judged`): its standard error ``se`` and ``bound`` (the sandwich's,
    inf where the replay does not depend on it), its floor of zero, ``tau_os`` against the larger of it and the
    joint's ``f_c`` [N·m], what the joint's ``motion`` over the stretch does not excite, a delay at its bound
    (``under``)."""
    reference = max(abs(value), f_c) if kind == "tau_os" else None
    status, reason = parameter_status(kind, float(value), float(se), float(bound), bool(at_floor), reference)
    return judged(Identified(float(value), float(se), float(bound), status, reason), kind, motion, under)


def _scales(x0: np.ndarray) -> np.ndarray:
    """Each value's unit in the search (4, n): its kind's mean magnitude over the joints (``tau_os``'s: F_c's), so
    that SciPy's relative finite-difference step is a like share of every value."""
    kind = np.abs(x0).mean(axis=1)
    kind[3] = max(kind[3], kind[1])
    kind = np.where(kind > 0, kind, 1.0)
    return np.repeat(kind[:, None], x0.shape[1], axis=1)


def write_refined(model: str | Path, refinement: Refinement, robot: Robot, output: str | Path,
                  timestep: float | None = None) -> None:
    """``model`` (the MJCF refined) with the refined values written into its joints and actuators (and the
    ``timestep`` [s] refined at, where given, into its ``<option>``), and comments saying so and naming every value
    that is not ``ok`` (:func:`not_ok_lines`: written as refined, not as if the data determined it), to ``output``
    (whole or not at all); ``model`` itself is not touched.

    Raises:
        InputError: a file without the joints or actuators refined, an output that cannot be written.
    """
    from lxml import etree

    from wbfriction.logs.tables import write_atomic

    try:
        tree = etree.parse(str(model))
    except (OSError, etree.XMLSyntaxError) as err:
        raise InputError(f"{model}: cannot read it as XML: {err}") from None
    root = tree.getroot()
    for j, joint in enumerate(refinement.joints):
        found = root.findall(f".//joint[@name='{joint}']")
        acts = [a for a in root.find("actuator") if a.get("name") == joint] if root.find("actuator") is not None \
            else []
        if len(found) != 1 or len(acts) != 1:
            raise InputError(f"{model}: no single joint and actuator named '{joint}' to write the refinement into")
        armature, frictionloss, damping, tau_os = refinement.value[:, j]
        for name, value in (("armature", armature), ("frictionloss", frictionloss), ("damping", damping)):
            found[0].set(name, repr(float(value)))
        bias = acts[0].get("biasprm", "0 0 0").split()
        gain = -float(bias[1]) if len(bias) > 1 else 0.0  # biasprm[1] = -kp
        bias[0] = repr(float(actuator_bias(gain, robot.encoder_offset.get(joint, 0.0), tau_os)))
        acts[0].set("biasprm", " ".join(bias))
        if refinement.delay_status != "not refined":
            acts[0].set("delay", repr(max(refinement.delay - HOLD_EDGE, 0.0)))
    if timestep is not None:
        option = root.find("option")
        if option is None:
            option = etree.Element("option")
            root.insert(0, option)
        option.set("timestep", repr(timestep))
    header = ("refined by wbfriction refine on rows {} to {} of its training log: armature, frictionloss, damping, "
              "biasprm[0] (the drive's constant torque tau_os) and delay of {} joints; the export's notes below give "
              "the values before".format(*refinement.rows, len(refinement.joints)))
    for line in reversed([header, *not_ok_lines(refinement)]):
        comment = etree.Comment(f" {line} ")
        comment.tail = "\n  "
        root.insert(0, comment)
    text = etree.tostring(tree, encoding="unicode")
    write_atomic(output, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def not_ok_lines(refinement: Refinement) -> list[str]:
    """One line per refined value whose status is not ``ok``: ``"<joint> <value> <v> ± <se> <unit>: <status>
    (<reason>)"``, in the robot's order, then the delay's (``not refined`` is no finding against it, and has none)."""
    why = refinement.reason or tuple(("",) * len(refinement.joints) for _ in PARAMETERS)
    lines = [f"{joint} {name} {refinement.value[k, j]:.4g} ± {refinement.stderr[k, j]:.2g} {UNITS[name]}: "
             f"{refinement.status[k][j]}" + (f" ({why[k][j]})" if why[k][j] else "")
             for j, joint in enumerate(refinement.joints) for k, name in enumerate(PARAMETERS)
             if refinement.status[k][j] != "ok"]
    if refinement.delay_status not in ("ok", "not refined"):
        lines.append(f"delay {refinement.delay:.4g} ± {refinement.delay_se:.2g} s: {refinement.delay_status}")
    return lines
