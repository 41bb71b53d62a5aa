"""Files in, numbers out: how well a model (the URDF a friction table was estimated with, and fitted
friction parameters) predicts the torques of a log, typically one it was not fitted on."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pyarrow as pa

from wbfriction.fit.params_file import check_params_source, read_params
from wbfriction.fit.predict import TorquePrediction, other_log_checks, predict_torques
from wbfriction.friction.io import read_friction_file
from wbfriction.logs.formats import format_to_write
from wbfriction.logs.tables import write_table
from wbfriction.pipeline.prediction_table import prediction_table


def predict_file(friction: str | Path, params: str | Path, workers: int = 1) -> TorquePrediction:
    """:func:`predict_table` without its table."""
    return predict_table(friction, params, workers)[0]


def predict_table(friction: str | Path, params: str | Path, workers: int = 1,
                  table: str | Path | None = None) -> tuple[TorquePrediction, pa.Table]:
    """Torque prediction errors (:func:`~wbfriction.fit.predict.predict_torques`) of the friction
    model ``params`` on the friction table ``friction``.

    Args:
        friction: a friction table (``wbfriction estimate`` of the held-out log, with the URDF
            whose inertias are tested).
        params: the parameters JSON (``wbfriction fit`` of the training logs' table, estimated
            with the same URDF); a joint's terms beyond velocity, where kept, predict with it (ripple included).
        table: where to write the prediction table (:mod:`~wbfriction.pipeline.prediction_table`: Parquet, or the
            format its name claims, as :func:`~wbfriction.logs.tables.write_table`), whole or not at all; None: not
            written.

    Returns:
        The prediction's errors per joint, and the prediction table sample by sample.

    Raises:
        InputError: what reading either file raises; parameters for another robot or none of
            the table's joints (:func:`~wbfriction.fit.params_file.check_params_source`); a ``table`` name whose
            format writes no file (before any work).
        OutputError: the system refused the table's write.

    Each joint's prediction is checked against what its noise and its fit's standard errors allow on this log
    (:func:`~wbfriction.fit.predict.other_log_checks`, refitting its model on ``friction`` on ``workers``
    processes): :attr:`~wbfriction.fit.predict.TorquePrediction.checks`.
    """
    if table is not None:
        format_to_write(table)
    fits = read_params(params)
    est = read_friction_file(friction)
    check_params_source(params, est)
    models = {j: f.kept_terms or f.params for j, f in fits.items()
              if f.params is not None}
    pred = predict_torques(est, models, source=str(friction))
    status = tuple(fits[j].verdict().status if j in fits else "" for j in pred.joints)
    checks = other_log_checks(est, fits, Path(friction).name, workers)
    pred = dataclasses.replace(pred, status=status, checks=checks)
    samples = prediction_table(est, models, pred, {"friction": friction, "params": params},
                               {j: f.model for j, f in fits.items()})
    if table is not None:
        write_table(samples, table)
    return pred, samples
