"""The choices of ``wbfriction excite`` (light: what the command line's help shows; the design is
:mod:`wbfriction.excite.pd_design`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from wbfriction.exceptions import InputError, OptionError
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
        if not self.rate > 0:
            raise InputError(f"--rate {self.rate:g}: a rate is > 0 Hz")
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

JOINT_SAMPLE = 1e3
"""What a design holds in memory per joint and sample simulated [bytes], about (the peak Python's allocations reach
over the samples, measured with ``tracemalloc`` at 8 and 16 s): 11.6 kB per sample of a hung Go2's candidate (12
joints: two simulations and two identifications), 4.0 kB of a Panda's design and prediction (7), 2.5 kB of
go2_walking's stance on three feet (12)."""
DESIGN_MEMORY = 2.0**31
"""The memory a design may hold [bytes]: 2 GiB, what one process may take on a laptop beside the others. With
:data:`JOINT_SAMPLE` it bounds the samples a design simulates (:func:`check_design_size`): a hung Go2's 895 s at
200 Hz, a Panda's 307 s at 1 kHz."""


def design_samples(joints: int) -> int:
    """The most samples a design of a robot of ``joints`` actuated joints may simulate: :data:`DESIGN_MEMORY` over
    :data:`JOINT_SAMPLE` per joint."""
    return int(DESIGN_MEMORY // (JOINT_SAMPLE * max(joints, 1)))


def check_design_size(robot: str, joints: int, duration: float, rate: float, option: str = "--duration") -> None:
    """Refuse, before any work, a design whose ``duration`` [s] at ``rate`` [Hz] simulates more samples than the
    memory a design may hold allows for the robot ``robot`` of ``joints`` actuated joints (:func:`design_samples`);
    ``option``: the one to name, ``--duration`` or ``--rate``.

    Raises:
        OptionError: naming ``option``, the most it may be with the other, and the memory bound.
    """
    most = design_samples(joints)
    if duration * rate <= most:
        return
    bound = f"{most / rate:.6g} s at {rate:g} Hz" if option == "--duration" else f"{most / duration:.6g} Hz over " \
        f"{duration:g} s"
    raise OptionError(option, duration if option == "--duration" else rate,
                      f"at most {bound}: {most} samples of the {joints} joints of robot '{robot}', what a design may "
                      f"hold in memory ({DESIGN_MEMORY / 2**30:g} GiB at about {JOINT_SAMPLE / 1e3:g} kB per joint and "
                      "sample)")
