"""Files in, files out: a friction table fitted joint by joint, with the energy check, into the parameters JSON."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from wbfriction.exceptions import InputError
from wbfriction.fit.energy import JointEnergy, energy_consistency
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import AUTO, DEFAULT_THRESHOLD, DEFAULT_TOLERANCE, FitOptions
from wbfriction.fit.params_file import energy_to_dict, write_params
from wbfriction.fit.result import FitResult, fitted_offsets, fitted_ripples
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.io import SIGN_CONVENTION, read_friction_file
from wbfriction.pipeline.provenance import file_provenance
from wbfriction.progress import Steps


@dataclass
class FittedFile:
    """What :func:`fit_file` fitted and checked (per torque-controlled joint of the table), and the table read."""

    fits: list[FitResult]
    energy: list[JointEnergy]
    est: FrictionEstimate


def fit_table(friction: str | Path, options: FitOptions = FitOptions(), *, threshold: float = DEFAULT_THRESHOLD,
              tolerance: float = DEFAULT_TOLERANCE, workers: int = 1, progress: Steps | None = None) -> FittedFile:
    """:func:`fit_file` without writing: the table read, every joint fitted, the energy checked.

    Raises:
        InputError: as :func:`fit_file`.
    """
    est = read_friction_file(friction)
    fits = fit_estimate(est, options, workers=workers, progress=progress)
    if not any(f.params is not None for f in fits):
        raise InputError(f"{friction}: no joint could be fitted (each has fewer than --min-samples "
                         f"{options.min_samples} valid samples); nothing written")
    return FittedFile(fits, energy_consistency(est, fitted_offsets(fits), threshold, tolerance,
                                               fitted_ripples(est, fits)), est)


def fit_file(friction: str | Path, output: str | Path, options: FitOptions = FitOptions(), *,
             threshold: float = DEFAULT_THRESHOLD, tolerance: float = DEFAULT_TOLERANCE,
             workers: int = 1, progress: Steps | None = None) -> FittedFile:
    """Fit a friction model to every joint of a friction table (:func:`~wbfriction.fit.joints.fit_joints`,
    on ``workers`` processes), check energy (eq. 7.9), and write the parameters JSON with its
    provenance and the model asked for, whole or not at all.

    Args:
        friction: the friction table (``wbfriction estimate``).
        output: the parameters JSON to write.
        options: the model, its choice and thresholds (:class:`~wbfriction.fit.options.FitOptions`; by
            default ``auto``: per joint the simplest model whose held-out RMS is within its
            ``selection_tolerance`` of the best, the reason recorded; see :mod:`wbfriction.fit`).
        threshold, tolerance: of the energy check (:func:`~wbfriction.fit.energy.energy_consistency`).
        workers: processes fitting joints side by side.
        progress: told of the fit's stages, counted in joints (:func:`~wbfriction.fit.joints.fit_estimate`).

    Raises:
        InputError: an unreadable or malformed friction table, a table where no joint has
            ``options.min_samples`` valid samples (nothing is written), an output folder that does not exist.
    """
    fitted = fit_table(friction, options, threshold=threshold, tolerance=tolerance, workers=workers, progress=progress)
    log = fitted.est.metadata.get("provenance", {})
    header: dict[str, object] = {"provenance": {**file_provenance("friction", friction),
                                                **{k: log[k] for k in ("robot", "urdf") if k in log},
                                                **{k: fitted.est.metadata[k] for k in ("torque_source",)
                                                   if k in fitted.est.metadata}},
                                 "sign_convention": SIGN_CONVENTION, "model": options.model}
    if options.model == AUTO:
        header["selection_tolerance"] = options.selection_tolerance
    write_params(output, fitted.fits, header, {e.joint: {"energy": energy_to_dict(e)} for e in fitted.energy})
    return fitted
