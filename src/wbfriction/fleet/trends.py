"""Friction over time, per robot and joint, and the joints whose friction drifted (issue 25).

Each robot's joint gives one series per followed quantity (:data:`~wbfriction.fleet.schema.TREND_PARAMS` and
the friction at the reference speeds), one point per log: the value and its standard error. A log whose fit is
not usable (``not excited``, ``failed``) or whose value or standard error is not finite gives no point; nor, for
a model parameter, a log fitted with another model than the joint's most frequent one (``fit --model auto``
may choose per log, and F_c of the Coulomb-viscous model is not F_c of (3.5)). The friction at a reference
speed is the same quantity in every model: every usable log gives a point.

**The change detector** (:mod:`~wbfriction.fleet.change_point`): for each series, the best change (a constant
followed by a linear drift or a step from an unknown onset) and its exact Monte Carlo p-value;

* a joint is flagged when one of its quantities has a p-value below ``alpha / m`` (Bonferroni over its ``m``
  quantities with enough points) **and** a change at the last log of at least
  :attr:`TrendOptions.min_change` of its baseline (F_c's for ``tau_os``, which may be zero): a significant
  change too small to matter is not a drift. A significant change from a baseline that is not told from zero
  is one whatever its size (its relative change is undefined: NaN).

**Temperature**: where every point of a series has the temperature it was measured at (the results'
``temperature``: logs with ``temperature.<joint>``) and they spread, the value's linear dependence on it is
fitted with the change (:func:`~wbfriction.fleet.change_point.detect_change`): a log recorded warm compares with
one recorded cold, at the reference temperature the table states (:attr:`TrendOptions.reference_temperature`, or
the series' median).

Sign convention: the values are those of the results dataset (:mod:`wbfriction.fleet.schema`): ``F_c``,
``F_v`` and ``f_at_<v>`` positive for friction opposing the motion.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from datetime import UTC, datetime, timedelta

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from wbfriction.choices import check_choice
from wbfriction.exceptions import InputError, OptionError
from wbfriction.fleet.change_point import FIRST_PASS, ChangePoint, detect_change
from wbfriction.fleet.options import SHAPES, Shape
from wbfriction.fleet.schema import REFERENCE_SPEEDS, RESULT_SCHEMA, TREND_PARAMS, speed_column
from wbfriction.logs.options import check_reference_temperature

QUANTITIES: tuple[str, ...] = (*TREND_PARAMS, *[speed_column(v) for v in REFERENCE_SPEEDS])
"""The quantities followed over time: the model's parameters and the friction at the reference speeds."""
UNITS = {"F_c": "N·m", "F_v": "N·m·s/rad", "tau_os": "N·m", **{speed_column(v): "N·m" for v in REFERENCE_SPEEDS}}
"""The unit of each quantity."""
USABLE = ("ok", "weak", "at bound")
"""The fit statuses whose values are points of a series (``not excited`` and ``failed`` fits have none; a fit whose
two routes disagree is biased one way or the other: its value is no point of a series either)."""


@dataclass(frozen=True)
class TrendOptions:
    """The change detector's settings (module docstring).

    Attributes:
        alpha: the false-alarm probability per joint (Bonferroni over its quantities).
        min_points: fewer points: no test.
        min_before, min_after: points before the onset, and from it on.
        min_change: the smallest change at the last log that is flagged, relative to the baseline.
        replicates: noise series of the p-value's Monte Carlo (the smallest p-value is ``1 / (replicates + 1)``);
            None: :meth:`draws` chooses enough for ``alpha``.
        seed: of those series.
        quantities: the quantities tested.
        shapes: the shapes of change tested (:data:`~wbfriction.fleet.change_point.SHAPES`: a linear drift
            from an onset, a step at it, or both, the better one chosen per series).
        temperature: whether the logs' temperatures (the results' ``temperature``), where every point of a series
            has one, enter its test (:func:`~wbfriction.fleet.change_point.detect_change`): its values compared at
            one reference temperature.
        reference_temperature: that temperature [°C]; None: each series' median.

    Raises:
        InputError: ``alpha`` out of (0, 1), ``replicates`` too few to reach ``alpha / m`` (naming
            ``--replicates``), an unknown quantity.
    """

    alpha: float = 1e-3
    min_points: int = 8
    min_before: int = 3
    min_after: int = 3
    min_change: float = 0.10
    replicates: int | None = None
    seed: int = 0
    quantities: tuple[str, ...] = QUANTITIES
    shapes: tuple[Shape, ...] = SHAPES
    temperature: bool = True
    reference_temperature: float | None = None

    def __post_init__(self) -> None:
        if not self.shapes:
            raise OptionError("--shapes", self.shapes, f"one or more of {', '.join(SHAPES)}")
        for shape in self.shapes:
            check_choice("shapes", shape, SHAPES)
        if not 0 < self.alpha < 1:
            raise InputError(f"--alpha must be in (0, 1), got {self.alpha}")
        unknown = set(self.quantities) - set(QUANTITIES)
        if unknown:
            raise InputError(f"unknown quantities {sorted(unknown)}: choose from {', '.join(QUANTITIES)}")
        check_reference_temperature(self.reference_temperature)
        if not self.temperature and self.reference_temperature is not None:
            raise OptionError("--reference-temperature", self.reference_temperature,
                              "left out with --no-temperature (no value is compared at a temperature then)")
        need = self.least_replicates()
        if self.replicates is not None and self.replicates < need:
            raise InputError(f"--replicates {self.replicates} cannot resolve --alpha {self.alpha:g} over "
                             f"{len(self.quantities)} quantities: give at least {need}")

    def least_replicates(self) -> int:
        """The fewest noise series whose smallest p-value is below ``alpha / m`` (``m`` the quantities)."""
        return max(2 * FIRST_PASS, int(np.ceil(len(self.quantities) / self.alpha)))

    def draws(self) -> int:
        """The noise series drawn: :attr:`replicates`, or :data:`REPLICATES` and at least
        :data:`RESOLUTION` times :meth:`least_replicates`."""
        if self.replicates is not None:
            return self.replicates
        return max(REPLICATES, RESOLUTION * self.least_replicates())


REPLICATES = 20_000
"""The noise series of the p-value by default (:meth:`TrendOptions.draws`)."""
RESOLUTION = 3
"""Times the fewest noise series that resolve ``alpha / m`` the default draws at least, so that a p-value near
the threshold is told from it."""


@dataclass(frozen=True)
class Series:
    """One quantity of one joint over time.

    Attributes:
        quantity: its name (:data:`QUANTITIES`).
        time: (n,) the logs' start times (UTC).
        value, se: (n,) values and standard errors [N·m, N·m·s/rad], NaN where the log gave no point.
        used: (n,) the logs that are points of the series.
        temperature: (n,) the temperature each value was measured at [°C] (the results' ``temperature``), NaN where
            not logged; None: not read.
    """

    quantity: str
    time: list[datetime]
    value: np.ndarray
    se: np.ndarray
    used: np.ndarray
    temperature: np.ndarray | None = None


@dataclass(frozen=True)
class JointTrend:
    """One robot's joint over time: its series, each series' best change, and the drifts found.

    Attributes:
        robot_id, joint: which.
        series: quantity -> :class:`Series`.
        tests: quantity -> its best change (quantities with too few points have none).
        drifts: the changes that are flagged, most significant first.
    """

    robot_id: str
    joint: str
    series: dict[str, Series]
    tests: dict[str, ChangePoint] = field(default_factory=dict)
    drifts: tuple[ChangePoint, ...] = ()

    @property
    def flagged(self) -> bool:
        return bool(self.drifts)

    @property
    def onset_time(self) -> datetime | None:
        """When the most significant drift started, or None."""
        return self.drifts[0].onset_time if self.drifts else None


@dataclass(frozen=True)
class FleetTrends:
    """Every robot's joints over time: flagged ones first (earliest onset first), then by robot and joint."""

    joints: list[JointTrend]
    options: TrendOptions

    @property
    def flagged(self) -> list[JointTrend]:
        return [j for j in self.joints if j.flagged]

    @property
    def tested(self) -> list[JointTrend]:
        """The joints with at least one quantity tested (enough usable points)."""
        return [j for j in self.joints if j.tests]

    def summary(self) -> str:
        """One sentence: how many of the tested joints drifted, and how many could not be tested and what they
        lack (usable logs, or start times: logs at one time tell no change over time)."""
        n, tested = len(self.joints), len(self.tested)
        untested = [j for j in self.joints if not j.tests]
        need = max(self.options.min_points, self.options.min_before + self.options.min_after)
        most = [max(((int(s.used.sum()), len({t for t, u in zip(s.time, s.used) if u})) for s in j.series.values()),
                    default=(0, 0)) for j in untested]  # the usable logs and their start times, at best
        few = sum(points < need for points, _ in most)
        clustered = sorted({m for m in most if m[0] >= need})
        if clustered:  # enough logs, at too few start times
            points, times = clustered[0] if len(clustered) == 1 else (0, 0)
            at = (f"its {points} usable logs at {times} start time{'s' if times > 1 else ''}" if points
                  else "its usable logs at too few start times")
        if tested == 0:
            lack = ([f"fewer than {self.options.min_points} usable logs"] if few else []) + ([at] if clustered else [])
            each = "each has " + " or ".join(lack) + (": a change over time needs logs at several" if not few else "")
            return f"none of the {n} robot joints could be tested ({each}): no drift can be told"
        parts = ([f"{few} with fewer than {self.options.min_points} usable logs"] if few else []) + \
            ([f"{len(untested) - few} with {at}"] if clustered else [])
        told = f" ({n - tested} not tested: {', '.join(parts)})" if untested else ""
        return f"{len(self.flagged)} of {tested} tested robot joints drifted{told}"

    def temperature_notes(self) -> list[tuple[str, str, str, str]]:
        """``(robot_id, joint, quantity, note)`` of every series whose temperatures were left out of its test
        although it has some (:attr:`~wbfriction.fleet.change_point.ChangePoint.temperature_note`)."""
        return [(j.robot_id, j.joint, q, cp.temperature_note) for j in self.joints for q, cp in j.tests.items()
                if cp.temperature_note]

    def to_table(self) -> pa.Table:
        """One row per robot, joint and tested quantity: the best change (its shape, onset, size, statistic,
        p-value), whether it is a flagged drift, and the temperature its baseline and size are at with the slope
        per °C found (null and NaN where the logs' temperatures did not enter the test), and why they did not where
        the series has some (:attr:`~wbfriction.fleet.change_point.ChangePoint.temperature_note`)."""
        rows: dict[str, list] = {k: [] for k in ("robot_id", "joint", "quantity", "points", "flagged", "shape",
                                                 "onset_time", "baseline", "change", "change_se", "relative_change",
                                                 "statistic", "p_value", "last_value", "reference_temperature",
                                                 "temperature_slope", "temperature_slope_se",
                                                 "temperature_note")}
        for j in self.joints:
            for q, cp in j.tests.items():
                s = j.series[q]
                rows["robot_id"].append(j.robot_id)
                rows["joint"].append(j.joint)
                rows["quantity"].append(q)
                rows["points"].append(int(s.used.sum()))
                rows["flagged"].append(cp in j.drifts)
                rows["shape"].append(cp.shape)
                rows["onset_time"].append(cp.onset_time)
                rows["baseline"].append(cp.baseline)
                rows["change"].append(cp.change)
                rows["change_se"].append(cp.change_se)
                rows["relative_change"].append(cp.relative)
                rows["statistic"].append(cp.statistic)
                rows["p_value"].append(cp.p_value)
                rows["last_value"].append(float(s.value[s.used][-1]))
                rows["reference_temperature"].append(cp.reference_temperature)
                rows["temperature_slope"].append(cp.temperature_slope)
                rows["temperature_slope_se"].append(cp.temperature_slope_se)
                rows["temperature_note"].append(cp.temperature_note)
        schema = pa.schema([("robot_id", pa.string()), ("joint", pa.string()), ("quantity", pa.string()),
                            ("points", pa.int64()), ("flagged", pa.bool_()), ("shape", pa.string()),
                            ("onset_time", pa.timestamp("us", tz="UTC")),
                            *[(n, pa.float64()) for n in ("baseline", "change", "change_se", "relative_change",
                                                         "statistic", "p_value", "last_value",
                                                         "reference_temperature", "temperature_slope",
                                                         "temperature_slope_se")],
                            ("temperature_note", pa.string())])
        return pa.Table.from_pydict(rows, schema=schema)


def joint_trend(robot_id: str, joint: str, rows: pa.Table, options: TrendOptions = TrendOptions()) -> JointTrend:
    """One joint's series (its rows of the results, one per log, in time order) and the drifts found."""
    rows = rows.take(pc.sort_indices(rows, sort_keys=[("start_time", "ascending"), ("log", "ascending")]))
    time = [t.astimezone(UTC) for t in pc.cast(rows.column("start_time"), pa.timestamp("us", tz="UTC"),
                                                safe=False).to_pylist()]  # datetimes, whatever is installed
    usable = np.isin(np.array(rows.column("status").to_pylist(), dtype=object), USABLE)
    models = np.array(rows.column("model").to_pylist(), dtype=object)
    temperature = (np.asarray(rows.column("temperature").to_numpy(zero_copy_only=False), dtype=float)
                   if options.temperature else None)
    dominant = max(sorted(set(models[usable])), key=lambda m: int(np.sum(models[usable] == m)), default=None)
    series = {}
    for q in options.quantities:
        # a parameter means one thing in one model: its series keeps the logs fitted with the joint's most
        # frequent model; the friction at a speed is the same quantity whatever the model
        same = usable if q.startswith("f_at_") else usable & (models == dominant)
        value = np.asarray(rows.column(q).to_numpy(zero_copy_only=False), dtype=float)
        se = np.asarray(rows.column(q + "_se").to_numpy(zero_copy_only=False), dtype=float)
        used = same & np.isfinite(value) & np.isfinite(se) & (se > 0)
        series[q] = Series(q, time, np.where(used, value, np.nan), np.where(used, se, np.nan), used, temperature)
    tests: dict[str, ChangePoint] = {}
    for q, s in series.items():
        scale = None
        if q == "tau_os":  # an offset may be zero: its change is measured against the Coulomb friction
            f_c = series.get("F_c")
            scale = float(np.nanmedian(f_c.value)) if f_c is not None and f_c.used.any() else None
        cp = detect_change(time, s.value, s.se, q, options, scale, s.temperature, options.reference_temperature)
        if cp is not None:
            tests[q] = cp
    m = max(len(tests), 1)
    drifts = sorted((cp for cp in tests.values() if cp.p_value < options.alpha / m
                     and (np.isnan(cp.relative) or abs(cp.relative) >= options.min_change)),
                    key=lambda cp: (cp.p_value, -cp.statistic))
    return JointTrend(robot_id, joint, series, tests, tuple(drifts))


def fleet_trends(table: pa.Table, options: TrendOptions = TrendOptions()) -> FleetTrends:
    """Every robot's joints over time (:func:`joint_trend`), from the results dataset
    (:func:`~wbfriction.fleet.results.read_results`).

    Raises:
        InputError: a table without the results' columns, or with no row.
    """
    missing = [n for n in RESULT_SCHEMA.names if n not in table.column_names]
    if missing:
        raise InputError(f"not a fleet's results: no column {missing[0]!r}")
    if table.num_rows == 0:
        raise InputError("the results hold no log")
    out = []
    keys = sorted(set(zip(table.column("robot_id").to_pylist(), table.column("joint").to_pylist())))
    for robot_id, joint in keys:
        mask = pc.and_(pc.equal(table.column("robot_id"), robot_id), pc.equal(table.column("joint"), joint))
        out.append(joint_trend(robot_id, joint, table.filter(mask), options))
    far = datetime.max.replace(tzinfo=UTC) - timedelta(days=1)
    out.sort(key=lambda j: (not j.flagged, j.onset_time or far, j.robot_id, j.joint))
    return FleetTrends(out, options)
