"""The choices of a batch (issue 25), in a module that imports only the standard library (the CLI's help reads
them without loading the library)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Literal

from wbfriction.fit.options import DEFAULT_THRESHOLD, DEFAULT_TOLERANCE, FitOptions
from wbfriction.friction.options import EstimateOptions

Shape = Literal["hinge", "step"]
SHAPES: tuple[Shape, ...] = ("hinge", "step")
"""The shapes of change the trends test (:mod:`wbfriction.fleet.change_point`): a linear drift from an onset, a
step at it."""


@dataclass(frozen=True)
class BatchOptions:
    """What every log of a batch is processed with: ``wbfriction estimate``'s and ``wbfriction fit``'s options.

    Attributes:
        estimate: the estimate's options (default: those of ``wbfriction estimate``).
        fit: the fit's options (default: those of ``wbfriction fit``).
        energy_threshold, energy_tolerance: of the energy check (eq. 7.9).
        chunk_rows: rows per chunk of the estimate.
    """

    estimate: EstimateOptions = EstimateOptions()
    fit: FitOptions = FitOptions()
    energy_threshold: float = DEFAULT_THRESHOLD
    energy_tolerance: float = DEFAULT_TOLERANCE
    chunk_rows: int = 10_000

    def for_entry(self, overrides: dict[str, Any]) -> BatchOptions:
        """These options with a manifest row's own (``diff``, ``route``, ``model``) applied."""
        out = self
        for name in ("diff", "route"):
            if name in overrides:
                out = dataclasses.replace(out, estimate=dataclasses.replace(out.estimate, **{name: overrides[name]}))
        if "model" in overrides:
            out = dataclasses.replace(out, fit=dataclasses.replace(out.fit, model=overrides["model"]))
        return out
