"""A fleet whose friction follows the joints' temperature and wears where it is told to (issue 40): do the trends
tell wear from temperature?

Bittencourt & Axelsson (IEEE/ASME Trans. Mechatronics 19(5), 2014; accelerated wear tests of an industrial robot
joint) found that temperature and load change friction more than wear does: a monitor that ignores them raises
false alarms, or misses wear. :func:`temperature_fleet` makes such a fleet at the friction estimate's level (the
simulators' terms are tested against ground truth elsewhere: :mod:`wbfriction.sim.arm`): per robot, joint and
log, a friction estimate ``tau_f = -f(qd; T) + noise`` of a Coulomb-viscous joint whose levels fall linearly with
the temperature ``T`` (:data:`K_TC`, :data:`K_TV`: the friction changes by tens of percent between the coldest and
the warmest log), the log's temperatures logged. The logs' temperatures follow a season (the ambient warming over
the fleet's days) and each log's duty (a random offset), and warm a little within each log. Some joints wear:
their Coulomb level grows by 15-30 % (a step or a ramp) from a random onset on.

Each log is fitted (:func:`~wbfriction.fit.joints.fit_estimate`) into the results' rows
(:func:`~wbfriction.fleet.task.result_rows`: each joint's values and the temperature they were measured at), and
the trends (:func:`~wbfriction.fleet.trends.fleet_trends`) run with the temperatures and without them
(:func:`score_temperature_fleet`).
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime, timedelta

import numpy as np
import pyarrow as pa

from wbfriction.fleet.options import Shape
from wbfriction.friction.models import CoulombViscousParams

K_TC = -0.008
"""The Coulomb level's change per °C, relative (-0.8 %/°C: 32 % over 40 °C; Bittencourt's decrease, linearised)."""
K_TV = -0.012
"""The viscous level's change per °C, relative (-1.2 %/°C)."""
T_REF = 35.0
"""The temperature the true levels are stated at [°C]."""


@dataclass(frozen=True)
class Wear:
    """A joint's Coulomb level growing from a log on.

    Attributes:
        robot_id, joint: where; shape: ``step`` (all at once) or ``hinge`` (a ramp to the last log);
        onset: the first worn log; size: the relative change reached at the last log (0.2: +20 %).
    """

    robot_id: str
    joint: str
    shape: Shape
    onset: int
    size: float

    def factor(self, index: int, logs: int) -> float:
        """The Coulomb level's factor at log ``index`` of ``logs``."""
        if index < self.onset:
            return 1.0
        if self.shape == "step":
            return 1.0 + self.size
        return 1.0 + self.size * (index - self.onset + 1) / (logs - self.onset)


@dataclass(frozen=True)
class TemperatureFleet:
    """The fleet's plan (module docstring).

    Attributes:
        robots, logs, joints: how many (ids ``robot-<r>``, joints ``j<k>``).
        worn: how many joints wear over the fleet (chosen at random, sizes 15-30 %, onsets at random with
            :attr:`margin` logs before and after).
        season: the ambient temperature's rise over the fleet's days [°C]; duty: each log's random offset, uniform
            in ``±duty`` [°C]; warm_up: the rise within a log [°C]; ambient: the first day's [°C].
        seconds, rate: each log's friction samples; noise: the estimate's torque noise [N·m].
        seed: of everything random.
    """

    robots: int = 3
    logs: int = 30
    joints: int = 4
    worn: int = 3
    season: float = 12.0
    duty: float = 12.0
    warm_up: float = 3.0
    ambient: float = 28.0
    seconds: float = 20.0
    rate: float = 100.0
    noise: float = 0.05
    margin: int = 6
    seed: int = 0

    def wear(self) -> tuple[Wear, ...]:
        """The worn joints (seeded)."""
        rng = np.random.default_rng([self.seed, 1])
        pairs = [(f"robot-{r}", f"j{k}") for r in range(self.robots) for k in range(self.joints)]
        chosen = rng.choice(len(pairs), size=self.worn, replace=False)
        out = []
        for c in sorted(chosen):
            shape: Shape = "step" if rng.random() < 0.5 else "hinge"
            onset = int(rng.integers(self.margin, self.logs - self.margin + 1))
            out.append(Wear(pairs[c][0], pairs[c][1], shape, onset, float(rng.uniform(0.15, 0.30))))
        return tuple(out)


TRUTH = CoulombViscousParams(F_v=0.3, F_c=1.0, tau_os=0.05)
"""Every joint's friction at :data:`T_REF`, before wear."""


def temperature_fleet(plan: TemperatureFleet = TemperatureFleet()) -> pa.Table:
    """The fleet's results (:data:`~wbfriction.fleet.schema.RESULT_SCHEMA`), one row per robot, log and joint.

    Returns:
        The rows, each joint's ``temperature`` the mean over its log's samples.
    """
    from wbfriction.fit.joints import fit_estimate
    from wbfriction.fit.options import FitOptions
    from wbfriction.fit.terms import load_torque
    from wbfriction.fleet.task import ResultKey, result_rows
    from wbfriction.friction.estimated import FrictionEstimate

    rng = np.random.default_rng([plan.seed, 2])
    wear = plan.wear()
    start = datetime(2026, 3, 1, tzinfo=UTC)
    t = np.arange(0.0, plan.seconds, 1.0 / plan.rate)
    n = len(t)
    parts = []
    for r in range(plan.robots):
        robot_id = f"robot-{r}"
        for i in range(plan.logs):
            qd, tau_f, temperature = [], [], []
            base = plan.ambient + plan.season * i / max(plan.logs - 1, 1) + rng.uniform(-plan.duty, plan.duty)
            for k in range(plan.joints):
                joint = f"j{k}"
                w, phase = rng.uniform(0.3, 1.2, 2), rng.uniform(0, 2 * np.pi, 2)
                v = 1.2 * np.sin(w[0] * t + phase[0]) + 0.5 * np.sin(2.7 * w[1] * t + phase[1])
                T = base + rng.uniform(-2.0, 2.0) + plan.warm_up * t / plan.seconds
                worn = np.prod([x.factor(i, plan.logs) for x in wear if (x.robot_id, x.joint) == (robot_id, joint)])
                F_c = TRUTH.F_c * worn * (1 + K_TC * (T - T_REF))
                F_v = TRUTH.F_v * (1 + K_TV * (T - T_REF))
                qd.append(v)
                tau_f.append(-(F_c * np.sign(v) + F_v * v + TRUTH.tau_os) + plan.noise * rng.standard_normal(n))
                temperature.append(T)
            joints = tuple(f"j{k}" for k in range(plan.joints))
            est = FrictionEstimate(joints, t, np.column_stack(qd), np.column_stack(tau_f), np.ones((n, plan.joints),
                                   bool), np.full(n, "single"), np.ones(n, bool), np.zeros((n, 0), bool), (),
                                   temperature=np.column_stack(temperature))
            fits = fit_estimate(est, FitOptions(model="coulomb-viscous"))
            key = ResultKey(robot_id, start + timedelta(days=i), f"{robot_id}/{i:03d}.parquet", "", "", "")
            parts.append(result_rows(key, fits, [], est.qd, est.valid, est.temperature, load_torque(est)))
    return pa.concat_tables(parts)


@dataclass(frozen=True)
class TemperatureScore:
    """The trends of one fleet against its wear.

    Attributes:
        flagged: the robot joints flagged; worn: those that wear.
        onset_error: per worn joint flagged, the flagged F_c change's onset less the true one [logs].
        size_error: per worn joint flagged, the F_c change's size less the true one, relative to the true one.
    """

    flagged: tuple[tuple[str, str], ...]
    worn: tuple[tuple[str, str], ...]
    onset_error: dict[tuple[str, str], int]
    size_error: dict[tuple[str, str], float]

    @property
    def false_alarms(self) -> tuple[tuple[str, str], ...]:
        return tuple(j for j in self.flagged if j not in self.worn)

    @property
    def missed(self) -> tuple[tuple[str, str], ...]:
        return tuple(j for j in self.worn if j not in self.flagged)


def score_temperature_fleet(plan: TemperatureFleet, results: pa.Table, temperature: bool = True,
                            replicates: int | None = None) -> TemperatureScore:
    """The trends of ``results`` (:func:`temperature_fleet`) with the logs' temperatures (or without: as if the
    logs had no ``temperature.<joint>`` column), scored against ``plan``'s wear: the F_c series' change of each
    worn joint, its onset and its size at the reference temperature."""
    from wbfriction.fleet.trends import TrendOptions, fleet_trends

    options = TrendOptions(temperature=temperature, reference_temperature=T_REF if temperature else None,
                           replicates=replicates)
    found = fleet_trends(results, options)
    wear = {(w.robot_id, w.joint): w for w in plan.wear()}
    flagged = tuple((j.robot_id, j.joint) for j in found.flagged)
    onset, size = {}, {}
    for j in found.joints:
        key = (j.robot_id, j.joint)
        if key in wear and key in flagged and "F_c" in j.tests:
            cp = j.tests["F_c"]
            onset[key] = cp.onset - wear[key].onset
            size[key] = cp.relative / wear[key].size - 1.0
    return TemperatureScore(flagged, tuple(sorted(wear)), onset, size)
