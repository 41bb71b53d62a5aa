"""Files in, numbers out: how well a model (the URDF a friction table was estimated with, and fitted
friction parameters) predicts the torques of a log, typically one it was not fitted on."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from wbfriction.fit.params_file import check_params_source, read_params
from wbfriction.fit.predict import TorquePrediction, other_log_checks, predict_torques
from wbfriction.friction.io import read_friction_file


def predict_file(friction: str | Path, params: str | Path, workers: int = 1) -> TorquePrediction:
    """Torque prediction errors (:func:`~wbfriction.fit.predict.predict_torques`) of the friction
    model ``params`` on the friction table ``friction``.

    Args:
        friction: a friction table (``wbfriction estimate`` of the held-out log, with the URDF
            whose inertias are tested).
        params: the parameters JSON (``wbfriction fit`` of the training logs' table, estimated
            with the same URDF); a joint's terms beyond velocity, where kept, predict with it (ripple included).

    Raises:
        InputError: what reading either file raises; parameters for another robot or none of
            the table's joints (:func:`~wbfriction.fit.params_file.check_params_source`).

    Each joint's prediction is checked against what its noise and its fit's standard errors allow on this log
    (:func:`~wbfriction.fit.predict.other_log_checks`, refitting its model on ``friction`` on ``workers``
    processes): :attr:`~wbfriction.fit.predict.TorquePrediction.checks`.
    """
    fits = read_params(params)
    est = read_friction_file(friction)
    check_params_source(params, est)
    models = {j: f.kept_terms or f.params for j, f in fits.items()
              if f.params is not None}
    pred = predict_torques(est, models, source=str(friction))
    status = tuple(fits[j].verdict().status if j in fits else "" for j in pred.joints)
    checks = other_log_checks(est, fits, Path(friction).name, workers)
    return dataclasses.replace(pred, status=status, checks=checks)
