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

from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log


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


    @property
    def active(self) -> bool:
        """Whether the sensors change anything."""
        return self.position_std > 0 or self.encoder_bits is not None or self.torque_std > 0

    def draw(self, n: int, n_q: int, n_tau: int) -> tuple[np.ndarray, np.ndarray]:
        """The position (n, n_q) [rad] and torque (n, n_tau) [N·m] noise of ``n`` samples,
        from :attr:`seed` (zeros where a noise is off)."""
        rng = np.random.default_rng(self.seed)
        eps_q = rng.normal(0.0, self.position_std, (n, n_q)) if self.position_std > 0 else np.zeros((n, n_q))
        eps_tau = rng.normal(0.0, self.torque_std, (n, n_tau)) if self.torque_std > 0 else np.zeros((n, n_tau))
        return eps_q, eps_tau

    def encoder(self, q: np.ndarray) -> np.ndarray:
        """Positions [rad] as the encoder reads them: rounded to its resolution, if any."""
        return q if self.resolution is None else np.round(q / self.resolution) * self.resolution


def apply_sensor_noise(log: Log, noise: SensorNoise) -> Log:
    """The log the sensors would have written (module docstring); ``log`` is not changed.

    The noise parameters are recorded in the metadata key ``sensor_noise``.
    """
    eps_q, eps_tau = noise.draw(len(log), log.q.shape[1], log.tau.shape[1])
    q = noise.encoder(log.q + eps_q)
    metadata = {**log.metadata, "sensor_noise": asdict(noise)}
    return dataclasses.replace(log, q=q, tau=log.tau + eps_tau, metadata=metadata)


SENSOR_KEYS = ("position_std", "encoder_bits", "torque_std", "seed", "delay")


def load_sensors_toml(path) -> dict:
    """The ``[sensors]`` table of a TOML file: any of :data:`SENSOR_KEYS`, e.g.::

        [sensors]
        position_std = 1e-4   # rad
        encoder_bits = 19
        torque_std = 0.05     # N·m
        seed = 0
        delay = 0.002         # s, measurement to command

    Raises:
        InputError: unreadable file, no ``[sensors]`` table, an unknown key.
    """
    from wbfriction.config import toml_table

    table = toml_table(path, "sensors")
    unknown = sorted(set(table) - set(SENSOR_KEYS))
    if unknown:
        raise InputError(f"{path}: [sensors] has unknown key(s) {', '.join(unknown)}; known: {', '.join(SENSOR_KEYS)}")
    return dict(table)
