"""The choices a user makes about the signals (thesis 7.1), in a module that imports nothing heavy: the
command line shows their defaults in its help without loading NumPy, SciPy or Pinocchio."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from wbfriction.signals.filters import SavgolWeights


@dataclass(frozen=True)
class FilterOptions:
    """Parameters of the filtering schemes (thesis 7.1; defaults: the thesis's).

    Attributes:
        window: Savitzky-Golay window length L (odd) [samples].
        poly_order: Savitzky-Golay polynomial order k (>= 2).
        weights: Savitzky-Golay weights, ``uniform`` or ``gaussian``
            (:func:`~wbfriction.signals.filters.savgol_weights`).
        cutoff: Butterworth cutoff [Hz] (one pass, -3 dB).
        butter_order: Butterworth order n.
    """

    window: int = 151
    poly_order: int = 4
    weights: SavgolWeights = "uniform"
    cutoff: float = 10.0
    butter_order: int = 6
