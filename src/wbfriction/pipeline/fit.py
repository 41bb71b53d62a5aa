"""Files in, files out: a friction table fitted joint by joint, with the energy check, into the parameters JSON."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from wbfriction.friction.energy import DEFAULT_THRESHOLD, DEFAULT_TOLERANCE, JointEnergy, energy_consistency
from wbfriction.friction.fit import FitResult, fit_estimate, fitted_offsets
from wbfriction.friction.io import SIGN_CONVENTION, energy_to_dict, read_friction_file, write_params
from wbfriction.pipeline.provenance import file_provenance


@dataclass
class FittedFile:
    """What :func:`fit_file` fitted and checked (per torque-controlled joint of the table)."""

    fits: list[FitResult]
    energy: list[JointEnergy]


def fit_file(friction: str | Path, output: str | Path, *, min_samples: int = 20,
             threshold: float = DEFAULT_THRESHOLD, tolerance: float = DEFAULT_TOLERANCE,
             workers: int = 1) -> FittedFile:
    """Fit model (3.5) to every joint of a friction table (:func:`~wbfriction.friction.fit.fit_joints`,
    on ``workers`` processes), check energy (eq. 7.9), and write the parameters JSON with its
    provenance, whole or not at all.

    Raises:
        InputError: an unreadable or malformed friction table, an output folder that does not exist.
    """
    est = read_friction_file(friction)
    fits = fit_estimate(est, min_samples=min_samples, workers=workers)
    energy = energy_consistency(est, fitted_offsets(fits), threshold, tolerance)
    header = {"provenance": file_provenance("friction", friction), "sign_convention": SIGN_CONVENTION}
    write_params(output, fits, header, {e.joint: {"energy": energy_to_dict(e)} for e in energy})
    return FittedFile(fits, energy)
