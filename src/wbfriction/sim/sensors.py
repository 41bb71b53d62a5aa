"""Sensor models applied to a simulated log: position noise, encoder quantisation, torque noise.

The simulators log exact positions and torques; a robot's sensors do not. This module
turns an exact log into what the sensors would have written, so that the estimator can be
scored against ``tau_f_true`` on realistic data (thesis ch. 7). The true columns
(``tau_f_true``, ``qd_true``, ``qdd_true``) are kept.

* position: ``q + N(0, position_std^2)``, then quantised to the encoder's resolution
  ``2 pi / 2^encoder_bits`` (round to nearest);
* torque: ``tau + N(0, torque_std^2)``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import asdict, dataclass

import numpy as np

from ..exceptions import InputError
from ..log import Log


@dataclass(frozen=True)
class SensorNoise:
    """Sensor imperfections (all off by default).

    Attributes:
        position_std: standard deviation of the joint-position noise [rad].
        encoder_bits: encoder resolution in bits per turn (e.g. 19), or None for none.
        torque_std: standard deviation of the torque-sensor noise [N·m].
        seed: seed of the noise generator (same seed, same noise).
    """

    position_std: float = 0.0
    encoder_bits: int | None = None
    torque_std: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.position_std < 0 or self.torque_std < 0:
            raise InputError("sensor noise standard deviations must be >= 0")
        if self.encoder_bits is not None and not 1 <= self.encoder_bits <= 52:
            raise InputError(f"encoder bits must be between 1 and 52, got {self.encoder_bits}")

    @property
    def resolution(self) -> float | None:
        """Encoder step [rad], or None."""
        return None if self.encoder_bits is None else 2.0 * np.pi / 2.0**self.encoder_bits


def apply_sensor_noise(log: Log, noise: SensorNoise) -> Log:
    """The log the sensors would have written (module docstring); ``log`` is not changed.

    The noise parameters are recorded in the metadata key ``sensor_noise``.
    """
    rng = np.random.default_rng(noise.seed)
    q = log.q + rng.normal(0.0, noise.position_std, log.q.shape) if noise.position_std > 0 else log.q.copy()
    if noise.resolution is not None:
        q = np.round(q / noise.resolution) * noise.resolution
    tau = log.tau + rng.normal(0.0, noise.torque_std, log.tau.shape) if noise.torque_std > 0 else log.tau.copy()
    metadata = {**log.metadata, "sensor_noise": asdict(noise)}
    return dataclasses.replace(log, q=q, tau=tau, metadata=metadata)
