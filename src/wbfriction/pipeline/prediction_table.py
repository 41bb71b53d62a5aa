"""The prediction table: what ``wbfriction predict --table`` writes, sample by sample and joint by joint, the torque
a model predicts against the measured one (one writer, one reader of its summary).

Columns (wide, one set per joint, as the friction table's): ``time`` [s] from the log's first sample; per joint
``<j>``: ``valid.<j>`` (the samples ``predict`` scores), ``qd.<j>`` [rad/s], the measured torque ``tau.<j>`` [N·m]
and the one predicted ``tau_pred.<j>`` [N·m] (a table without the measured torques, written before they were kept,
has neither), the friction estimated ``tau_f.<j>`` [N·m] (the friction table's: ``M qdd + h - tau``) and the one the
model predicts ``tau_f_pred.<j>`` [N·m], and ``residual.<j>`` = ``tau - tau_pred`` = ``tau_f_pred - tau_f`` [N·m],
whose RMS over the valid samples is the ``friction`` column ``predict`` prints. The metadata (key ``wbfriction``)
holds the units, the sign convention, the sources, the log's first stamp, its runs and the per-joint summary
(:func:`prediction_table`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path
from typing import Any, cast

import numpy as np
import pyarrow as pa

from wbfriction.fit.predict import FrictionCurve, TorquePrediction, predicted_friction
from wbfriction.fit.terms import TermFit
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.logs.metadata import read_metadata, with_metadata
from wbfriction.logs.runs import log_runs
from wbfriction.logs.tables import file_sha256, finite_json

KIND = "wbfriction prediction table"
"""The metadata's ``kind``: what the file is."""

UNITS = {"time": "s", "valid.<j>": "0/1", "qd.<j>": "rad/s", "tau.<j>": "N·m", "tau_pred.<j>": "N·m",
         "tau_f.<j>": "N·m", "tau_f_pred.<j>": "N·m", "residual.<j>": "N·m"}
"""The unit of each column (``<j>``: a joint's name), as the metadata's ``units`` holds them."""

COLUMNS = {
    "time": "time from the log's first sample (its stamp: time_origin)",
    "valid.<j>": "the samples predict scores (the friction table's valid, where the model has a value)",
    "qd.<j>": "the joint's velocity, through the estimate's scheme",
    "tau.<j>": "the measured torque",
    "tau_pred.<j>": "the torque the model predicts, M qdd + h + f(qd): tau + tau_f - tau_f_pred",
    "tau_f.<j>": "the friction estimated, M qdd + h - tau (the friction table's)",
    "tau_f_pred.<j>": "the friction the model predicts, -f(qd) (its terms beyond velocity included; through the "
                      "estimate's smoother where it has one)",
    "residual.<j>": "measured less predicted torque, tau - tau_pred = tau_f_pred - tau_f",
}
"""What each column holds, as the metadata's ``columns`` holds it."""

SIGN_CONVENTION = "tau_f = -f(qd): the torque friction exerts on the joint; residual = measured - predicted"

def _joint_summary(pred: TorquePrediction, i: int, model: str) -> dict[str, Any]:
    check = pred.checks[i] if pred.checks else None
    return {"model": model, "samples": int(pred.samples[i]), "rms_rigid_body": float(pred.rms_rigid_body[i]),
            "rms": float(pred.rms[i]), "status": pred.status[i] if pred.status else "",
            "terms": list(pred.terms[i]) if pred.terms else [],
            "moving_rms": None if check is None else check.rms,
            "allowed": None if check is None else check.allowed,
            "predicts": None if check is None else check.predicts}


def prediction_table(est: FrictionEstimate, models: Mapping[str, FrictionCurve | TermFit], pred: TorquePrediction,
                     sources: Mapping[str, str | Path] | None = None,
                     families: Mapping[str, str] | None = None) -> pa.Table:
    """The prediction table (module docstring) of the joints of ``est`` that ``models`` predicts.

    Args:
        est: the friction estimate of the log predicted (N samples).
        models: joint -> friction model, as :func:`~wbfriction.fit.predict.predict_torques` took them.
        pred: what :func:`~wbfriction.fit.predict.predict_torques` (and its checks) made of them: the metadata's
            per-joint summary (``joints``: ``model``, the family of ``families``, ``samples``, ``rms_rigid_body``,
            ``rms``, ``moving_rms``, ``allowed`` [N·m], ``predicts``, ``status``, ``terms``).
        sources: the files read, by role (``friction``, ``params``): recorded with their SHA-256.
        families: joint -> the family of its model (``coulomb-viscous``...), for the summary ("" if not given).

    Returns:
        The Arrow table, N rows; the metadata also holds ``time_origin`` (the log's first stamp [s]), ``runs``
        (:func:`~wbfriction.logs.runs.log_runs`, row ranges) and ``order`` (the joints, in the log's order).
    """
    cols: dict[str, Any] = {"time": est.time - est.time[0] if len(est.time) else est.time}
    joints = [j for j in est.joints if j in models]
    for joint in joints:
        i = est.joints.index(joint)
        valid = est.valid[:, i] & np.isfinite(est.tau_f[:, i])
        model = predicted_friction(est, i, models[joint], valid)
        valid &= np.isfinite(model)
        cols[f"valid.{joint}"] = valid
        cols[f"qd.{joint}"] = est.qd[:, i]
        if est.tau is not None:
            cols[f"tau.{joint}"] = est.tau[:, i]
            cols[f"tau_pred.{joint}"] = est.tau[:, i] + est.tau_f[:, i] - model
        cols[f"tau_f.{joint}"] = est.tau_f[:, i]
        cols[f"tau_f_pred.{joint}"] = model
        cols[f"residual.{joint}"] = model - est.tau_f[:, i]
    index = {j: k for k, j in enumerate(pred.joints)}
    metadata = {"kind": KIND, "units": UNITS, "columns": COLUMNS, "sign_convention": SIGN_CONVENTION,
                "time_origin": float(est.time[0]) if len(est.time) else 0.0,
                "runs": [[r.rows.start, r.rows.stop] for r in log_runs(est.time)], "order": joints,
                "robot": est.metadata.get("provenance", {}).get("robot"),
                "sources": {role: {"file": Path(path).name, "sha256": file_sha256(path)}
                            for role, path in (sources or {}).items()},
                "joints": {j: _joint_summary(pred, index[j], (families or {}).get(j, "")) for j in joints}}
    return with_metadata(pa.table(cols), cast(dict, finite_json(metadata)))


@dataclasses.dataclass(frozen=True)
class PredictionSummary:
    """What a prediction table's metadata says (:func:`prediction_table`).

    Attributes:
        joints: the joints predicted, in the log's order.
        runs: the log's runs, half-open row ranges.
        summary: joint -> its per-joint summary (``model``, ``samples``, ``rms_rigid_body``, ``rms``, ``moving_rms``,
            ``allowed`` [N·m] or None, ``predicts``, ``status``, ``terms``).
        metadata: the whole metadata.
    """

    joints: tuple[str, ...]
    runs: tuple[tuple[int, int], ...]
    summary: dict[str, dict[str, Any]]
    metadata: dict[str, Any]


def read_prediction_summary(table: pa.Table, source: str = "<table>") -> PredictionSummary:
    """The metadata of a prediction table (:class:`PredictionSummary`).

    Raises:
        InputError: a table that is not a prediction table (its metadata's ``kind``), naming ``source``.
    """
    from wbfriction.exceptions import InputError

    meta = read_metadata(table, source)
    if meta.get("kind") != KIND:
        raise InputError(f"{source}: not a prediction table ('wbfriction predict --table')")
    runs = tuple((int(a), int(b)) for a, b in meta.get("runs") or [(0, table.num_rows)])
    return PredictionSummary(tuple(meta.get("order", ())), runs, dict(meta.get("joints", {})), meta)
