"""A simulated fleet whose friction drifts where it is told to (issue 25): ``wbfriction study-fleet``.

:func:`simulate_fleet` walks each robot of a :class:`FleetPlan` once per log (short walks of the ideal simulator,
a log a day, the studies' sensor noise with its own seed per log), with the thesis's Table 6.1 friction on the
legs, constant except where a :class:`Drift` makes one parameter of one joint grow linearly over a robot's last
logs. It writes the logs and a manifest (:mod:`wbfriction.fleet.manifest`). :func:`score_flags` compares the
joints a trend detector flags with the drifts: found, missed, false alarms, onset errors in logs.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Literal

from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.models import FrictionParams
from wbfriction.logs.log import write_log
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress
from wbfriction.sim import simulate_ideal
from wbfriction.sim.options import SensorNoise
from wbfriction.sim.sensors import apply_sensor_noise
from wbfriction.studies.common import SIMULATOR
from wbfriction.studies.realistic import NOISE
from wbfriction.walking import walking_reference
from wbfriction.walking.options import GaitOptions

DriftedParameter = Literal["F_c", "F_v"]
"""The parameters a drift changes."""


@dataclass(frozen=True)
class Drift:
    """A parameter of one robot's joint growing linearly over the robot's last logs.

    Attributes:
        robot_id, joint: where.
        parameter: ``F_c`` or ``F_v``.
        change: relative change reached at the last log (0.30: +30 %).
        logs: the last ``logs`` logs drift: the first of them (the onset) is ``change / logs`` above the
            constant value, the last ``change`` above.
    """

    robot_id: str
    joint: str
    parameter: DriftedParameter
    change: float
    logs: int

    def onset(self, n_logs: int) -> int:
        """The index of the first drifted log of a robot with ``n_logs`` logs."""
        return n_logs - self.logs

    def factor(self, index: int, n_logs: int) -> float:
        """The parameter's factor at log ``index`` (1 before the onset)."""
        k = index - self.onset(n_logs) + 1
        return 1.0 + self.change * max(0, k) / self.logs


@dataclass(frozen=True)
class FleetPlan:
    """A simulated fleet (module docstring); the defaults are issue 25's: 4 robots x 25 logs, the right knee's
    F_c +30 % over robot-1's last 10 logs, the left ankle pitch's F_v +50 % over robot-2's last 8 (on one
    4-step walk with the sensor noise, their fits' standard errors are 1.2-1.8 % of F_c and 0.9-1.1 % of F_v).

    Attributes:
        robots: how many (ids ``robot-0``, ``robot-1``, ...); logs: logs per robot.
        drifts: the drifts; everything else stays constant.
        gait: each log's walk.
        noise: the sensors' noise (its seed is replaced per log).
        start: the first log's start time; spacing: between a robot's logs.
        seed: the noise seeds' base.
    """

    robots: int = 4
    logs: int = 25
    drifts: tuple[Drift, ...] = (Drift("robot-1", "leg_right_4_joint", "F_c", 0.30, 10),
                                 Drift("robot-2", "leg_left_5_joint", "F_v", 0.50, 8))
    gait: GaitOptions = GaitOptions(gait="forward", steps=4)
    noise: SensorNoise = NOISE
    start: datetime = datetime(2026, 1, 5, 8, 0, tzinfo=UTC)
    spacing: timedelta = timedelta(days=1)
    seed: int = 0

    @property
    def robot_ids(self) -> list[str]:
        return [f"robot-{r}" for r in range(self.robots)]


@dataclass(frozen=True)
class FleetSimulation:
    """What :func:`simulate_fleet` wrote: the manifest, and per robot the logs in time order."""

    manifest: Path
    logs: dict[str, list[Path]]
    plan: FleetPlan


def friction_of(robot: Robot, plan: FleetPlan, robot_id: str, index: int) -> dict[str, FrictionParams]:
    """The friction injected in log ``index`` of ``robot_id``: Table 6.1's by leg joint group, drifts applied."""
    friction = {j: THESIS_TARGETS[g] for g, joints in robot.groups.items() if g in THESIS_TARGETS for j in joints}
    for d in plan.drifts:
        if d.robot_id == robot_id:
            p = friction[d.joint]
            friction[d.joint] = dataclasses.replace(p, **{d.parameter: getattr(p, d.parameter)
                                                          * d.factor(index, plan.logs)})
    return friction


def simulate_fleet(robot: Robot, output_dir: Path, plan: FleetPlan = FleetPlan(),
                   progress: StageProgress | None = None) -> FleetSimulation:
    """Simulate every log of ``plan`` into ``output_dir/logs/<robot_id>/<index>.parquet`` and write
    ``output_dir/manifest.csv`` (module docstring). The same plan gives the same bytes.

    Raises:
        SimulationError: a walk that fell.
    """
    say = progress or (lambda label: None)
    reference = walking_reference(robot, plan.gait)
    lines = ["log,robot_id,start_time,robot"]
    logs: dict[str, list[Path]] = {}
    for r, robot_id in enumerate(plan.robot_ids):
        folder = output_dir / "logs" / robot_id
        folder.mkdir(parents=True, exist_ok=True)
        logs[robot_id] = []
        for i in range(plan.logs):
            say(f"simulate {robot_id}, log {i + 1} of {plan.logs}")
            log = simulate_ideal(robot, reference, friction_of(robot, plan, robot_id, i), SIMULATOR).log
            noise = dataclasses.replace(plan.noise, seed=plan.seed + 1000 * r + i)
            path = folder / f"{i:03d}.parquet"
            write_log(apply_sensor_noise(log, noise) if noise.active else log, robot, path)
            logs[robot_id].append(path)
            start = plan.start + i * plan.spacing + r * timedelta(minutes=30)
            lines.append(f"{path.relative_to(output_dir)},{robot_id},{start.isoformat()},{robot.name}")
    manifest = output_dir / "manifest.csv"
    manifest.write_text("\n".join(lines) + "\n")
    return FleetSimulation(manifest, logs, plan)


def simulate_arm_fleet(folder: Path, robots: int = 2, logs: int = 12, seconds: float = 3.0,
                       drifts: tuple[Drift, ...] = (), start: datetime = datetime(2026, 1, 5, 8, tzinfo=UTC),
                       spacing: timedelta = timedelta(days=1), progress: StageProgress | None = None) -> Path:
    """A small, fast fleet: ``robots`` simulated Panda arms (``arm-0``, ...) with ``wbfriction simulate``'s
    default arm friction, ``logs`` excitation runs of ``seconds`` each per arm (torque noise 0.01 N·m, seed
    ``100 r + i``), ``drifts`` applied; the logs and ``manifest.csv`` go into ``folder``; ``progress`` is
    called with a line after each log. Returns the manifest."""
    from wbfriction.logs.tables import write_table
    from wbfriction.model.loading import load_robot
    from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm

    robot = load_robot("panda")
    base = default_arm_friction(robot)
    lines = ["log,robot_id,start_time,robot"]
    for r in range(robots):
        for i in range(logs):
            friction = dict(base)
            for d in drifts:
                if d.robot_id == f"arm-{r}":
                    p = friction[d.joint]
                    friction[d.joint] = dataclasses.replace(p, **{d.parameter: getattr(p, d.parameter)
                                                                  * d.factor(i, logs)})
            sim = simulate_arm(robot, friction, options=ArmOptions(duration=seconds, seed=100 * r + i,
                                                                   torque_std=0.01))
            name = f"arm{r}_{i:02d}.parquet"
            write_table(sim.table, folder / name)
            lines.append(f"{name},arm-{r},{(start + i * spacing).isoformat()},panda")
            if progress is not None:
                progress(f"simulated arm-{r}'s log {i + 1} of {logs} ({r * logs + i + 1} of {robots * logs})")
    (folder / "manifest.csv").write_text("\n".join(lines) + "\n")
    return folder / "manifest.csv"


@dataclass(frozen=True)
class FleetScore:
    """Flagged joints against the drifts.

    Attributes:
        found: ``(robot_id, joint) -> onset error`` [logs] of each drift flagged.
        missed: drifts not flagged.
        false_alarms: flagged series with no drift; series: how many were tested.
    """

    found: dict[tuple[str, str], int]
    missed: list[tuple[str, str]]
    false_alarms: list[tuple[str, str]]
    series: int

    @property
    def exact(self) -> bool:
        """Every drift flagged, no other joint."""
        return not self.missed and not self.false_alarms


def score_flags(flagged: dict[tuple[str, str], int], plan: FleetPlan, series: int) -> FleetScore:
    """Score ``flagged`` (``(robot_id, joint) -> onset log index``) against ``plan``'s drifts, over ``series``
    tested robot-joint series."""
    truth = {(d.robot_id, d.joint): d.onset(plan.logs) for d in plan.drifts}
    found = {k: flagged[k] - onset for k, onset in truth.items() if k in flagged}
    return FleetScore(found, [k for k in truth if k not in flagged], sorted(k for k in flagged if k not in truth),
                      series)


@dataclass(frozen=True)
class FleetStudy:
    """What :func:`run_fleet_study` found: the score, the trends' flagged joints, where it wrote, and how long the
    simulation, the batch and the trends took [s]."""

    score: FleetScore
    flagged: list[tuple[str, str, str, int]]
    files: list[Path]
    seconds: dict[str, float]


def run_fleet_study(robot: Robot, output_dir: Path, plan: FleetPlan = FleetPlan(), workers: int = 2,
                    progress: StageProgress | None = None) -> FleetStudy:
    """Simulate the fleet (:func:`simulate_fleet`), process it with ``wbfriction batch`` on a local Dask cluster of
    ``workers`` processes, find the trends and score them against the drifts; the results, ``trends.html`` and
    ``trends.parquet`` go into ``output_dir``.

    Raises:
        SimulationError: a walk that fell.
    """
    import time

    from wbfriction.fleet.batch import run_batch
    from wbfriction.fleet.manifest import read_manifest
    from wbfriction.fleet.results import read_results
    from wbfriction.fleet.trends import fleet_trends
    from wbfriction.logs.tables import write_table
    from wbfriction.report.trends import write_trends_html

    say = progress or (lambda label: None)
    seconds = {}
    t = time.perf_counter()
    sim = simulate_fleet(robot, output_dir, plan, progress)
    seconds["simulate"] = time.perf_counter() - t
    say(f"batch: {plan.robots * plan.logs} logs on {workers} Dask workers")
    t = time.perf_counter()
    run_batch(read_manifest(sim.manifest), output_dir / "results", workers=workers)
    seconds["batch"] = time.perf_counter() - t
    say("trends")
    t = time.perf_counter()
    trends = fleet_trends(read_results(output_dir / "results").table)
    files = [output_dir / "trends.html", output_dir / "trends.parquet"]
    write_trends_html(trends, files[0], "Friction trends of a simulated fleet")
    write_table(trends.to_table(), files[1])
    seconds["trends"] = time.perf_counter() - t
    flagged = {(j.robot_id, j.joint): j.drifts[0].onset for j in trends.flagged}
    tested = sum(1 for j in trends.joints if j.tests)
    return FleetStudy(score_flags(flagged, plan, tested),
                      [(j.robot_id, j.joint, j.drifts[0].quantity, j.drifts[0].onset) for j in trends.flagged],
                      files, seconds)
