"""One log of a batch (issue 25): estimate, fit, energy check, and the rows of the results dataset.

:func:`process_log` is what a Dask task runs, and what the serial run calls in order: the same function, so the
results are the same bytes. It does what ``wbfriction estimate LOG`` and ``wbfriction fit`` do with the same
options (a walking robot's raw log first made the project's log, :func:`~wbfriction.pipeline.raw_log.prepared_log`;
:func:`~wbfriction.pipeline.estimate_step.estimate_file` on one process, then
:func:`~wbfriction.pipeline.fit_step.fit_table`, what ``fit`` runs before it writes).

Sign convention: ``tau_f`` is the torque friction exerts on the joint; the model ``f(qd)`` is fitted to
``-tau_f`` (:mod:`wbfriction.fleet.schema`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from importlib import resources
from pathlib import Path

import numpy as np
import pyarrow as pa
from threadpoolctl import threadpool_limits

from wbfriction.exceptions import OutputError, WbfrictionError
from wbfriction.fit.energy import JointEnergy
from wbfriction.fit.result import FitResult
from wbfriction.fit.terms import TermFit, load_torque
from wbfriction.fleet.manifest import LogEntry
from wbfriction.fleet.options import BatchOptions
from wbfriction.fleet.schema import REFERENCE_SPEEDS, RESULT_SCHEMA, TREND_PARAMS, speed_column
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.tables import file_sha256, scratch_folder
from wbfriction.model.robot import Robot
from wbfriction.pipeline.chunks import Chunking
from wbfriction.pipeline.estimate_step import ChunkExecutor, RobotSpec, estimate_file, worker_robot
from wbfriction.pipeline.fit_step import fit_table
from wbfriction.pipeline.raw_log import prepared_log
from wbfriction.version import __version__


@dataclass(frozen=True)
class ResultKey:
    """What a log's rows describe (issue 37): the log as listed (its robot id, start time and path) and what its
    result is computed from (the SHA-256 hex digests of the log's bytes, the robot model's files and the
    options). :attr:`key` digests them all: the result file's name. Two rows of a manifest are two keys, even
    when their logs have the same bytes; a row corrected (robot id, start time) or other options are another
    key, and the log's earlier result is replaced (:mod:`wbfriction.fleet.batch`)."""

    robot_id: str
    start_time: datetime
    log: str
    log_sha256: str
    robot_sha256: str
    options_sha256: str

    @property
    def key(self) -> str:
        fields = (self.robot_id, self.start_time.astimezone(UTC).isoformat(), self.log, self.log_sha256,
                  self.robot_sha256, self.options_sha256)
        return hashlib.sha256(json.dumps(fields).encode()).hexdigest()


@dataclass(frozen=True)
class LogOutcome:
    """What :func:`process_log` gives back: the log's rows (:data:`~wbfriction.fleet.schema.RESULT_SCHEMA`), or
    the one-line error that stopped it; and where its friction table was written, if asked for."""

    entry: LogEntry
    key: ResultKey
    rows: pa.Table | None = None
    error: str = ""
    table: Path | None = None

    @property
    def failed(self) -> bool:
        return self.rows is None


def robot_sha256(spec: RobotSpec, robot: Robot) -> str:
    """SHA-256 over what defines a robot model: its URDF (or MJCF) file and its configuration (the TOML given,
    or the built-in robot's packaged TOML)."""
    digest = hashlib.sha256(file_sha256(robot.urdf).encode())
    if spec.config is not None:
        digest.update(file_sha256(spec.config).encode())
    else:
        text = resources.files("wbfriction.model.robots").joinpath(f"{robot.name}.toml").read_bytes()
        digest.update(hashlib.sha256(text).hexdigest().encode())
    return digest.hexdigest()


def options_sha256(options: BatchOptions) -> str:
    """SHA-256 of the options, as canonical JSON (every field, sorted keys)."""
    return hashlib.sha256(json.dumps(dataclasses.asdict(options), sort_keys=True, default=str).encode()).hexdigest()


def result_key(entry: LogEntry, log_hash: str, robot_hash: str, options: BatchOptions) -> ResultKey:
    """The key of ``entry``, whose log's SHA-256 is ``log_hash``, processed with ``options`` on the robot whose
    :func:`robot_sha256` is ``robot_hash``."""
    return ResultKey(entry.robot_id, entry.start_time, str(entry.log), log_hash, robot_hash, options_sha256(options))


def process_log(entry: LogEntry, key: ResultKey, options: BatchOptions, scratch: Path,
                table: Path | None = None, executor: ChunkExecutor | None = None,
                chunk_workers: int = 1) -> LogOutcome:
    """Estimate, fit and check one log (module docstring); never raises for a fault of the log or its robot.

    Args:
        entry: the log.
        key: its :func:`result_key` (recorded in every row).
        options: the batch's options with the entry's own applied (:meth:`BatchOptions.for_entry`).
        scratch: a folder for the friction table while it is fitted (removed after).
        table: where to keep the friction table, or None.
        executor, chunk_workers: where a long log's chunks go, ``chunk_workers`` at a time
            (:func:`~wbfriction.pipeline.estimate_step.estimate_file`); None: all in this process.

    Returns:
        The outcome: rows on success; else the error's one line (a
        :class:`~wbfriction.exceptions.WbfrictionError`'s message, or the exception's type and message).

    Raises:
        OutputError: a file that cannot be written (the friction table kept, the scratch folder): the
            environment, which no other log escapes.
    """
    try:
        robot = worker_robot(entry.robot)
        with threadpool_limits(1), scratch_folder(scratch) as folder:
            friction = table if table is not None else folder / "friction.parquet"
            with prepared_log(Path(entry.log), robot, str(entry.log), ReadOptions(), friction) as (log, _):
                estimate_file(entry.robot, log, friction, options.estimate, chunking=Chunking(
                    rows=options.chunk_rows, workers=chunk_workers if executor is not None else 1), robot=robot,
                    executor=executor, source=str(entry.log))
            fitted = fit_table(friction, options.fit, threshold=options.energy_threshold,
                               tolerance=options.energy_tolerance)
        est = fitted.est
        rows = result_rows(key, fitted.fits, fitted.energy, est.qd, est.valid, est.temperature, load_torque(est))
        return LogOutcome(entry, key, rows, table=table)
    except OutputError as exc:  # the results cannot be written: no other log's either, the batch stops
        where = table if table is not None else f"{scratch} (the friction table of {entry.log.name})"
        raise OutputError(str(where), exc.errno, exc.reason) from None
    except WbfrictionError as exc:
        return LogOutcome(entry, key, error=one_line(str(exc)))
    except Exception as exc:  # a fault of this log must not stop the others: recorded, with its type
        return LogOutcome(entry, key, error=one_line(f"{entry.log}: {type(exc).__name__}: {exc}"))


def one_line(text: str) -> str:
    """A message on one line (its whitespace runs, line breaks included, as one space)."""
    return " ".join(text.split())


def reference_friction(fit: FitResult, v: float) -> tuple[float, float]:
    """The fitted model's dissipative friction at speed ``v`` [rad/s], ``(f(+v) - f(-v)) / 2`` [N·m], and its
    standard error from the parameters' covariance (delta method, :meth:`FitResult.dissipative`); NaN without a fit
    or a covariance."""
    value, se = fit.dissipative(np.array([v]))
    return float(value[0]), float(se[0])


def result_rows(key: ResultKey, fits: list[FitResult], energy: list[JointEnergy], qd: np.ndarray,
                valid: np.ndarray, temperature: np.ndarray | None = None, load: np.ndarray | None = None
                ) -> pa.Table:
    """The rows of the log of ``key`` (:data:`~wbfriction.fleet.schema.RESULT_SCHEMA`), one per joint of ``fits``;
    ``qd`` (N, n_tc) [rad/s] and ``valid`` (N, n_tc) of the estimate give each joint's velocity range,
    ``temperature`` (N, n_tc) [°C] (or None) its temperature, ``load`` (N, n_tc) [N·m] (or None) the rigid-body
    torque the load term reads (:func:`~wbfriction.fit.terms.load_torque`). A fit with terms beyond velocity
    gives its velocity model refitted with them (``F_c``, ``F_v``: at zero load and its reference temperature,
    without the ripple); its ``f_at_<v>`` is the friction under the log's mean ``|load|`` (zero without ``load``):
    the level a velocity model alone fits, whichever terms a log keeps (issue 52: the KUKA's repeated wrist run kept
    a load term in one log and not the other, and at zero load its friction at 0.3 rad/s read 0.18 N·m against the
    other log's 0.30)."""
    shares = {e.joint: e.generating_share for e in energy}
    columns: dict[str, list] = {name: [] for name in RESULT_SCHEMA.names}
    for i, fit in enumerate(fits):
        rows = valid[:, i] & np.isfinite(qd[:, i])
        v = qd[rows, i]
        terms = fit.kept_terms
        params = terms.params if terms is not None else fit.params
        values = params.to_dict() if params is not None else {}
        stderr = terms.stderr if terms is not None else fit.stderr
        crb = {} if terms is not None else fit.crb  # the bound is the velocity model's
        row = {"robot_id": key.robot_id, "log": key.log, "start_time": utc_ns(key.start_time),
               "key": key.key, "log_sha256": key.log_sha256, "robot_sha256": key.robot_sha256,
               "options_sha256": key.options_sha256, "joint": fit.joint, "model": fit.model, "route": fit.route,
               "status": fit.verdict().status, "n_samples": fit.n_samples,
               "qd_min": float(v.min()) if v.size else float("nan"),
               "qd_max": float(v.max()) if v.size else float("nan"),
               "qd_p95": float(np.percentile(np.abs(v), 95)) if v.size else float("nan"),
               "temperature": _temperature(terms, temperature, i, rows),
               "energy_share": float(shares.get(fit.joint, float("nan"))),
               "rms_residual": float(fit.rms_residual), "version": __version__}
        for p in TREND_PARAMS:
            row[p] = float(values.get(p, float("nan")))
            row[f"{p}_se"] = float(stderr.get(p, float("nan")))
            row[f"{p}_crb"] = float(crb.get(p, float("nan")))
        if terms is not None:
            check = terms.check.coefficients if terms.check is not None else None
        else:
            check = fit.route_check.params if fit.route_check is not None else None
        for p in TREND_PARAMS[:2]:
            row[f"{p}_check"] = float(check.get(p, float("nan"))) if check else float("nan")
        reach = float(np.max(np.abs(v))) if v.size else 0.0
        loads = np.abs(load[rows, i]) if load is not None else np.zeros(0)
        loads = loads[np.isfinite(loads)]
        mean_load = float(np.mean(loads)) if loads.size else 0.0
        for s in REFERENCE_SPEEDS:
            nan = (float("nan"), float("nan"))
            f, se = (nan if s > reach else terms.speed_friction(s, mean_load) if terms is not None
                     else reference_friction(fit, s))
            row[speed_column(s)], row[speed_column(s) + "_se"] = f, se
        for name in RESULT_SCHEMA.names:
            columns[name].append(row[name])
    return pa.Table.from_pydict(columns, schema=RESULT_SCHEMA)


def _temperature(terms: TermFit | None, temperature: np.ndarray | None, i: int, rows: np.ndarray) -> float:
    """The temperature a joint's values are at [°C]: its fit's reference temperature where it kept a temperature
    term, else the mean over its samples; NaN where not logged."""
    if terms is not None and "temperature" in terms.kept and terms.reference_temperature is not None:
        return float(terms.reference_temperature)
    if temperature is None:
        return float("nan")
    t = temperature[rows, i]
    t = t[np.isfinite(t)]
    return float(np.mean(t)) if t.size else float("nan")


def utc_ns(t: datetime) -> int:
    """Nanoseconds since the epoch of an aware time (exact: a datetime has microseconds)."""
    return (t - EPOCH) // timedelta(microseconds=1) * 1000


EPOCH = datetime(1970, 1, 1, tzinfo=UTC)
