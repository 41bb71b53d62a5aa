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
from dataclasses import asdict

from wbfriction.exceptions import InputError
from wbfriction.logs.log import Log
from wbfriction.sim.options import SensorNoise


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
