"""Whether a replay can replay what it scores (issue 81, class 2): one check, run before any replay work, by
``wbfriction rollout`` (:func:`~wbfriction.replay.mjcf.replay_mjcf`), ``wbfriction refine``
(:func:`~wbfriction.replay.refine.refine_mjcf`) and :func:`~wbfriction.replay.rollout.rollout`.

A replay sends a log's set-points, one a log period ``P`` (the median of the time's steps), to a simulator and
reads the simulated angles at the log's samples (:mod:`wbfriction.replay.mjcf`). What it scores is that replay only
where the following hold; each limit follows from how the replay runs, none is tuned:

* **the timestep against the actuators' history** (the file's actuators, not PACE's): MuJoCo 4 delays an
  actuator's control by reading its history of ``nsample`` controls, one a timestep ``h``, at ``delay`` back with a
  zero-order hold; the sample it needs is ``ceil(delay / h)`` steps back, and where that is more than ``nsample``
  it reads the oldest, silently: a shorter delay (measured on MuJoCo 4.0.0 over random ``h``, ``delay``,
  ``nsample``: exact if and only if ``ceil(delay / h) <= nsample``; ``tests/replay/test_feasibility.py``). So
  ``h >= delay / nsample`` (:func:`check_history`), the bound the export's note prints;
* **the timestep against the log period**: a set-point is held from its sample to the next, applied from the first
  physics step at or after its time; with ``h <= P`` every set-point is applied for a step at least and every sample
  read within a step of its time; a longer step skips set-points and reads one state for several samples
  (:func:`check_timestep`);
* **the window against the log period**: a window restarts from the log's state (its first sample is the log's)
  every ``round(window / P)`` samples; a window of fewer than two samples simulates nothing and scores every model
  zero (:func:`check_window`);
* **PACE's torque delay against the window**: its torque is computed once a period and applied ``D`` periods later,
  the window's first torque standing in before; a delay as long as the window (``D >= samples - 1``) applies only
  that stand-in (:func:`check_torque_delay`);
* **the log's runs**: the replay takes each row as sent one period after the one before; a row whose step from
  the one before does not round to one period (``|t_k - t_(k-1) - P| >= P / 2``: a gap, samples missing; a time
  that repeats or goes back) starts a new run (:func:`log_runs`). The rule is the row's own step, not a grid from
  the log's start: a slow drift of the clock, or times stored in float32 (a quantised step, its median a little off
  its mean), never adds up to a gap, and a sample's jitter passes while it stays within half a period of the one
  before's. Runs are replayed separately: every window restarts at a run's first row, the history before it is that
  row's set-point (as before a log's first row), no window crosses a gap (:func:`run_windows`). A stretch without
  a run of two rows has nothing to replay;
* **the file's robot against the TOML's** (:func:`check_robot`): ``wbfriction export`` writes the robot's model
  name (its URDF's ``<robot name>``, an MJCF's ``<mujoco model>``) as the file's ``<mujoco model>`` and exactly the
  robot's joints (:attr:`Robot.actuated`); a file of another name or other joints is another robot's (the Go2, the
  A1 and the Aliengo share their joints' names). The encoder offsets sit in the actuators' bias with the fits'
  constant, ``biasprm[0] = -kp offset - tau_os``, from which the offset cannot be told apart; the export lists them
  exactly in its note at the top of ``<actuator>`` (``"joint": rad``, :func:`~wbfriction.export.drive.offset_lines`),
  and the replay takes the log's angles to the model's with the TOML's: the two must be equal, bit for bit (a file
  whose comments were stripped has no such record, and its offsets are not checked).

Each refusal is a :class:`ReplayInfeasible`, one line naming the file, the option or key and the limit.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.model.robot import Robot

DRIVE_NOTE = "PD drivers (wbfriction)"
"""How the export's note at the top of ``<actuator>`` begins (:func:`~wbfriction.export.mjcf.drive_note`)."""
OFFSETS_HEADER = "encoder offsets [rad]"
"""How its list of encoder offsets begins, one ``"joint": rad`` line each after it."""


class ReplayInfeasible(InputError):
    """A replay that would score what it cannot replay (module docstring), refused before any replay.

    Attributes:
        source: the file at fault (the MJCF, the log) as given.
        option: what is at fault, as the command line or the file spells it: ``--timestep``, ``--window``,
            ``--torque-delay``, ``<mujoco model>``, ``[encoder_offset]``, ``time``.
        value: the value given (a number, a name).
        limit: what it must be, e.g. ``a timestep >= 0.00048 s``.
        problem: the message after ``source: ``.
    """

    def __init__(self, source: str, option: str, value: object, limit: str, problem: str):
        self.source, self.option, self.value, self.limit, self.problem = source, option, value, limit, problem
        super().__init__(f"{source}: {problem}")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.source, self.option, self.value, self.limit, self.problem))


def log_period(time: np.ndarray, source: str = "<table>") -> float:
    """The log's sample period [s]: the median of its time's steps (what every replay steps the set-points by).

    Raises:
        ReplayInfeasible: a median step that is not > 0 (no period to replay at), or fewer than two rows.
    """
    period = float(np.median(np.diff(time))) if len(time) > 1 else math.nan
    if not (math.isfinite(period) and period > 0):
        raise ReplayInfeasible(source, "time", period, "a period > 0 [s]",
                               f"the log's time has no period to replay at (its median step {period!r} s)")
    return period


def log_runs(time: np.ndarray, source: str = "<table>") -> tuple[tuple[int, int], ...]:
    """The log's evenly sampled runs, rows ``[a, b)`` each, in order, covering every row (module docstring): row
    ``k`` is in the run of row ``k - 1`` while ``|t_k - t_(k-1) - P| < P / 2``.

    Raises:
        ReplayInfeasible: a time without a period (:func:`log_period`).
    """
    period = log_period(time, source)
    cuts = (np.flatnonzero(~(np.abs(np.diff(time) - period) < 0.5 * period)) + 1).tolist()
    return tuple(zip([0, *cuts], [*cuts, len(time)]))


def run_windows(runs: Sequence[tuple[int, int]], start: int, stop: int, shot: int) -> list[tuple[int, int]]:
    """The windows ``[first, last)`` of a replay of rows ``[start, stop)`` restarted every ``shot`` rows and at each
    run's first row: no window crosses two runs. One run: ``range(start, stop, shot)``'s windows."""
    out = []
    for a, b in runs:
        lo, hi = max(a, start), min(b, stop)
        out += [(first, min(first + shot, hi)) for first in range(lo, hi, shot)]
    return out


def stretch_runs(runs: Sequence[tuple[int, int]], rows: tuple[int, int]) -> tuple[tuple[int, int], ...]:
    """The runs within rows ``[start, stop)``, cut to them."""
    return tuple((max(a, rows[0]), min(b, rows[1])) for a, b in runs if a < rows[1] and b > rows[0])


def window_rows(horizon: float | None, period: float, rows: tuple[int, int]) -> int:
    """The samples of a window (a shot) of ``horizon`` seconds (None: the stretch) at the log ``period`` [s]:
    ``horizon / period`` rounded half up (at least one), a half within rounding of the period (a period read as the
    median of stamps, ``0.0050000000000000044`` for 5 ms) counted as a half, and no more than the stretch's."""
    length = rows[1] - rows[0]
    return length if horizon is None else min(length, max(1, math.floor(horizon / period + 0.5 + 1e-9)))


def check_window(source: str, horizon: float | None, period: float, rows: tuple[int, int]) -> None:
    """Refuse a window of fewer than two of the log's samples (module docstring).

    Raises:
        ReplayInfeasible: naming ``--window``, the window's samples and the least window that holds two.
    """
    if window_rows(horizon, period, rows) >= 2 or horizon is None:
        return
    raise ReplayInfeasible(source, "--window", horizon, f"a window >= {1.5 * period:g} s",
                           f"a window (--window) of {horizon:g} s holds {max(1, round(horizon / period))} of the log's "
                           f"samples of {period:g} s: it would restart from the log at every row and simulate nothing "
                           f"(every model 0); give one of {1.5 * period:g} s (two samples) or more")


def check_timestep(source: str, timestep: float, period: float, log: str = "the log") -> None:
    """Refuse a physics step of the file ``source`` longer than the period of ``log`` (module docstring).

    Raises:
        ReplayInfeasible: naming ``--timestep``, the step, the log and its period.
    """
    if timestep <= period * (1.0 + 1e-9):
        return
    raise ReplayInfeasible(source, "--timestep", timestep, f"a timestep <= {period:g} s",
                           f"a timestep (--timestep; the file's by default) of {timestep:g} s is longer than {log}'s "
                           f"period {period:g} s: its set-points would be skipped and its samples read late; give at "
                           f"most {period:g} s")


def check_history(source: str, model: Any, acts: np.ndarray, names: Sequence[str]) -> None:
    """Refuse a timestep at which an actuator's history does not reach its delay (module docstring): ``delay >
    nsample h`` for a delayed actuator of ``acts`` (indices into the compiled MuJoCo ``model``), ``names`` theirs.

    Raises:
        ReplayInfeasible: naming ``--timestep``, the actuator, its ``nsample`` and delay, and the least timestep.
    """
    h = float(model.opt.timestep)
    for act, name in zip(acts, names):
        delay, samples = float(model.actuator_delay[act]), int(model.actuator_history[act, 0])
        if delay <= 0 or delay <= samples * h:
            continue
        least = delay / samples if samples else math.inf
        held = f"a delay of {delay:.6g} s at timesteps >= {least:.6g} s" if samples else "no delay (nsample 0)"
        raise ReplayInfeasible(source, "--timestep", h, f"a timestep >= {least:.6g} s",
                               f"actuator '{name}' holds {samples} set-points ({held}); at a timestep (--timestep) of "
                               f"{h:g} s it would read its oldest, a delay of {samples * h:.6g} s instead: give a "
                               f"timestep of {least:.6g} s or more, or export again with a longer history")


def check_torque_delay(source: str, delay: float, period: float, samples: int) -> None:
    """Refuse PACE's torque delay of ``delay`` periods as long as a window of ``samples`` (module docstring).

    Raises:
        ReplayInfeasible: naming ``--torque-delay``, the window's samples and the longest delay it replays.
    """
    if delay < samples - 1:
        return
    raise ReplayInfeasible(source, "--torque-delay", delay, f"at most {samples - 2} periods",
                           f"a torque delay (--torque-delay) of {delay:g} periods ({delay * period:g} s) is as long "
                           f"as a window of {samples} samples: every torque would be applied after its window ends; "
                           f"give at most {samples - 2} periods, or a longer --window")


def check_runs(source: str, runs: Sequence[tuple[int, int]], rows: tuple[int, int]) -> None:
    """Refuse a stretch none of whose runs holds two of its rows (nothing to replay between the gaps).

    Raises:
        ReplayInfeasible: naming the log's ``time`` and the stretch.
    """
    if any(min(b, rows[1]) - max(a, rows[0]) >= 2 for a, b in runs):
        return
    raise ReplayInfeasible(source, "time", rows, "two rows a period apart",
                           f"rows {rows[0]} to {rows[1]} hold no two rows a log period apart (their times are gaps "
                           f"all): nothing to replay")


def model_name(model: Any) -> str:
    """A compiled MuJoCo model's name, its ``<mujoco model>``."""
    return bytes(model.names).split(b"\0", 1)[0].decode()


def exported_offsets(path: str | Path) -> dict[str, float] | None:
    """The encoder offsets [rad] ``wbfriction export`` recorded in an MJCF (its note at the top of ``<actuator>``),
    by joint, every PD-driven joint without a line at 0 (the export lists every offset the robot gives); None where the
    file holds no such note (not an export, or its comments stripped)."""
    from lxml import etree

    try:
        root = etree.parse(str(path)).getroot()
    except (OSError, etree.XMLSyntaxError):
        return None
    for comment in root.iter(etree.Comment):
        lines = (comment.text or "").splitlines()
        if not lines or DRIVE_NOTE not in lines[0]:
            continue
        listed = [k for k, line in enumerate(lines) if line.strip().startswith(OFFSETS_HEADER)]
        out: dict[str, float] = {}
        for line in lines[listed[0] + 1:] if listed else []:
            name, _, value = line.strip().rpartition(": ")
            try:
                out[json.loads(name)] = float(value)
            except ValueError:  # the note's end (json's errors are ValueErrors)
                break
        return out
    return None


def check_robot(source: str, model: Any, robot: Robot) -> None:
    """Refuse a file exported for another robot, or with other encoder offsets than the robot TOML's (module
    docstring): ``model`` the compiled MJCF of ``source``.

    Raises:
        ReplayInfeasible: naming ``<mujoco model>`` and both robots; a joint the robot lacks; ``[encoder_offset]``,
            the joint and both offsets.
    """
    import mujoco

    ours, theirs = robot.model.name, model_name(model)
    if ours and theirs != ours:
        raise ReplayInfeasible(source, "<mujoco model>", theirs, f"'{ours}'",
                               f"a model of '{theirs}' (its <mujoco model>), not of robot '{robot.name}' (its model "
                               f"'{ours}'): replay it with the TOML it was exported for, or export for {robot.name}")
    joints = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)
              if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE]
    extra = [j for j in joints if j not in robot.actuated]
    if extra:
        raise ReplayInfeasible(source, "<joint>", extra[0], f"the joints of {robot.name}",
                               f"joint '{extra[0]}' is not one of robot '{robot.name}''s: another robot's model")
    recorded = exported_offsets(source)
    if recorded is None:
        return
    for joint in robot.actuated:
        given, held = float(robot.encoder_offset.get(joint, 0.0)), recorded.get(joint, 0.0)
        if given != held:
            raise ReplayInfeasible(source, "[encoder_offset]", given, f"{held!r} rad",
                                   f"exported with encoder offset {held!r} rad for '{joint}' (in its actuator's bias), "
                                   f"the robot TOML of {robot.name} gives {given!r}: replay it with the TOML it was "
                                   f"exported with, or export again")
