"""Two routes on the same samples: the measured one against the rigid-contact one (issue 23, item 4).

Where the sensors' route (:mod:`wbfriction.friction.measured`) and the thesis's rigid-contact route both
estimate a sample (single support), their difference per joint, ``tau_f(measured) - tau_f(contact)``
[N·m], is written beside the estimate (``disagreement.<joint>``). Both routes see the same torques and
accelerations; what tells them apart is what each assumes: the rigid route that the stance sole is
welded flat to the ground, the wrench route that the sensors and the inertia model are right. A large
disagreement (RMS above :data:`LARGE` of the friction's own RMS) is given its likeliest cause
(:func:`likely_cause`):

* mostly a constant (its mean above half its RMS): an **offset** — a force-torque sensor's or a torque
  sensor's;
* following the joint's acceleration (correlation above 0.5): a **wrong inertia** (the two routes weigh
  the inertia model differently: the rigid one through the stance leg, the wrench one through the whole
  body);
* otherwise: **neither**, and the check does not pretend to know which: a stance foot that moves (a rocking or
  compliant sole, which breaks the rigid route's premise and not the sensors'), an inertia error spread over the
  other joints' accelerations, or a sensor that drifts. Nothing in the two routes' difference alone tells these
  apart (issue 65: the foot was blamed where the model or a sensor was at fault).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

MIN_SAMPLES = 50
"""Fewer common samples than this: no verdict."""
LARGE = 0.1
"""A disagreement whose RMS exceeds this share of the friction's RMS gets a likely cause."""


@dataclass(frozen=True)
class RouteCheck:
    """One joint's disagreement between the measured and the rigid-contact route.

    Attributes:
        joint: the joint.
        samples: samples where both routes estimated it.
        rms, mean: RMS and mean of ``tau_f(measured) - tau_f(contact)`` over them [N·m].
        share: ``rms`` over the RMS of the measured route's ``tau_f`` there.
        cause: the likely cause of a large disagreement (module docstring), or "" (agreement, or too few
            samples to say).
    """

    joint: str
    samples: int
    rms: float
    mean: float
    share: float
    cause: str


def likely_cause(difference: np.ndarray, qdd: np.ndarray) -> str:
    """The likely cause of a disagreement (module docstring) from its samples (n,) [N·m] and the joint's
    accelerations there (n,) [rad/s^2]."""
    rms = float(np.sqrt(np.mean(difference**2)))
    if abs(float(np.mean(difference))) > 0.5 * rms:
        return "an offset: a force-torque or torque sensor's"
    if np.std(qdd) > 0 and abs(float(np.corrcoef(difference, qdd)[0, 1])) > 0.5:
        return "a wrong inertia: the disagreement follows the acceleration"
    return ("neither a constant nor following the acceleration: a stance foot that moves (a rocking or compliant "
            "sole), an inertia error through the other joints, or a drifting sensor")


def cross_check(joints: tuple[str, ...], disagreement: np.ndarray, tau_f: np.ndarray, qdd: np.ndarray | None
                ) -> list[RouteCheck]:
    """Per joint, the disagreement (N, n) [N·m] (NaN where one route did not estimate) summarised, with the
    measured route's friction ``tau_f`` (N, n) and the accelerations ``qdd`` (N, n) (None: not known)."""
    out = []
    for i, joint in enumerate(joints):
        both = np.isfinite(disagreement[:, i]) & np.isfinite(tau_f[:, i])
        d = disagreement[both, i]
        if d.size < MIN_SAMPLES:
            out.append(RouteCheck(joint, int(d.size), float("nan"), float("nan"), float("nan"), ""))
            continue
        rms = float(np.sqrt(np.mean(d**2)))
        scale = float(np.sqrt(np.mean(tau_f[both, i] ** 2)))
        share = rms / scale if scale > 0 else float("inf")
        cause = ""
        if share > LARGE:
            cause = likely_cause(d, qdd[both, i] if qdd is not None else np.zeros_like(d))
        out.append(RouteCheck(joint, int(d.size), rms, float(np.mean(d)), share, cause))
    return out


def cross_check_file(path: str | Path) -> list[RouteCheck]:
    """:func:`cross_check` of a friction table file (Parquet, CSV or HDF5) written with a measured route,
    reading three columns of one joint at a time (bounded memory in the log's length); [] when the table has
    no ``disagreement.<joint>`` column.

    Raises:
        InputError: an unreadable file, naming it.
    """
    from wbfriction.logs.tables import TableFile

    table = TableFile(path)
    joints = tuple(c.removeprefix("disagreement.") for c in table.schema().names if c.startswith("disagreement."))
    out = []
    for joint in joints:
        cols = table.read([f"disagreement.{joint}", f"tau_f.{joint}", f"qdd.{joint}"])
        x = {n.split(".", 1)[0]: cols.column(n).to_numpy(zero_copy_only=False).astype(float)[:, None]
             for n in cols.column_names}
        out += cross_check((joint,), x["disagreement"], x["tau_f"], x.get("qdd"))
    return out
