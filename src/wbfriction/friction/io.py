"""The friction estimate's documents: the friction table and the parameters JSON (one writer, one reader each).

* The **friction table** (Parquet, CSV or HDF5) holds a
  :class:`~wbfriction.friction.estimate.FrictionEstimate` sample by sample:
  :func:`friction_table` writes it, :func:`read_friction_table` reads it back (the estimate's
  options, and so its smoother, ride in the table's metadata).
* The **parameters JSON** holds the fitted model per joint (:class:`~wbfriction.friction.fit.FitResult`): its
  name (``model``: ``coulomb-viscous``, ``stribeck`` or ``thesis`` (3.5)), parameters, standard errors, their
  Cramér-Rao bounds (``crb``) and the torque noise they take (``torque_noise``), which parameters ended at a
  bound (``at_bound``), the estimate's ``route`` and the same model on the other route (``route_check``: its
  parameters, standard errors, and those that ``disagree``), the velocity noise the model's expectation took
  (``velocity_noise``), the samples left out where the joint may stick (``stick_speed``, ``n_stuck``) and, when
  the model was chosen by held-out error, how (``selection``). :func:`write_params` writes it (``wbfriction
  fit`` and the studies), :func:`read_params` reads it (``wbfriction report --params``). A standard error that
  is not finite (not identifiable) is written as ``null`` and read back as ``inf``. Files written before the
  model choice (no ``model`` key) hold model (3.5) and read back so.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import fields
from pathlib import Path
from typing import Any, cast

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.friction.energy import JointEnergy
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.fit import FitResult, HeldOutScore, ModelSelection, RouteCheck
from wbfriction.friction.holdout import PredictionCheck
from wbfriction.friction.models import check_model, params_from_dict, target_from_dict
from wbfriction.friction.options import ROUTES
from wbfriction.friction.params_check import check_model_params, check_terms
from wbfriction.friction.terms import TermFit
from wbfriction.logs.clock import read_clock
from wbfriction.logs.tables import file_sha256, numeric_column, read_metadata, read_table, with_metadata, write_json
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
    the terms' signals [``q.<j>``, ``tau.<j>``, ``temperature.<j>``] (:mod:`~wbfriction.friction.terms`),
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
                          ("q", est.q), ("tau", est.tau)):
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
                                   if k in ("estimate_options", "momentum", "base_motion")}
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
        temperature=_temperature(table, joints, source))


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


# ------------------------------------------------------------------ parameters JSON
def finite_or_none(x: float | None) -> float | None:
    """A number as the JSON files hold it: ``null`` for one that is not finite (or none)."""
    return None if x is None or not np.isfinite(x) else float(x)


def _number(x: Any) -> float:
    """A number of the JSON; ``null`` (written for a value that is not finite) as ``inf``."""
    return float("inf") if x is None else float(x)


def selection_to_dict(selection: ModelSelection) -> dict[str, Any]:
    """How a joint's model was chosen, as the parameters JSON records it (a held-out RMS that is
    not finite: ``null``)."""
    return {"chosen": selection.chosen, "reason": selection.reason, "tolerance": selection.tolerance,
            "n_train": selection.n_train, "n_held_out": selection.n_held_out,
            "scores": [{"model": c.model, "held_out_rms": finite_or_none(c.held_out_rms),
                        "at_bound": list(c.at_bound)} for c in selection.scores]}


def selection_from_dict(d: Mapping[str, Any]) -> ModelSelection:
    """Inverse of :func:`selection_to_dict` (a ``null`` held-out RMS reads back as NaN).

    Raises:
        InputError: a missing key, an unknown model, a value of the wrong kind.
    """
    try:
        scores = tuple(HeldOutScore(check_model(c["model"], "selection.scores.model"),
                                    float("nan") if c.get("held_out_rms") is None else float(c["held_out_rms"]),
                                    tuple(map(str, c.get("at_bound", ())))) for c in d.get("scores", ()))
        return ModelSelection(check_model(d["chosen"], "selection.chosen"), str(d.get("reason", "")), scores,
                              float(d["tolerance"]), int(d.get("n_train", 0)), int(d.get("n_held_out", 0)))
    except KeyError as exc:
        raise InputError(f"selection: missing key {exc}") from None
    except (TypeError, ValueError, AttributeError) as exc:
        raise InputError(f"selection: {exc}") from None


def _covariance(rows: Any, p: int) -> np.ndarray:
    """A parameters JSON's ``covariance`` (p x p, in the parameters' order; ``null`` for ``inf``: a parameter that
    is not identifiable).

    Raises:
        ValueError: not a p x p matrix of numbers.
    """
    cov = np.array([[_number(x) for x in row] for row in rows], dtype=float)
    if cov.shape != (p, p):
        raise ValueError(f"covariance of shape {cov.shape}, expected ({p}, {p}) (one row per parameter)")
    return cov


def fit_to_dict(fit: FitResult) -> dict[str, Any]:
    """One joint's entry of the parameters JSON (a standard error that is not finite: ``null``)."""
    clean = finite_or_none
    d: dict[str, Any] = {"n_samples": fit.n_samples, "n_screened": fit.n_screened, "fitted": fit.params is not None,
                         "success": fit.success, "message": fit.message,
                         "rms_residual": clean(fit.rms_residual), "model": fit.model,
                         "params": None if fit.params is None else fit.params.to_dict(),
                         "stderr": {k: clean(v) for k, v in fit.stderr.items()},
                         "at_bound": dict(fit.at_bound), "speed": fit.speed}
    if fit.params is not None and fit.covariance is not None:  # the curve's standard error at any speed
        d["covariance"] = [[clean(float(x)) for x in row] for row in fit.covariance]
    d["crb"] = {k: clean(v) for k, v in fit.crb.items()}
    d["torque_noise"] = fit.torque_noise
    d["route"] = fit.route
    if fit.route_check is not None:
        rc = fit.route_check
        d["route_check"] = {"route": rc.route, "params": rc.params,
                            "stderr": {k: clean(v) for k, v in rc.stderr.items()}, "disagree": list(rc.disagree)}
    d["velocity_noise"], d["stick_speed"], d["n_stuck"] = fit.velocity_noise, fit.stick_speed, fit.n_stuck
    d["pass_rows"] = clean(fit.pass_rows)  # null: every reversal that changes sign passes
    if fit.later is not None:
        d["later_stretch"] = fit.later.to_dict()
    verdict = fit.verdict()
    d["status"], d["status_reason"] = verdict.status, verdict.reason
    if fit.selection is not None:
        d["selection"] = selection_to_dict(fit.selection)
    if fit.terms is not None:
        d["terms"] = fit.terms.to_dict()
    if fit.rms_error_vs_true is not None:
        d["rms_error_vs_true"] = clean(fit.rms_error_vs_true)
        d["rms_model_vs_true"] = clean(fit.rms_model_vs_true)
    if fit.target is not None:
        d["target"] = fit.target.to_target()
        d["error_percent"] = {k: clean(v) for k, v in (fit.error_percent() or {}).items()}
    return d


def fit_from_dict(joint: str, d: Mapping[str, Any]) -> FitResult:
    """Inverse of :func:`fit_to_dict` (a ``null`` standard error reads back as ``inf``: not
    identifiable). Without ``model`` (files of earlier versions) the parameters are those of (3.5);
    without ``at_bound``, no parameter is known to be at a bound (an empty table); without ``speed``, how much
    the joint moved is not known. ``status`` is not read: it follows from the rest
    (:meth:`~wbfriction.friction.fit.FitResult.verdict`). The values are held to what ``fit`` writes
    (:mod:`~wbfriction.friction.params_check`: dissipative parameters, terms whole and consistent with the model).

    Raises:
        InputError: an unknown model, unknown parameter names (or ``at_bound`` names that are not
            the model's), a value that is not a number, a value :mod:`~wbfriction.friction.params_check` refuses
            (naming its key).
    """
    try:
        model = check_model(str(d.get("model", "thesis")))
        res: FitResult = FitResult(joint=joint, n_samples=int(d.get("n_samples", 0)),
                                   n_screened=int(d.get("n_screened", 0)),
                                   success=bool(d.get("success", False)), message=str(d.get("message", "")),
                                   rms_residual=_number(d.get("rms_residual")), model=model,
                                   speed=None if d.get("speed") is None else _number(d["speed"]))
        if d.get("params") is not None:
            res.params = params_from_dict(model, d["params"])
            missing = [n for n in res.params.names if n not in d["params"]]
            if missing:  # its default would be read: a removed F_c a frictionless joint
                raise InputError(f"params.{missing[0]} is missing: 'fit' writes every parameter of the {model} model")
            res.stderr = {k: _number(v) for k, v in (d.get("stderr") or {}).items()}
            if d.get("covariance") is not None:
                res.covariance = _covariance(d["covariance"], len(res.params.names))
        at_bound = d.get("at_bound") or {}
        unknown = set(at_bound) - set(res.params.names if res.params is not None else at_bound)
        if unknown:
            raise InputError(f"at_bound names {', '.join(sorted(unknown))}: not parameters of the {model} model")
        res.at_bound = {str(k): bool(v) for k, v in at_bound.items()}
        if d.get("selection") is not None:
            res.selection = selection_from_dict(d["selection"])
        res.crb = {str(k): _number(v) for k, v in (d.get("crb") or {}).items()}
        res.torque_noise = None if d.get("torque_noise") is None else float(d["torque_noise"])
        res.route = str(d.get("route", "acceleration"))
        if d.get("route_check") is not None:
            rc = d["route_check"]
            res.route_check = RouteCheck(str(rc["route"]), None if rc.get("params") is None else
                                         {str(k): float(v) for k, v in rc["params"].items()},
                                         {str(k): _number(v) for k, v in (rc.get("stderr") or {}).items()},
                                         tuple(map(str, rc.get("disagree", ()))))
        res.velocity_noise = float(d.get("velocity_noise", 0.0))
        res.stick_speed = float(d.get("stick_speed", 0.0))
        res.n_stuck = int(d.get("n_stuck", 0))
        if "pass_rows" in d:
            res.pass_rows = _number(d["pass_rows"])
        if d.get("later_stretch") is not None:
            res.later = PredictionCheck.from_dict(d["later_stretch"])
        if d.get("terms") is not None:
            res.terms = TermFit.from_dict(d["terms"])
        if d.get("target") is not None:
            res.target = target_from_dict(d["target"])
        if "rms_error_vs_true" in d:
            res.rms_error_vs_true = _number(d["rms_error_vs_true"])
            res.rms_model_vs_true = _number(d.get("rms_model_vs_true"))
        if res.params is not None:  # what 'fit' writes, and nothing else (issue 53)
            check_model_params(res.params, "params")
        if res.terms is not None:
            check_terms(res.terms, model)
    except KeyError as exc:
        raise InputError(f"missing key {exc}") from None
    except (TypeError, ValueError, AttributeError) as exc:
        raise InputError(str(exc)) from None
    return res


def energy_to_dict(energy: JointEnergy) -> dict[str, Any]:
    """The energy check of one joint (eq. 7.9) as the parameters JSON records it."""
    return {"generating_share": finite_or_none(energy.generating_share), "tau_os_removed": energy.tau_os,
            "threshold": energy.threshold, "flagged": energy.flagged,
            **({"ripple_removed": True} if energy.ripple_removed else {})}


def write_params(path: str | Path, fits: Iterable[FitResult], header: Mapping[str, Any] | None = None,
                 extra: Mapping[str, Mapping[str, Any]] | None = None) -> None:
    """Write the parameters JSON, whole or not at all: the ``header`` keys (provenance, sign
    convention, a study's robot and gait...), then ``joints``: per joint :func:`fit_to_dict` and
    its ``extra`` keys (energy check, thesis numbering...).

    Raises:
        InputError: an output folder that does not exist.
    """
    extra = extra or {}
    joints = {f.joint: {**fit_to_dict(f), **extra.get(f.joint, {})} for f in fits}
    write_json(path, {**(header or {}), "joints": joints})


def read_params(path: str | Path) -> dict[str, FitResult]:
    """Fitted parameters written by :func:`write_params` (``wbfriction fit``, the demo), by joint name.

    Raises:
        InputError: a file that is not such JSON (named with the key at fault).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: file not found")
    try:
        doc = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not JSON: {exc}") from None
    joints = doc.get("joints") if isinstance(doc, dict) else None
    if not isinstance(joints, dict):
        raise InputError(f"{path}: no 'joints' object: not a parameter file from 'wbfriction fit'")
    out = {}
    for joint, d in joints.items():
        try:
            out[joint] = fit_from_dict(joint, d)
        except (InputError, AttributeError) as exc:
            raise InputError(f"{path}: joint '{joint}': {exc}") from None
    return out


def check_params_source(params: str | Path, est: FrictionEstimate, table: str | Path | None = None) -> None:
    """Refuse a parameters file (one :func:`read_params` has read) that does not belong with a
    friction table: fitted for another robot (the robots both record,
    :func:`~wbfriction.pipeline.provenance.log_provenance`), sharing none of its joints, or, with
    ``table`` (the file ``est`` was read from: a report of the table the parameters were fitted
    on), fitted on another table (its recorded SHA-256 differs).

    Raises:
        InputError: naming the parameters file and what does not match.
    """
    path = Path(params)
    doc = json.loads(path.read_text())  # read by read_params first: a parameters file
    prov = doc.get("provenance", {}) if isinstance(doc, dict) else {}
    prov = prov if isinstance(prov, dict) else {}
    robot, table_robot = prov.get("robot"), est.metadata.get("provenance", {}).get("robot")
    if robot is not None and table_robot is not None and robot != table_robot:
        raise InputError(f"{path}: parameters of robot '{robot}', not of the table's robot '{table_robot}'")
    joints = doc.get("joints", {}) if isinstance(doc, dict) else {}
    if not set(joints) & set(est.joints):
        raise InputError(f"{path}: none of its joints is a joint of the friction table")
    digest = prov.get("friction_sha256")
    if table is not None and digest is not None and digest != file_sha256(table):
        raise InputError(f"{path}: fitted on {prov.get('friction', 'another table')}, not on {table} (their "
                         "SHA-256 differ): fit this table, or give its own parameters")
