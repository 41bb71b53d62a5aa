"""The parameters JSON: the fitted model per joint, as a document (one writer, one reader).

The **parameters JSON** holds the fitted model per joint (:class:`~wbfriction.fit.result.FitResult`): its
name (``model``: ``coulomb-viscous``, ``stribeck`` or ``thesis`` (3.5)), parameters, standard errors, their
Cramér-Rao bounds (``crb``) and the torque noise they take (``torque_noise``), which parameters ended at a
bound (``at_bound``), which magnitudes the data press against their floor of zero (``pressed``), how far F_c and
F_v move between the candidate families (``model_spread``: with ``model="auto"``), the delete-one-block jackknife's
standard errors (``block_spread``, :mod:`~wbfriction.fit.block_spread`) and the share of the two routes' difference
read as the estimate's bias (``route_spread``, :mod:`~wbfriction.fit.route_spread`) (the standard error a user
reads: the larger of ``stderr`` and ``block_spread``, ``model_spread`` and ``route_spread`` in quadrature; a file
without the last two, of an earlier version, reads back without them), the
estimate's ``route`` and the same model on the other route (``route_check``: its parameters, standard errors, and
those that ``disagree``), the velocity noise the model's expectation took
(``velocity_noise``), the samples left out where the joint may stick (``stick_speed``, ``n_stuck``) and, when
the model was chosen by held-out error, how (``selection``). :func:`write_params` writes it (``wbfriction
fit`` and the studies), :func:`read_params` reads it (``wbfriction report --params``). A standard error that
is not finite (not identifiable) is written as ``null`` and read back as ``inf``; no number that is not finite is
written at all (``logs.tables.finite_json``: ``null``, its meaning the key's). Files written before the model
choice (no ``model`` key) hold model (3.5) and read back so.

What ``fit`` writes, its readers take (issue 63): :mod:`~wbfriction.fit.params_check` is what both sides hold to.
The fit's bounds keep its own parameters within it, and the terms' refit holds every magnitude of the velocity model
(F_v, F_c, F_cS, the Stribeck level F_s) at zero where the data would put it below
(:data:`~wbfriction.fit.term_design.NONNEGATIVE`, named in ``terms.at_bound``), so a file is refused only where it
is not ``fit``'s (hand-edited, damaged): at the writer, not by readers that would take a value ``fit`` should not
have written. ``tests/fit/test_roundtrip.py`` fits many tables and reads every file back.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.fit.energy import JointEnergy
from wbfriction.fit.holdout import PredictionCheck
from wbfriction.fit.params_check import check_model_params, check_terms
from wbfriction.fit.result import FitResult, HeldOutScore, ModelSelection, RouteCheck
from wbfriction.fit.terms import TermFit
from wbfriction.friction.decision import UNMEASURED
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import check_model, params_from_dict, target_from_dict
from wbfriction.logs.tables import file_sha256, write_json


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
                        "at_bound": list(c.at_bound), "unresolved": list(c.unresolved)}
                       for c in selection.scores]}


def selection_from_dict(d: Mapping[str, Any]) -> ModelSelection:
    """Inverse of :func:`selection_to_dict` (a ``null`` held-out RMS reads back as NaN).

    Raises:
        InputError: a missing key, an unknown model, a value of the wrong kind.
    """
    try:
        scores = tuple(HeldOutScore(check_model(c["model"], "selection.scores.model"),
                                    float("nan") if c.get("held_out_rms") is None else float(c["held_out_rms"]),
                                    tuple(map(str, c.get("at_bound", ()))), tuple(map(str, c.get("unresolved", ()))))
                       for c in d.get("scores", ()))
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
                         "at_bound": dict(fit.at_bound), "speed": fit.speed, "reverse": fit.reverse}
    if fit.pressed:
        d["pressed"] = {k: [clean(v), clean(se)] for k, (v, se) in fit.pressed.items()}
    if fit.model_spread:
        d["model_spread"] = {k: clean(v) for k, v in fit.model_spread.items()}
    if fit.block_spread:
        d["block_spread"] = {k: clean(v) for k, v in fit.block_spread.items()}
    if fit.route_spread:
        d["route_spread"] = {k: clean(v) for k, v in fit.route_spread.items()}
    if fit.params is not None and fit.covariance is not None:  # the curve's standard error at any speed
        d["covariance"] = [[clean(float(x)) for x in row] for row in fit.covariance]
    d["crb"] = {k: clean(v) for k, v in fit.crb.items()}
    d["torque_noise"] = fit.torque_noise
    d["route"] = fit.route
    if fit.route_check is not None:
        rc = fit.route_check
        d["route_check"] = {"route": rc.route, "params": rc.params,
                            "stderr": {k: clean(v) for k, v in rc.stderr.items()}, "disagree": list(rc.disagree)}
        if rc.block_spread:
            d["route_check"]["block_spread"] = {k: clean(v) for k, v in rc.block_spread.items()}
    d["velocity_noise"], d["stick_speed"], d["n_stuck"] = fit.velocity_noise, fit.stick_speed, fit.n_stuck
    d["pass_rows"] = clean(fit.pass_rows)  # null: every reversal that changes sign passes
    if fit.later is not None:
        d["later_stretch"] = fit.later.to_dict()
    if fit.unmeasured:  # never ok then: a reader's verdict must be the one written (issue 82)
        d["unmeasured"] = fit.unmeasured
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
    if fit.fallback is not None:
        d["fallback"] = fit_to_dict(fit.fallback)
    return d


def fit_from_dict(joint: str, d: Mapping[str, Any]) -> FitResult:
    """Inverse of :func:`fit_to_dict` (a ``null`` standard error reads back as ``inf``: not
    identifiable). Without ``model`` (files of earlier versions) the parameters are those of (3.5);
    without ``at_bound``, no parameter is known to be at a bound (an empty table); without ``speed``, how much
    the joint moved is not known. ``status`` is not read: it follows from the rest (:meth:`FitResult.verdict
    <wbfriction.fit.result.FitResult.verdict>`), all written, ``unmeasured`` too (:func:`written_unmeasured`): every
    reader gives the fit the status ``fit`` wrote. The values are held to what ``fit`` writes
    (:mod:`~wbfriction.fit.params_check`: dissipative parameters, terms whole and consistent with the model).

    Raises:
        InputError: an unknown model, unknown parameter names (or ``at_bound`` names that are not
            the model's), a value that is not a number, a value :mod:`~wbfriction.fit.params_check` refuses
            (naming its key).
    """
    try:
        model = check_model(str(d.get("model", "thesis")))
        res: FitResult = FitResult(joint=joint, n_samples=int(d.get("n_samples", 0)),
                                   n_screened=int(d.get("n_screened", 0)),
                                   success=bool(d.get("success", False)), message=str(d.get("message", "")),
                                   rms_residual=_number(d.get("rms_residual")), model=model,
                                   speed=None if d.get("speed") is None else _number(d["speed"]),
                                   reverse=None if d.get("reverse") is None else _number(d["reverse"]))
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
        res.pressed = {str(k): (_number(v[0]), _number(v[1])) for k, v in (d.get("pressed") or {}).items()}
        res.model_spread = {str(k): _number(v) for k, v in (d.get("model_spread") or {}).items()}
        res.block_spread = {str(k): _number(v) for k, v in (d.get("block_spread") or {}).items()}
        res.route_spread = {str(k): _number(v) for k, v in (d.get("route_spread") or {}).items()}
        if d.get("selection") is not None:
            res.selection = selection_from_dict(d["selection"])
        res.crb = {str(k): _number(v) for k, v in (d.get("crb") or {}).items()}
        res.torque_noise = None if d.get("torque_noise") is None else float(d["torque_noise"])
        res.route = str(d.get("route", "acceleration"))
        if d.get("route_check") is not None:
            rc = d["route_check"]
            res.route_check = RouteCheck(str(rc["route"]), None if rc.get("params") is None else
                                         {str(k): _number(v) for k, v in rc["params"].items()},
                                         {str(k): _number(v) for k, v in (rc.get("stderr") or {}).items()},
                                         tuple(map(str, rc.get("disagree", ()))),
                                         {str(k): _number(v) for k, v in (rc.get("block_spread") or {}).items()})
        res.unmeasured = written_unmeasured(d)
        res.velocity_noise = float(d.get("velocity_noise") or 0.0)  # null (not measured): none taken
        res.stick_speed = float(d.get("stick_speed") or 0.0)
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
        if d.get("fallback") is not None:
            try:
                res.fallback = fit_from_dict(joint, d["fallback"])
            except InputError as exc:
                raise InputError(f"fallback: {exc}") from None
    except KeyError as exc:
        raise InputError(f"missing key {exc}") from None
    except (TypeError, ValueError, AttributeError) as exc:
        raise InputError(str(exc)) from None
    return res


def written_unmeasured(d: Mapping[str, Any]) -> str:
    """Why a joint's estimate had no measured noise (:attr:`~wbfriction.fit.result.FitResult.unmeasured`), as its
    entry ``d`` says it: its ``unmeasured``; in a file of an earlier version, which wrote only the status, the part of
    a ``weak`` status's reason that says so (:data:`~wbfriction.fit.status.UNMEASURED`); "" for none."""
    if d.get("unmeasured") is not None:
        return str(d["unmeasured"])
    if d.get("status") != "weak":
        return ""
    first = str(d.get("status_reason") or "").split("; ")[0]
    return first if first.startswith(UNMEASURED) else ""


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


def not_finite(doc: Any, key: str = "") -> tuple[str, Any] | None:
    """The first value of a JSON document ``doc`` that is a number but not finite, and its key (``a.b[2].c``), or
    None: a ``NaN``, ``Infinity`` or ``-Infinity`` (which JSON does not have and Python writes), a number too large
    for a float (``1e999``), or a string that spells one (``"nan"``, ``"inf"``). No file the package writes holds
    one (:func:`~wbfriction.logs.tables.finite_json` writes ``null``, its meaning the key's), whatever its key."""
    if isinstance(doc, dict):
        items: Iterable[tuple[str, Any]] = ((f"{key}.{k}" if key else str(k), v) for k, v in doc.items())
    elif isinstance(doc, list):
        items = ((f"{key}[{i}]", v) for i, v in enumerate(doc))
    else:
        if isinstance(doc, float) and not math.isfinite(doc):
            return key, doc
        if isinstance(doc, str):
            try:
                return (key, doc) if not math.isfinite(float(doc)) else None
            except ValueError:
                return None
        return None
    for k, v in items:
        if (found := not_finite(v, k)) is not None:
            return found
    return None


def read_params(path: str | Path) -> dict[str, FitResult]:
    """Fitted parameters written by :func:`write_params` (``wbfriction fit``, the demo), by joint name.

    Raises:
        InputError: a file that is not such JSON (named with the key at fault); a value that is a number but not
            finite, whatever its key (:func:`not_finite`: ``fit`` writes ``null`` there), naming the file, the joint
            and the key.
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
    if (bad := not_finite({k: v for k, v in doc.items() if k != "joints"})) is not None:
        raise InputError(f"{path}: {bad[0]} is {bad[1]!r}: not a finite number ('fit' writes null there)")
    out = {}
    for joint, d in joints.items():
        where = f"{path}: joint '{joint}': "
        if (bad := not_finite(d)) is not None:
            raise InputError(f"{where}{bad[0]} is {bad[1]!r}: not a finite number ('fit' writes null where a value is "
                             "not finite)")
        try:
            out[joint] = fit_from_dict(joint, d)
        except (InputError, AttributeError) as exc:
            raise InputError(f"{path}: joint '{joint}': {exc}") from None
    return out


def params_robot(params: str | Path) -> tuple[str | None, str | None]:
    """The robot a parameters file (one :func:`read_params` has read) was fitted for: its provenance's ``robot``
    and ``urdf`` (:func:`~wbfriction.pipeline.provenance.log_provenance`), each None where it records none."""
    doc = json.loads(Path(params).read_text())
    prov = doc.get("provenance", {}) if isinstance(doc, dict) else {}
    prov = prov if isinstance(prov, dict) else {}
    name, urdf = prov.get("robot"), prov.get("urdf")
    return (name if isinstance(name, str) else None), (urdf if isinstance(urdf, str) else None)


def same_model_file(recorded: str | None, urdf: str | Path) -> bool:
    """Whether the model file a provenance recorded is ``urdf``: the same path, or the same bytes."""
    if recorded is None:
        return False
    a, b = Path(recorded), Path(urdf)
    try:
        return a.resolve() == b.resolve() or (a.is_file() and b.is_file() and a.read_bytes() == b.read_bytes())
    except OSError:
        return False


def check_params_robot(params: str | Path, robot: str | None, urdf: str | Path | None = None,
                       whose: str = "") -> None:
    """Refuse a parameters file (one :func:`read_params` has read) fitted for another robot than ``robot`` (model
    file ``urdf``): the file's recorded robot differs from it both by name and by model file (two TOMLs of one URDF,
    ``panda`` and ``panda_pd``, are one robot). Nothing is refused where either side records no robot. ``whose``:
    the words before the robot's name in the message (e.g. "the table's ").

    Raises:
        InputError: naming the file, both robots and their model files.
    """
    name, fitted_urdf = params_robot(params)
    if name is None or robot is None or name == robot or (urdf is not None and same_model_file(fitted_urdf, urdf)):
        return
    raise InputError(f"{params}: parameters of robot '{name}' ({fitted_urdf or 'its model file not recorded'}), "
                     f"not of {whose}'{robot}' ({urdf or 'its model file not recorded'}): give the robot model they "
                     "were fitted with")


def read_robot_params(params: str | Path, robot: str, joints: Iterable[str],
                      urdf: str | Path | None = None) -> dict[str, FitResult]:
    """:func:`read_params` for the robot named ``robot`` (model file ``urdf``) whose joints are ``joints``: the one
    check wherever a parameters file meets a robot model (export, rollout). Two robots of one class share their
    joints' names (a Go2 and an Aliengo), so the joints alone do not tell them apart: the file's recorded robot must
    be this one, by its name or its model file (the same URDF under another TOML's name is the same robot).

    Raises:
        InputError: what :func:`read_params` raises; a file fitted for another robot; a joint ``robot`` lacks (each
            naming the file).
    """
    fits = read_params(params)
    check_params_robot(params, robot, urdf)
    known = set(joints)
    unknown = [j for j in fits if j not in known]
    if unknown:
        raise InputError(f"{params}: joint '{unknown[0]}' is not an actuated joint of robot '{robot}'")
    return fits


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
    made = est.metadata.get("provenance", {})
    made = made if isinstance(made, dict) else {}
    check_params_robot(path, made.get("robot"), made.get("urdf"), whose="the table's robot ")
    joints = doc.get("joints", {}) if isinstance(doc, dict) else {}
    if not set(joints) & set(est.joints):
        raise InputError(f"{path}: none of its joints is a joint of the friction table")
    digest = prov.get("friction_sha256")
    if table is not None and digest is not None and digest != file_sha256(table):
        raise InputError(f"{path}: fitted on {prov.get('friction', 'another table')}, not on {table} (their "
                         "SHA-256 differ): fit this table, or give its own parameters")
