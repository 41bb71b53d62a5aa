"""The friction table: a :class:`~wbfriction.friction.estimated.FrictionEstimate` sample by sample, as a document
(one writer, one reader).

The **friction table** (Parquet, CSV or HDF5) holds a :class:`~wbfriction.friction.estimate.FrictionEstimate`
sample by sample: :func:`friction_table` writes it, :func:`read_friction_table` reads it back (the estimate's
options, and so its smoother, ride in the table's metadata). The fitted parameters' document, the parameters
JSON, is :mod:`wbfriction.fit.params_file`'s.
"""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path
from typing import cast

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import target_from_dict
from wbfriction.friction.options import ROUTES
from wbfriction.logs.clock import read_clock
from wbfriction.logs.tables import numeric_column, read_metadata, read_table, with_metadata
from wbfriction.logs.temperature import screen_temperature
from wbfriction.signals.kinematics import Smoother, make_smoother
from wbfriction.signals.options import SCHEMES, FilterOptions
from wbfriction.signals.window import MomentumWindow

SIGN_CONVENTION = "tau_f = -f(qd); fit of f (the joint's model, eqs. 3.1-3.5) to -tau_f"
"""What the parameters JSON of ``wbfriction fit`` states of its sign."""


# ------------------------------------------------------------------ friction table
CHECK = "check."
"""Prefix of the columns of the other route's estimate (:attr:`FrictionEstimate.route_check`): ``check.qd.<j>``,
``check.tau_f.<j>``, ``check.valid.<j>``; its metadata is the table's key ``route_check``."""


def friction_table(est: FrictionEstimate) -> pa.Table:
    """The estimate as an Arrow table: ``time``, ``phase``, ``unique``, [``route``], [``cond``],
    ``contact.<frame>``, and per joint ``qd.<j>``, ``tau_f.<j>``, ``valid.<j>``,
    ``qdd.<j>``, ``delta_qdd.<j>``, [``delta_qdd_companion.<j>``], [``disagreement.<j>``], [``tau_f_true.<j>``],
    [``determined.<j>``] (point feet),
    the terms' signals [``q.<j>``, ``tau.<j>``, ``temperature.<j>``] (:mod:`~wbfriction.fit.terms`),
    [the other route's ``check.qd.<j>``, ``check.tau_f.<j>``, ``check.valid.<j>`` (:data:`CHECK`)];
    the companion's scheme is the metadata key ``companion_diff``, the other route's metadata ``route_check``."""
    cols: dict[str, object] = {"time": est.time, "phase": pa.array(est.phase.astype(str)),
                               "unique": est.unique}
    if est.route is not None:
        cols["route"] = pa.array(est.route.astype(str))
    if est.cond is not None:
        cols["cond"] = est.cond
    for i, f in enumerate(est.contact_frames):
        cols[f"contact.{f}"] = est.contact[:, i].astype(np.int8)
    for i, j in enumerate(est.joints):
        cols[f"qd.{j}"] = est.qd[:, i]
        cols[f"tau_f.{j}"] = est.tau_f[:, i]
        cols[f"valid.{j}"] = est.valid[:, i]
        for name, arr in (("qdd", est.qdd), ("delta_qdd", est.delta_qdd),
                          ("delta_qdd_companion", est.companion_delta_qdd), ("disagreement", est.disagreement),
                          ("q", est.q), ("tau", est.tau), ("determined", est.determined)):
            if arr is not None:
                cols[f"{name}.{j}"] = arr[:, i]
        if est.temperature is not None and not np.all(np.isnan(est.temperature[:, i])):
            cols[f"temperature.{j}"] = est.temperature[:, i]
        if est.tau_f_true is not None and not np.all(np.isnan(est.tau_f_true[:, i])):
            cols[f"tau_f_true.{j}"] = est.tau_f_true[:, i]
    metadata = dict(est.metadata)
    check = est.route_check
    if check is not None:
        for i, j in enumerate(est.joints):
            cols.update({f"{CHECK}qd.{j}": check.qd[:, i], f"{CHECK}tau_f.{j}": check.tau_f[:, i],
                         f"{CHECK}valid.{j}": check.valid[:, i]})
        metadata["route_check"] = {k: v for k, v in check.metadata.items()
                                   if k in ("estimate_options", "momentum", "base_motion", "foot_force_sampling")}
    if est.companion_diff is not None:
        metadata["companion_diff"] = est.companion_diff
    return with_metadata(pa.table(cols), metadata)




# ------------------------------------------------------------------ reading it back
def _optional_columns(table: pa.Table, prefix: str, joints, source: str) -> np.ndarray | None:
    """(N, n) of ``<prefix>.<joint>`` columns, NaN for a missing one; None if all are missing."""
    names = set(table.column_names)
    if not any(f"{prefix}.{j}" in names for j in joints):
        return None
    return np.column_stack([_float_column(table, f"{prefix}.{j}", source) if f"{prefix}.{j}" in names
                            else np.full(table.num_rows, np.nan) for j in joints])


def _float_column(table: pa.Table, name: str, source: str) -> np.ndarray:
    """A column that may hold NaN (what could not be estimated)."""
    return numeric_column(table, name, source, finite=False)


def _table_smoother(meta: dict, time: np.ndarray, source: str) -> Smoother | None:
    """The estimate's filter, rebuilt from the ``estimate_options`` metadata (None without one)."""
    opts = meta.get("estimate_options")
    if opts is None or len(time) < 2:
        return None
    bad = InputError(f"{source}: the metadata's estimate_options are not those of 'wbfriction estimate'")
    if not isinstance(opts, dict) or not isinstance(opts.get("filtering", {}), dict):
        raise bad
    diff = opts.get("diff", "central")
    if diff not in (*SCHEMES, "true"):
        raise InputError(f"{source}: the metadata's estimate_options name an unknown scheme {diff!r}")
    try:
        filtering = FilterOptions(**opts.get("filtering", {}))
    except TypeError:
        raise bad from None
    for f in fields(filtering):
        value, default = getattr(filtering, f.name), getattr(FilterOptions(), f.name)
        if type(value) is not type(default) and not (isinstance(default, float) and type(value) is int):
            raise InputError(f"{source}: the metadata's estimate_options.filtering.{f.name} is {value!r}")
    dt = float(np.median(np.diff(time)))
    clock = meta.get("clock", {})
    kind = clock.get("kind") if isinstance(clock, dict) else None
    t = None
    if kind == "skipping":  # differentiated on the stamps as recorded
        t = time - time[0]
    elif kind == "jittered":  # differentiated on the regularised clock: rebuilt from the same stamps
        regular = read_clock(time, source, time_base="regularised")
        dt, t = regular.period, regular.t
    route = opts.get("route", "acceleration")
    if route not in ROUTES:
        raise InputError(f"{source}: the metadata's estimate_options name an unknown route {route!r}")
    if route == "momentum":
        momentum = opts.get("momentum")
        windows = [momentum.get(k) if isinstance(momentum, dict) else None for k in ("velocity_window", "window")]
        if not all(isinstance(w, int) and not isinstance(w, bool) and w >= 3 and w % 2 == 1 for w in windows):
            raise InputError(f"{source}: the metadata's estimate_options.momentum is {momentum!r}, not two odd "
                             "windows in samples")
        return MomentumWindow(int(cast(int, windows[1])) // 2, dt, t)
    return make_smoother(diff, filtering, dt, t)


def _check_targets(meta: dict, source: str) -> None:
    """The ``friction_true`` metadata (simulations): joint -> parameters of (3.5)."""
    targets = meta.get("friction_true", {})
    if not isinstance(targets, dict):
        raise InputError(f"{source}: the metadata's friction_true is not a table of joints")
    for joint, params in targets.items():
        try:
            if not isinstance(params, dict):
                raise TypeError("not a table of parameters")
            target_from_dict(params)
        except (TypeError, ValueError) as exc:
            raise InputError(f"{source}: the metadata's friction_true of '{joint}': {exc}") from None


def read_friction_table(table: pa.Table, source: str = "<table>") -> FrictionEstimate:
    """Read back a friction table written by ``wbfriction estimate`` (:func:`friction_table`).

    The joints are those with a ``tau_f.<j>`` column; each needs ``qd.<j>`` and ``valid.<j>``,
    and the table ``time``. The other columns are optional (older tables, or tables of other
    tools): without ``phase`` every sample counts as single support; without ``unique``, the
    single-support ones are unique; the contact flags, ``qdd``, ``delta_qdd``, the companion,
    ``tau_f_true`` and the terms' signals (``q``, ``tau``, ``temperature``) are then None. The smoother is
    rebuilt from the ``estimate_options`` metadata.

    Raises:
        InputError: no joint, or a missing column (named with ``source``).
    """
    names = table.column_names
    joints = tuple(c[len("tau_f."):] for c in names if c.startswith("tau_f."))  # check.tau_f.* start otherwise
    if not joints:
        raise InputError(f"{source}: no 'tau_f.<joint>' column: not a friction table from 'wbfriction estimate'")
    for c in ("time", *[f"{p}{j}" for j in joints for p in ("qd.", "valid.")]):
        if c not in names:
            raise ColumnError(source, c, None, f"missing column '{c}'")
    time = numeric_column(table, "time", source)
    stack = lambda prefix, finite=False: np.column_stack(  # noqa: E731
        [numeric_column(table, f"{prefix}.{j}", source, finite=finite) for j in joints])
    frames = tuple(c[len("contact."):] for c in names if c.startswith("contact."))
    contact = (np.column_stack([numeric_column(table, f"contact.{f}", source) for f in frames]).astype(bool)
               if frames else np.zeros((len(time), 0), dtype=bool))
    try:
        phase = (np.asarray(table.column("phase").to_pylist(), dtype=str) if "phase" in names
                 else np.full(len(time), "single"))
    except (pa.ArrowException, ValueError):  # text is decoded lazily: damaged UTF-8 fails here
        raise ColumnError(source, "phase", None, "column 'phase' is not text") from None
    unique = (numeric_column(table, "unique", source).astype(bool) if "unique" in names else phase == "single")
    try:
        route = np.asarray(table.column("route").to_pylist(), dtype=str) if "route" in names else None
    except (pa.ArrowException, ValueError):
        raise ColumnError(source, "route", None, "column 'route' is not text") from None
    meta = read_metadata(table, source)
    smoother = _table_smoother(meta, time, source)
    _check_targets(meta, source)
    companion_diff = meta.get("companion_diff")
    if companion_diff is not None and companion_diff not in SCHEMES:
        raise InputError(f"{source}: the metadata's companion_diff is {companion_diff!r}, not a scheme")
    route_check = None
    if any(f"{CHECK}tau_f.{j}" in names for j in joints):
        for c in (f"{CHECK}{p}{j}" for j in joints for p in ("qd.", "tau_f.", "valid.")):
            if c not in names:
                raise ColumnError(source, c, None, f"missing column '{c}'")
        check_meta = meta.get("route_check")
        if not isinstance(check_meta, dict):
            raise InputError(f"{source}: columns '{CHECK}*' without the metadata's route_check")
        route_check = FrictionEstimate(
            joints=joints, time=time, qd=stack(f"{CHECK}qd"), tau_f=stack(f"{CHECK}tau_f"),
            valid=stack(f"{CHECK}valid", True).astype(bool), phase=phase, unique=unique, contact=contact,
            contact_frames=frames, metadata=dict(check_meta), smoother=_table_smoother(
                {**check_meta, "clock": meta.get("clock", {})}, time, source))
    return FrictionEstimate(
        route_check=route_check,
        joints=joints, time=time, qd=stack("qd"), tau_f=stack("tau_f"), valid=stack("valid", True).astype(bool),
        phase=phase, unique=unique, contact=contact, contact_frames=frames,
        qdd=_optional_columns(table, "qdd", joints, source),
        delta_qdd=_optional_columns(table, "delta_qdd", joints, source),
        cond=_float_column(table, "cond", source) if "cond" in names else None,
        tau_f_true=_optional_columns(table, "tau_f_true", joints, source), metadata=meta, smoother=smoother,
        companion_delta_qdd=_optional_columns(table, "delta_qdd_companion", joints, source),
        companion_diff=companion_diff, route=route,
        disagreement=_optional_columns(table, "disagreement", joints, source),
        q=_optional_columns(table, "q", joints, source), tau=_optional_columns(table, "tau", joints, source),
        temperature=_temperature(table, joints, source), determined=_determined(table, joints, source))


def _determined(table: pa.Table, joints, source: str) -> np.ndarray | None:
    """The ``determined.<joint>`` columns (N, n) (point feet, :mod:`wbfriction.friction.point_contacts`), or None."""
    flags = _optional_columns(table, "determined", joints, source)
    return None if flags is None else flags == 1


def _temperature(table: pa.Table, joints, source: str) -> np.ndarray | None:
    """The ``temperature.<joint>`` columns (N, n) [°C], screened as a log's are
    (:func:`~wbfriction.logs.temperature.screen_temperature`: ``estimate`` named the glitches it left out, a table
    written otherwise has them left out here too), or None."""
    T = _optional_columns(table, "temperature", joints, source)
    return None if T is None else screen_temperature(T, joints, source)[0]


def read_friction_file(path: str | Path) -> FrictionEstimate:
    """:func:`read_friction_table` of a Parquet, CSV or HDF5 file.

    Raises:
        InputError: an unreadable file, or what :func:`read_friction_table` raises (named with the file).
    """
    return read_friction_table(read_table(path), str(path))
