"""The report computed: ``wbfriction report`` reads a friction table (and parameters, an identification), fits
and checks what is not given, and gathers what the HTML shows (:mod:`wbfriction.report.html` renders it).

The report shows, for a person to judge a friction table at a glance:

* a summary: one row per joint that moved (its label, fit status, F_c, F_v, tau_os with standard errors,
  energy share, valid samples, verdict), the joints that did not move in one line, and the
  energy-consistency warnings (:mod:`wbfriction.fit.energy`, eq. 7.9);
* the friction clouds of the joints that moved as small multiples, each on its own axes, with the
  fitted model (3.5) and the target where known;
* the identified parameters with their standard errors (6.2.2), and the errors against the
  targets of a simulated log;
* where fits kept terms beyond velocity, those terms, the conditions their F_c, F_v hold at and the ranges they were
  fitted on (:mod:`wbfriction.report.terms`);
* the energy-consistency table (share of power-generating samples, zero crossings of
  ``Delta qdd`` against those of the velocity, Fig. 7.4);
* per joint: the cloud, ``tau_f`` over time by support phase, Fig. 7.4 with and without
  filtering, and the spectrum of the estimated acceleration (Fig. 7.1);
* the inertia identification of ``wbfriction identify --json``, when given;
* the provenance: input files with their SHA-256, robot, options, every dependency's version, the date.

Joints are named by their labels (``[labels]`` of the robot TOML, recorded in the friction table by
``estimate``; :mod:`wbfriction.model.labels`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from wbfriction.fit.energy import JointEnergy, energy_consistency
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import DEFAULT_THRESHOLD, DEFAULT_TOLERANCE
from wbfriction.fit.params_file import check_params_source, read_params
from wbfriction.fit.result import FitResult, fitted_offsets, fitted_ripples
from wbfriction.fit.status import MIN_SPEED, joint_speed
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.io import read_friction_file
from wbfriction.inertia.document import Identification
from wbfriction.inertia.io import read_identification
from wbfriction.logs.tables import file_sha256
from wbfriction.model.labels import default_label
from wbfriction.pipeline.provenance import dependency_versions, output_date
from wbfriction.signals.spectrum import MIN_SAMPLES, joint_spectra, longest_run
from wbfriction.version import __version__


def acceleration_spectra(est: FrictionEstimate, tail: float = 0.01) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """Spectrum of the estimated acceleration ``qdd_est = qdd - Delta qdd`` (5.10) of every joint
    over the longest stretch where it is defined for all joints, and its suggested cutoff
    (Fig. 7.1, :func:`~wbfriction.signals.spectrum.suggest_cutoff`); {} when the table lacks the columns
    or the stretch is shorter than 64 samples."""
    if est.qdd is None or est.delta_qdd is None:
        return {}
    qdd_est = est.qdd - est.delta_qdd
    a, b = longest_run(np.isfinite(qdd_est).all(axis=1))
    if b - a < MIN_SAMPLES:
        return {}
    freq, amp, cutoff = joint_spectra(qdd_est[a:b], float(np.median(np.diff(est.time))), tail)
    return {j: (freq, amp[:, i], float(cutoff[i])) for i, j in enumerate(est.joints)}


def joint_moved(est: FrictionEstimate, joint: str) -> bool:
    """Whether ``joint`` moved in its valid samples: the 95th percentile of ``|qd|`` there at least
    :data:`~wbfriction.fit.status.MIN_SPEED` (the fit's "not excited" criterion)."""
    i = est.joints.index(joint)
    return joint_speed(est.qd[est.valid[:, i], i]) >= MIN_SPEED


def _options_text(options: dict) -> str:
    """Options as ``name value`` pairs, comma separated, nested ones in parentheses (what a person reads, not
    JSON)."""
    return ", ".join(f"{k} ({_options_text(v)})" if isinstance(v, dict) else f"{k} {v}"
                     for k, v in sorted(options.items()) if v is not None)


@dataclass
class Report:
    """What a report shows, computed; :meth:`html` renders it.

    Attributes:
        est: the estimate read from the friction table.
        fits: fitted parameters by joint (from ``--params`` or fitted here).
        energy: energy consistency by joint.
        provenance: (label, value) pairs: inputs, robot, options.
        threshold: share of power-generating samples above which a joint is flagged.
        identification: what ``wbfriction identify --json`` wrote, or None.
        labels: joint -> the label a person reads.
        versions: (name, version) of wbfriction, Python and the dependencies.
        date: the date the report was made (:func:`~wbfriction.pipeline.provenance.output_date`).
    """

    est: FrictionEstimate
    fits: dict[str, FitResult]
    energy: dict[str, JointEnergy]
    provenance: list[tuple[str, str]]
    threshold: float
    identification: Identification | None = None
    labels: dict[str, str] | None = None
    versions: tuple[tuple[str, str], ...] = ()
    date: str = ""

    @property
    def flagged(self) -> list[JointEnergy]:
        return [e for e in self.energy.values() if e.flagged and e.joint in self.moved]

    @cached_property
    def moved(self) -> tuple[str, ...]:
        """The joints that moved (:func:`joint_moved`), in table order: those the report shows."""
        return tuple(j for j in self.est.joints if joint_moved(self.est, j))

    @property
    def still(self) -> tuple[str, ...]:
        """The joints that did not move: one line in the report."""
        moved = set(self.moved)
        return tuple(j for j in self.est.joints if j not in moved)

    def label(self, joint: str) -> str:
        """What a person reads for ``joint``."""
        return (self.labels or {}).get(joint) or default_label(joint)


def make_report(friction: str | Path, params: str | Path | None = None,
                threshold: float = DEFAULT_THRESHOLD, tolerance: float = DEFAULT_TOLERANCE,
                identification: str | Path | None = None, workers: int = 1) -> Report:
    """Read a friction table (and parameters, else fit them on ``workers`` processes,
    :func:`~wbfriction.fit.joints.fit_estimate`; and an identification of the inertia model,
    :func:`~wbfriction.inertia.io.read_identification`) and compute the report.

    Raises:
        InputError: unreadable inputs; parameters fitted on another table or for another robot
            (:func:`~wbfriction.fit.params_file.check_params_source`).
    """
    friction = Path(friction)
    ident = None if identification is None else read_identification(identification)
    est = read_friction_file(friction)
    if params is not None:
        fits = read_params(params)
        check_params_source(params, est, friction)
    else:
        fits = {f.joint: f for f in fit_estimate(est, workers=workers)}
    energy = {e.joint: e for e in energy_consistency(est, fitted_offsets(fits.values()), threshold, tolerance,
                                                         fitted_ripples(est, fits.values(), str(friction)))}
    meta = est.metadata
    prov: list[tuple[str, str]] = [("friction table", f"{friction} (sha256 {file_sha256(friction)})")]
    if params is not None:
        prov.append(("parameters", f"{params} (sha256 {file_sha256(params)})"))
    else:
        prov.append(("parameters", "fitted by the report (no --params given)"))
    source = dict(meta.get("provenance", {}))
    if source.get("log"):
        prov.append(("log", f"{source['log']} (sha256 {source.get('log_sha256', '?')})"))
    elif meta.get("source"):
        prov.append(("log", str(meta["source"])))
    prov.append(("robot", str(source.get("robot") or meta.get("robot", "?"))))
    if source.get("urdf"):
        prov.append(("robot model (URDF or MJCF)", str(source["urdf"])))
    if "estimate_options" in meta:
        prov.append(("estimate options", _options_text(meta["estimate_options"])))
    if est.companion_diff:
        prov.append(("companion scheme (Fig. 7.4)", est.companion_diff))
    if source.get("wbfriction"):
        prov.append(("estimated with", f"wbfriction {source['wbfriction']}"))
    prov.append(("report", f"wbfriction {__version__}; energy threshold {100 * threshold:g} %, "
                               f"tolerance {tolerance:g} N·m"))
    if identification is not None:
        prov.append(("inertia identification", f"{identification} (sha256 {file_sha256(identification)})"))
    labels = meta.get("joint_labels")
    fits = {j: f.reported() for j, f in fits.items()}  # with terms, the refitted model the status is about
    return Report(est, fits, energy, prov, threshold, ident, dict(labels) if isinstance(labels, dict) else None,
                  tuple(dependency_versions()), output_date())
