"""Joint positions as finite Fourier series (Swevers, Ganseman, Tukel, De Schutter & Van Brussel, *Optimal robot
excitation and identification*, IEEE T-RA 13(5), 1997), the reference motion an excitation design gives its joints:

.. math::

    q_i(t) = q_{i,0} + \\sum_{l=1}^{L} \\frac{a_{il}}{\\omega_f l}\\sin(\\omega_f l t)
             - \\frac{b_{il}}{\\omega_f l}\\cos(\\omega_f l t),

periodic in ``2 pi / omega_f``. The fixed-base arm tracks it (:mod:`wbfriction.sim.arm`); a standing robot's swing
leg follows it (:mod:`.single_support`, :mod:`.tripod_support`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np


@dataclass(frozen=True)
class FourierTrajectory:
    """Joint positions as finite Fourier series (module docstring).

    Attributes:
        center: ``q_0`` (n,) [rad].
        a, b: coefficients (n, L) [rad/s].
        omega: fundamental angular frequency ``omega_f`` [rad/s].
    """

    center: np.ndarray
    a: np.ndarray
    b: np.ndarray
    omega: float

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions [rad], velocities [rad/s] and accelerations [rad/s^2] at times ``t`` (N,): each (N, n)."""
        w = self.omega * np.arange(1, self.a.shape[1] + 1)  # (L,)
        s, c = _harmonics(np.asarray(t, dtype=float), w)  # (N, L)
        q = self.center + s @ (self.a / w).T - c @ (self.b / w).T
        qd = c @ self.a.T + s @ self.b.T
        qdd = -s @ (self.a * w).T + c @ (self.b * w).T
        return q, qd, qdd


def _harmonics(t: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``sin(t w^T)`` and ``cos(t w^T)`` (N, L), read-only (:func:`_harmonics_of`)."""
    return _harmonics_of(t.tobytes(), w.tobytes())


@lru_cache(maxsize=8)
def _harmonics_of(t: bytes, w: bytes) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_harmonics` of the times and frequencies given as bytes, kept for the next call with the same (a
    design's optimiser evaluates one time grid thousands of times)."""
    arg = np.outer(np.frombuffer(t), np.frombuffer(w))
    s, c = np.sin(arg), np.cos(arg)
    s.flags.writeable = c.flags.writeable = False
    return s, c
