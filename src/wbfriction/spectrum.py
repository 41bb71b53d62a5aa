"""Amplitude spectrum of the estimated joint acceleration, and the cutoff it suggests (thesis Fig. 7.1).

The thesis tunes the low-pass of the measured acceleration on the spectrum of the
*estimated* one, ``qdd_est`` of (5.10): computed by the model from the measured torques, it
is far less disturbed than the twice-differentiated positions, and it shows where the
motion's content ends. Above it there is nothing to keep
(:func:`~wbfriction.filters.suggest_cutoff`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dynamics import constrained_dynamics
from .exceptions import InputError
from .filters import amplitude_spectrum, finite_runs, suggest_cutoff
from .kinematics import measure
from .log import Log
from .robot import Robot


@dataclass
class AccelerationSpectrum:
    """Spectra of the estimated acceleration of some joints.

    Attributes:
        joints: joint names (n,).
        freq: frequencies (F,) [Hz].
        amplitude: one-sided amplitude spectra (F, n) [rad/s^2].
        cutoff: suggested cutoff per joint (n,) [Hz].
        span: (start, stop) times of the stretch analysed [s].
    """

    joints: tuple[str, ...]
    freq: np.ndarray
    amplitude: np.ndarray
    cutoff: np.ndarray
    span: tuple[float, float]

    @property
    def suggestion(self) -> float:
        """One cutoff for all the joints: the median of theirs [Hz] (robust to a joint whose
        estimated acceleration carries impacts; the thesis read its 10 Hz off representative
        joints, the knee and the hip pitch)."""
        return float(np.median(self.cutoff))


def acceleration_spectrum(robot: Robot, log: Log, joints: list[str] | None = None, tail: float = 0.01,
                          progress=None) -> AccelerationSpectrum:
    """Spectrum of ``qdd_est`` (5.10) per joint over the longest stretch with a foot on the ground.

    Args:
        robot: the robot; log: a validated log.
        joints: torque-controlled joints to analyse (default: all of them).
        tail: share of the power left above the suggested cutoff
            (:func:`~wbfriction.filters.suggest_cutoff`).
        progress: optional callable receiving numbers of samples done.

    Raises:
        InputError: an unknown joint, or fewer than 64 samples with a foot on the ground.
    """
    names = list(robot.torque_controlled) if joints is None else list(joints)
    unknown = [j for j in names if j not in robot.torque_controlled]
    if unknown:
        raise InputError(f"{log.source}: '{unknown[0]}' is not a torque-controlled joint of {robot.name}")
    kin = measure(log, "central")
    usable = kin.valid & kin.contact.any(axis=1)
    runs = finite_runs(np.where(usable, 0.0, np.nan))
    a, b = max(runs, key=lambda r: r[1] - r[0]) if runs else (0, 0)
    if b - a < 64:
        raise InputError(f"{log.source}: fewer than 64 consecutive samples with a foot on the ground")
    rows = slice(a, b)
    dyn = constrained_dynamics(robot, kin.q[rows], kin.qd[rows], kin.qdd[rows], kin.tau[rows], kin.contact[rows],
                               None if kin.base is None else kin.base[rows], with_Mmod_inv=False, progress=progress)
    cols = [robot.actuated.index(j) for j in names]
    freq, amp = amplitude_spectrum(dyn.qdd_est[:, cols], log.dt)
    cutoff = np.array([suggest_cutoff(freq, amp[:, i], tail) for i in range(len(cols))])
    return AccelerationSpectrum(tuple(names), freq, amp, cutoff, (float(log.time[a]), float(log.time[b - 1])))
