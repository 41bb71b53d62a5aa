"""The choices of ``wbfriction excite`` (light: what the command line's help shows; the design is
:mod:`wbfriction.excite.pd_design`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from wbfriction.exceptions import InputError
from wbfriction.sim.pd_options import REAL_DRIVER, DriverNoise, HungOptions, SetpointOptions


@dataclass(frozen=True)
class PdExciteOptions:
    """What :func:`design_pd` designs (:mod:`wbfriction.excite.pd_design`).

    Attributes:
        duration: the recording [s]; rate: the drivers' rate [Hz] (the set-points' samples).
        amplitudes: the shares of each joint's half range searched.
        reversals: the ranges of times between two reversals searched [s] (shortest, longest).
        torque_share: share of each driver's torque limit the motion may ask.
        velocity: command ``qd_des`` = the set-points' slope (False: zeros, as the real Aliengo's log).
        noise: the drivers' noise the prediction takes (:data:`~wbfriction.sim.pd_options.REAL_DRIVER`: a real
            driver's).
        seed: the ramps' levels and times.
    """

    duration: float = 30.0
    rate: float = 200.0
    amplitudes: tuple[float, ...] = (0.5, 0.65, 0.8, 0.95)
    reversals: tuple[tuple[float, float], ...] = ((0.2, 1.5), (0.1, 0.8), (0.5, 3.0))
    torque_share: float = 0.8
    velocity: bool = False
    noise: DriverNoise = REAL_DRIVER
    seed: int = 0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.duration) and self.duration * self.rate >= 2 * 200):
            raise InputError(f"--duration {self.duration:g}: the design needs at least 200 samples x 2 "
                             f"({400 / self.rate:g} s at {self.rate:g} Hz)")
        if not self.amplitudes or not all(0 < a <= 1 for a in self.amplitudes):
            raise InputError(f"--amplitude {self.amplitudes}: shares of each joint's half range, in (0, 1]")
        if not 0 < self.torque_share <= 1:
            raise InputError(f"--torque-share {self.torque_share!r} is not a share in (0, 1]")

    def hung(self, amplitude: float, reversal: tuple[float, float]) -> HungOptions:
        """The simulation of the candidate ``amplitude``, ``reversal`` with the drivers' noise."""
        return HungOptions(duration=self.duration, rate=self.rate, noise=self.noise,
                           setpoints=SetpointOptions(kind="ramps", amplitude=amplitude, reversal=reversal,
                                                     velocity=self.velocity, seed=self.seed))


PD_EXCITE = PdExciteOptions()
"""The defaults."""

ARM_RATE = 1000.0
"""A fixed-base arm's default rate [Hz] (:class:`~wbfriction.excite.design.ExciteOptions`' own)."""
ARM_PERIOD = 10.0
"""A fixed-base arm's default Fourier period [s] (:class:`~wbfriction.excite.design.ExciteOptions`' own)."""
