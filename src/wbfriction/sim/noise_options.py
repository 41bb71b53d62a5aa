"""The sensor-noise options the simulated logs take (``simulate --position-noise``, ``--sensors``), as fields of the
rigs' and engines' options (:func:`~wbfriction.options.option`); this module imports only the standard library and
the options."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Optional

from wbfriction.options import option

if TYPE_CHECKING:
    from wbfriction.sim.options import SensorNoise


@dataclass(frozen=True)
class SensorNoiseOptions:
    """The sensor noise a simulated log takes.

    Attributes:
        position_noise: joint-position noise std [rad]; None: none.
        encoder_bits: encoder resolution [bits per turn]; None: the simulator's default.
        torque_noise: torque-sensor noise std [N·m]; None: none.
        noise_seed: the noise's seed; None: 0.
    """

    position_noise: Optional[float] = option(None, quantity="position_std")
    encoder_bits: Optional[int] = option(None, quantity="encoder_bits")
    torque_noise: Optional[float] = option(None, quantity="torque_std")
    noise_seed: Optional[int] = option(None, quantity="seed")


@dataclass(frozen=True)
class SensorsFileOptions(SensorNoiseOptions):
    """The sensor noise with a TOML of it: ``sensors``, a TOML with a ``[sensors]`` table (position_std,
    encoder_bits, torque_std, seed; delay), which the options given override."""

    sensors: Optional[Path] = option(None)

    def noise(self, delay: float | None = None) -> tuple[SensorNoise, float]:
        """The sensor noise and the measurement-to-command delay [s]: the ``sensors`` TOML's ``[sensors]`` table
        (none: the defaults), each option given overriding it (``delay`` in ms).

        Raises:
            InputError: a sensors TOML that cannot be read, or with unknown keys.
        """
        from wbfriction.sim.options import SensorNoise
        from wbfriction.sim.sensors import load_sensors_toml

        table = load_sensors_toml(self.sensors) if self.sensors is not None else {}
        given = {"position_std": self.position_noise, "encoder_bits": self.encoder_bits,
                 "torque_std": self.torque_noise, "seed": self.noise_seed,
                 "delay": None if delay is None else delay * 1e-3}
        table.update({k: v for k, v in given.items() if v is not None})
        lag = float(table.pop("delay", 0.0))
        return SensorNoise(**table), lag
