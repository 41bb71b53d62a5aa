"""The fleet's results dataset (issue 25, issue 37): one row per log and joint, what :mod:`wbfriction.fleet.batch`
writes and :mod:`wbfriction.fleet.trends` reads.

The dataset is a folder of Parquet files, one per log, in a folder per robot; every file holds the whole
:data:`RESULT_SCHEMA` (``robot_id`` included, as text), so that any Parquet reader opens the folder as one
table (``pandas.read_parquet``, ``pyarrow.parquet.read_table``, ``pyarrow.dataset``, Polars, DuckDB with
``RESULTS/*/*.parquet``) and reads the ids as they were written (``007`` stays ``007``)::

    RESULTS/<robot_id>/<key>.parquet          one file per log: its joints' rows
    RESULTS-failed/<key>.json                 beside it: one file per log that failed, its entry and error
    TABLES/<robot_id>/<key>.parquet           where asked (``--tables TABLES``): the log's friction table

``key`` names what the rows describe (:class:`~wbfriction.fleet.task.ResultKey`): the log (its path and the
SHA-256 of its bytes), the robot id and start time it was listed with, the robot model and the options. A log
has one file at most: a batch that lists it again with anything changed replaces its file. Each file carries
the SHA-256 of its rows in its metadata (:data:`RESULT_DOCUMENT`), so that a damaged file is found
(:mod:`wbfriction.fleet.results`).

Sign convention: as everywhere in wbfriction, ``tau_f`` is the torque friction exerts on the joint, and the
model ``f(qd)`` is fitted to ``-tau_f`` (positive ``F_c``, ``F_v``: friction opposing the motion).
``f_at_<v>`` is the model's dissipative friction at speed ``v``: ``(f(+v) - f(-v)) / 2`` [N·m], free of the
offset ``tau_os`` and robust where the model's parameters trade off against each other; NaN where the joint
did not reach ``v`` in the log (an extrapolation is no measurement). Where the fit kept terms beyond velocity
(:mod:`wbfriction.fit.terms`), the values are its velocity model's refitted with them: at zero load, at the
reference temperature, without the position ripple; ``temperature`` says at which temperature the values are.
``f_at_<v>`` is then at the log's mean load (``|tau + tau_f|``): the level a velocity model alone fits on the log,
comparable between logs that keep different terms.
"""

from __future__ import annotations

import pyarrow as pa

RESULT_DOCUMENT = "wbfriction fleet result"
"""The ``document`` named in a result file's ``wbfriction`` metadata (with ``rows_sha256``, the digest of its
rows): what tells a result from any other Parquet file."""
REFERENCE_SPEEDS: tuple[float, ...] = (0.1, 0.3, 1.0)
"""The speeds [rad/s] at which each fit's friction ``f_at_<v>`` is reported."""
TREND_PARAMS: tuple[str, ...] = ("F_c", "F_v", "tau_os")
"""The model parameters followed over time, each with its standard error ``<name>_se`` and its Cramér-Rao bound's
standard deviation ``<name>_crb`` (:mod:`wbfriction.fit.bound`)."""


def speed_column(v: float) -> str:
    """The column of the friction at reference speed ``v`` [rad/s], e.g. ``f_at_0.3``."""
    return f"f_at_{v:g}"


RESULT_SCHEMA = pa.schema([
    ("robot_id", pa.string()),            # the robot, as the manifest names it
    ("log", pa.string()),                 # the log's path (absolute)
    ("start_time", pa.timestamp("ns", tz="UTC")),  # when the log started
    ("key", pa.string()),                 # SHA-256 hex of what the rows describe (ResultKey)
    ("log_sha256", pa.string()),
    ("robot_sha256", pa.string()),
    ("options_sha256", pa.string()),
    ("joint", pa.string()),
    ("model", pa.string()),               # the fitted model: thesis, stribeck, coulomb-viscous
    ("route", pa.string()),               # the estimate's route: momentum, acceleration
    ("status", pa.string()),              # the fit's verdict: ok, weak, routes disagree, at bound, not excited, failed
    ("n_samples", pa.int64()),            # valid samples fitted
    ("qd_min", pa.float64()),             # [rad/s] over the fitted samples
    ("qd_max", pa.float64()),
    ("qd_p95", pa.float64()),             # 95th percentile of |qd| [rad/s]
    *[(name, pa.float64()) for p in TREND_PARAMS for name in (p, f"{p}_se", f"{p}_crb")],  # [N·m], [N·m·s/rad]
    *[(f"{p}_check", pa.float64()) for p in TREND_PARAMS[:2]],  # the same model on the other route (NaN: none)
    *[(name, pa.float64()) for v in REFERENCE_SPEEDS for name in (speed_column(v), speed_column(v) + "_se")],
    ("temperature", pa.float64()),        # [°C] the values' temperature: the fit's T_ref with a temperature term,
                                          # else the mean over the samples fitted; NaN: not logged
    ("energy_share", pa.float64()),       # share of friction power that generates energy (eq. 7.9), in [0, 1]
    ("rms_residual", pa.float64()),       # [N·m]
    ("version", pa.string()),             # wbfriction's version
])
"""One row per log and torque-controlled joint (module docstring). Missing values are NaN (floats) or null."""
