"""Files in, files out: an exported MJCF replayed under a log's set-points (:func:`~wbfriction.sim.replay.replay_mjcf`),
its tracking error per joint as a table and a figure."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import pyarrow as pa

from wbfriction.logs.tables import write_table
from wbfriction.model.robot import Robot
from wbfriction.sim.replay import Replay, replay_mjcf
from wbfriction.sim.rollout import RolloutResult, read_log_setpoints


@dataclass(frozen=True)
class ReplayCheck:
    """A file replayed two ways over one stretch: restarted from the log every ``horizon`` seconds (``windows``) and
    in one shot (``whole``), each a :class:`~wbfriction.sim.rollout.RolloutResult`."""

    windows: RolloutResult
    whole: RolloutResult

    def table(self) -> pa.Table:
        """A row per joint: ``joint``, ``rms_windows`` and ``rms_whole`` [rad]."""
        return pa.table({"joint": list(self.windows.joints), "rms_windows": self.windows.rms,
                         "rms_whole": self.whole.rms})


def replay_file(robot: Robot, log: str | Path, model: str | Path, replay: Replay, *,
                times: tuple[float, float] | None = None, output: str | Path | None = None,
                figure: str | Path | None = None) -> ReplayCheck:
    """Replay ``model`` (an MJCF ``wbfriction export`` wrote for ``robot``) under the set-points of ``log`` over
    ``times`` ([t0, t1) [s]; None: the whole log), in windows of ``replay.horizon`` and in one shot; write the table
    (:meth:`ReplayCheck.table`, Parquet) to ``output`` and the windows' figure
    (:func:`~wbfriction.report.figures.rollout_figure`) to ``figure`` where given, each whole or not at all.

    Raises:
        what :func:`~wbfriction.sim.replay.replay_mjcf` raises; InputError: an output that cannot be written.
    """
    data = read_log_setpoints(robot, log)
    windows = replay_mjcf(model, robot, data, replay, times=times)
    whole = replay_mjcf(model, robot, data, replace(replay, horizon=None), times=times)
    check = ReplayCheck(windows, whole)
    if output is not None:
        write_table(check.table(), output)
    if figure is not None:
        from wbfriction.report.figures import rollout_figure
        rollout_figure([windows], figure)
    return check
