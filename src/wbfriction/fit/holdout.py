"""Does a fit predict data it was not fitted on? The checks behind the ``does not predict`` status (issue 52).

A fit's standard errors say how well the data determine its parameters if the model is right and the friction the
same throughout. Neither is known: a friction that changed over the log (a joint warming, a second run half an hour
later) or a model error that follows the motion (an inertia error, a torque ripple) leaves the standard errors small
and the numbers wrong. What such a fit cannot do is predict data it was not fitted on.

Two places hold such data. **Its own later stretch** (:func:`~wbfriction.fit.selection.later_stretch`, run by every
fit): the same model fitted on the earliest ``1 - LATER`` of the samples the fit used predicts the last
:data:`LATER` (``e_model``), beside the whole fit's residuals there (``e_best``: the noise and what no model of this
family explains). **Another log** (:func:`~wbfriction.fit.predict.other_log_checks`, run by ``predict``): the
fit predicts it (``e_model``), beside the same model fitted on that log itself (``e_best``).

If the fit is right, its held-out mean square exceeds the best one's by its prediction variance alone,
``mean(g_t C g_t^T)`` over the held-out samples (``C`` the predicting fit's covariance, ``g_t`` the model's gradient
there). The excess beyond it, ``mean(e_model^2 - e_best^2) - mean(g C g^T)``, has a Newey-West standard error (the
residuals are correlated over a filter's window); the fit does not predict when the excess is beyond
:data:`HOLDOUT_Z` standard errors, the held-out RMS beyond ``1 + HOLDOUT_EXCESS`` times what the noise and the
standard errors allow, ``sqrt(mean(e_best^2) + mean(g C g^T))``, **and** the excess's own RMS beyond
:data:`HOLDOUT_FRICTION` of the friction the joint shows: significant, and material for the residual and for the
friction (a 12 % excess on a simulated knee's 0.02 N·m of model error is 1.5 % of its 0.6 N·m of friction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from wbfriction.fit.regression import held_out_gain

LATER = 0.3
"""The share of a fit's samples, the last in time, it is checked on (fitted on the others)."""
HOLDOUT_Z = 3.0
"""The excess of the held-out mean square must be beyond this many of its standard errors ..."""
HOLDOUT_EXCESS = 0.05
"""... and the held-out RMS beyond ``1 +`` this share of what the noise and the standard errors allow, for a fit
not to predict (chosen across the real datasets and the simulators: README, *Defaults chosen across the data*)."""
HOLDOUT_FRICTION = 0.05
"""... and the excess beyond what is allowed, ``sqrt(rms^2 - allowed^2)``, beyond this share of the friction the joint
shows there (the model's odd part at the held-out samples' 95th percentile of speed)."""
MIN_HELD_OUT = 20
"""Fewer samples on either side: no check."""


@dataclass(frozen=True)
class PredictionCheck:
    """How a fit predicted samples it was not fitted on (module docstring).

    Attributes:
        held_out: what was predicted, as a phrase ("the last 30 % of its samples", a log's name).
        samples: the held-out samples scored.
        rms: the fit's RMS error on them [N·m].
        allowed: what the noise and the standard errors allow there, ``sqrt(mean(e_best^2) + mean(g C g^T))``
            [N·m].
        z: the excess of the held-out mean square in its standard errors.
        share: for the later stretch, the share of the fit's samples held out; None for another log.
        note: what else explains a miss, a phrase (the held-out log faster than the fit's samples), or "".
        friction: the friction the joint shows there [N·m] (module docstring); 0: not known (no materiality test on
            it).
    """

    held_out: str
    samples: int
    rms: float
    allowed: float
    z: float
    share: float | None = None
    note: str = ""
    friction: float = 0.0

    @property
    def ratio(self) -> float:
        """``rms / allowed``."""
        return self.rms / self.allowed if self.allowed > 0 else math.inf

    @property
    def excess(self) -> float:
        """The RMS beyond what is allowed, ``sqrt(rms^2 - allowed^2)`` (0 within it) [N·m]."""
        return math.sqrt(max(self.rms**2 - self.allowed**2, 0.0))

    @property
    def predicts(self) -> bool:
        """Whether the fit predicts the held-out samples (module docstring)."""
        return self.predicts_at(HOLDOUT_Z, HOLDOUT_EXCESS, HOLDOUT_FRICTION)

    def predicts_at(self, z: float, excess: float, friction: float = HOLDOUT_FRICTION) -> bool:
        """Whether it predicts with the thresholds ``z`` (:data:`HOLDOUT_Z`), ``excess`` (:data:`HOLDOUT_EXCESS`) and
        ``friction`` (:data:`HOLDOUT_FRICTION`)."""
        return not (self.z > z and self.ratio > 1.0 + excess and self.excess > friction * self.friction)

    def describe(self) -> str:
        """What it predicted and how, one phrase (the reason of a fit that does not predict)."""
        if self.share is not None:
            head = (f"fitted on the first {100 * (1 - self.share):.0f} % of its samples, it predicts the last "
                    f"{100 * self.share:.0f} % to {self.rms:.3g} N·m")
            cause = "the friction changed over the log, or a model error its standard errors do not see"
        else:
            head = f"it predicts {self.held_out} to {self.rms:.3g} N·m"
            cause = "the friction or the motion's model error differs there"
        share = f", {100 * self.excess / self.friction:.0f} % of its friction" if self.friction > 0 else ""
        return (f"{head} where the noise and its standard errors allow {self.allowed:.3g} ({self.z:.1f} standard "
                f"errors{share}): {cause}" + (f"; {self.note}" if self.note else ""))

    def to_dict(self) -> dict[str, Any]:
        """As the parameters JSON's ``later_stretch`` holds it: a number that is not finite ``null`` (``z``: no
        standard error of the excess, an infinite one; ``rms``, ``allowed``, ``friction``: not known)."""
        def clean(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return {"held_out": self.held_out, "share": self.share, "samples": self.samples, "rms": clean(self.rms),
                "allowed": clean(self.allowed), "z": clean(self.z), "predicts": self.predicts,
                "note": self.note, "friction": clean(self.friction)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> PredictionCheck:
        """Inverse of :meth:`to_dict` (``z`` ``null``: infinite; the others ``null``: NaN)."""
        def number(key: str, missing: float) -> float:
            return missing if d.get(key) is None else float(d[key])

        return cls(str(d["held_out"]), int(d["samples"]), number("rms", math.nan), number("allowed", math.nan),
                   number("z", math.inf), None if d.get("share") is None else float(d["share"]),
                   str(d.get("note", "")), number("friction", 0.0))


def split_later(use: np.ndarray, share: float = LATER) -> tuple[np.ndarray, np.ndarray]:
    """(before, later): the rows before the last ``share`` of the samples ``use`` (N,) bool, and those last samples;
    later starts at a row, so every row before it is before (whatever ``use`` says of it)."""
    rows = np.flatnonzero(use)
    cut = rows[min(int(round((1.0 - share) * rows.size)), rows.size - 1)] if rows.size else 0
    before = np.arange(use.size) < cut
    return before, use & ~before


def prediction_variance(g: np.ndarray, covariance: np.ndarray) -> float:
    """``mean_t(g_t C g_t^T)`` [N²·m²] of the model's gradients ``g`` (n, p) and the fit's covariance ``C`` (p, p):
    what its parameters' uncertainty adds to its mean square error on those samples; a parameter that is not
    identifiable (infinite variance) left out.

    A covariance is positive semi-definite, but one of nearly collinear parameters (an offset and a ripple's
    ``cos q`` on a joint that hardly moves) holds rounding of the size of its largest entries: its quadratic form
    ``g C g^T`` can come out negative, and ``sqrt(mean(e_best^2) + variance)`` NaN (issue 63). The form is taken on
    its eigenvalues clipped at zero, ``sum_i max(lambda_i, 0) (g v_i)^2``: never below zero."""
    if not len(g):
        return 0.0
    known = np.isfinite(np.diag(covariance))
    cov = np.where(np.outer(known, known), covariance, 0.0)
    values, vectors = np.linalg.eigh(0.5 * (cov + cov.T))
    return float(np.mean((np.asarray(g) @ vectors) ** 2 @ np.clip(values, 0.0, None)))


def prediction_check(held_out: str, e_model: np.ndarray, e_best: np.ndarray, variance: float, rows: np.ndarray,
                     share: float | None = None, note: str = "", friction: float = 0.0) -> PredictionCheck:
    """The check of the module docstring from the residuals (n,) of the predicting fit and of the best one on the
    held-out ``rows`` (n,) of the series, and the prediction variance [N²·m²] (:func:`prediction_variance`)."""
    finite = np.isfinite(e_model) & np.isfinite(e_best)
    e_model, e_best, rows = e_model[finite], e_best[finite], rows[finite]
    gain, se = held_out_gain(e_model, e_best, rows)
    if not finite.any():  # nothing to score: no excess, nothing allowed
        return PredictionCheck(held_out, 0, 0.0, 0.0, 0.0, share, note, friction)
    rms = float(np.sqrt(np.mean(e_model**2)))
    allowed = float(np.sqrt(np.mean(e_best**2) + max(variance, 0.0)))
    if not math.isfinite(gain):  # fewer than two samples: no excess measured
        z = 0.0
    else:
        z = (gain - variance) / se if se > 0 else (math.inf if gain > variance else 0.0)
    return PredictionCheck(held_out, int(finite.sum()), rms, allowed, float(z), share, note, friction)
