"""The choices a user makes about the signals (thesis 7.1), in a module that imports nothing heavy: the
command line shows their defaults in its help without loading NumPy, SciPy or Pinocchio. Each choice is
checked here, where it is defined."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

from wbfriction.choices import check_choice, check_range, flag
from wbfriction.exceptions import OptionError

NOISE_TARGET = 0.03
"""Most RMS noise a scheme may leave in the acceleration [rad/s^2] (:mod:`wbfriction.signals.choice`: measured;
through a joint inertia of 1 kg·m^2 it is 0.03 N·m, below the studies' torque-sensor noise of 0.05 N·m); the
default of ``EstimateOptions.noise_target``."""

Scheme = Literal["central", "backward", "savgol", "butterworth"]
"""A differentiation scheme: plain differences, then the filtering ones (:mod:`~wbfriction.signals.kinematics`)."""
SCHEMES: tuple[Scheme, ...] = get_args(Scheme)
FILTERING_SCHEMES: tuple[Scheme, ...] = ("savgol", "butterworth")
Diff = Literal["central", "backward", "savgol", "butterworth", "true"]
"""A scheme, or ``true``: the simulators' logged true velocities and accelerations."""
DIFFS: tuple[Diff, ...] = get_args(Diff)
DiffOption = Literal["auto", "central", "backward", "savgol", "butterworth", "true"]
"""A :data:`Diff`, or ``auto``: the scheme and its filter chosen from the log's positions
(:func:`~wbfriction.friction.estimate.resolve_differentiation`)."""
DIFF_OPTIONS: tuple[DiffOption, ...] = get_args(DiffOption)

TorqueAlignment = Literal["zoh", "sample"]
"""How torques are aligned with the central second difference (:func:`~wbfriction.signals.kinematics.align_torque`)."""
TORQUE_ALIGNMENTS: tuple[TorqueAlignment, ...] = get_args(TorqueAlignment)
AlignmentOption = Literal["auto", "zoh", "sample"]
"""A :data:`TorqueAlignment`, or ``auto``: what the log's metadata declare, else ``zoh``."""
ALIGNMENT_OPTIONS: tuple[AlignmentOption, ...] = get_args(AlignmentOption)

Velocity = Literal["differentiated", "logged"]
"""Where the joint velocities come from: the positions differentiated by the scheme, or the
log's own ``qd.<joint>`` columns (:func:`~wbfriction.signals.kinematics.measure`)."""
VELOCITIES: tuple[Velocity, ...] = get_args(Velocity)

Mask = Literal["swing", "single"]
"""Which single-support samples of a joint count (:mod:`~wbfriction.signals.phases`)."""
MASKS: tuple[Mask, ...] = get_args(Mask)

SavgolWeights = Literal["uniform", "gaussian"]
"""The named weights of a Savitzky-Golay fit (:func:`~wbfriction.signals.filters.savgol_weights`)."""
WEIGHTS: tuple[SavgolWeights, ...] = get_args(SavgolWeights)


@dataclass(frozen=True)
class FilterOptions:
    """Parameters of the filtering schemes (thesis 7.1; defaults: the thesis's).

    Attributes:
        window: Savitzky-Golay window length L (odd, >= 3) [samples].
        poly_order: Savitzky-Golay polynomial order k (>= 2, < L).
        weights: Savitzky-Golay weights, ``uniform`` or ``gaussian``
            (:func:`~wbfriction.signals.filters.savgol_weights`).
        cutoff: Butterworth cutoff [Hz] (one pass, -3 dB; > 0).
        butter_order: Butterworth order n (>= 1).

    Raises:
        OptionError: a value out of its range or not one of its choices (naming the option, e.g. ``--window``).
    """

    window: int = 151
    poly_order: int = 4
    weights: SavgolWeights = "uniform"
    cutoff: float = 10.0
    butter_order: int = 6

    def __post_init__(self) -> None:
        if self.window < 3 or self.window % 2 == 0:
            raise OptionError(flag("window"), self.window, "odd and at least 3")
        check_range("poly_order", self.poly_order, low=2, high=self.window - 1)
        check_choice("weights", self.weights, WEIGHTS)
        check_range("cutoff", self.cutoff, low=0.0, strict=True)
        check_range("butter_order", self.butter_order, low=1)
