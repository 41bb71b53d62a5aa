"""The motion ``excite`` designs: each joint a finite Fourier series that starts and ends at rest (Swevers, Ganseman,
Tukel, De Schutter & Van Brussel, *Optimal robot excitation and identification*, IEEE T-RA 13(5), 1997; the
parameterisation of FloBaRoID and BIRDy):

.. math::

    q_i(t) = c_i + \\sum_{l=1}^{L} \\frac{a_{il}}{\\omega_f l}\\sin(\\omega_f l t)
             - \\frac{b_{il}}{\\omega_f l}\\cos(\\omega_f l t),
    \\qquad \\sum_l a_{il} = 0, \\quad \\sum_l l\\, b_{il} = 0,

periodic in ``2 pi / omega_f`` (a whole number of periods per recording: it ends where it started, at rest:
``qd(0) = sum_l a_il = 0``, ``qdd(0) = omega_f sum_l l b_il = 0``). The two constraints are kept by writing each
joint's ``a`` and ``b`` in a basis of their null spaces (:class:`FourierSpace`): the design's free variables are
each joint's centre ``c_i`` and ``2 (L - 1)`` coordinates, unconstrained.

The series is :class:`~wbfriction.walking.fourier.FourierTrajectory`, which the arm simulator tracks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.walking.fourier import FourierTrajectory


def rest_basis(harmonics: int) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal bases (L, L - 1) of the coefficients that keep a joint at rest at ``t = 0``: ``a`` with
    ``sum_l a_l = 0`` and ``b`` with ``sum_l l b_l = 0`` (module docstring)."""
    from scipy.linalg import null_space

    ell = np.arange(1, harmonics + 1, dtype=float)
    return null_space(np.ones((1, harmonics))), null_space(ell[None, :])


@dataclass(frozen=True)
class FourierSpace:
    """The designs of ``n`` joints with ``harmonics`` harmonics of the fundamental ``omega`` [rad/s]: a vector of
    ``n (2 L - 1)`` free variables per design (module docstring), joint by joint: ``[c, za (L - 1), zb (L - 1)]``.

    Attributes:
        n: the joints designed.
        harmonics: ``L`` (at least 2: starting at rest takes one of each joint's ``a`` and one of its ``b``).
        omega: the fundamental ``omega_f`` [rad/s].
    """

    n: int
    harmonics: int
    omega: float

    def __post_init__(self) -> None:
        if self.harmonics < 2:
            raise InputError(f"--harmonics {self.harmonics}: a design at rest at its ends needs at least 2")
        if not (np.isfinite(self.omega) and self.omega > 0):
            raise InputError(f"a design's fundamental must be > 0 rad/s, got {self.omega!r}")

    @property
    def per_joint(self) -> int:
        """Free variables per joint: ``2 L - 1``."""
        return 2 * self.harmonics - 1

    def trajectory(self, x: np.ndarray) -> FourierTrajectory:
        """The series of the free variables ``x`` (n (2 L - 1),)."""
        Na, Nb = rest_basis(self.harmonics)
        z = np.asarray(x, dtype=float).reshape(self.n, self.per_joint)
        L1 = self.harmonics - 1
        return FourierTrajectory(z[:, 0].copy(), z[:, 1:1 + L1] @ Na.T, z[:, 1 + L1:] @ Nb.T, self.omega)

    def variables(self, trajectory: FourierTrajectory) -> np.ndarray:
        """The free variables (n (2 L - 1),) of a series at rest at ``t = 0`` (the inverse of :meth:`trajectory`).

        Raises:
            InputError: a series of other shape or fundamental, or not at rest at ``t = 0``.
        """
        if trajectory.a.shape != (self.n, self.harmonics) or not np.isclose(trajectory.omega, self.omega):
            raise InputError(f"a series of {trajectory.a.shape} harmonics at {trajectory.omega:g} rad/s is not of "
                             f"this design space ({self.n}, {self.harmonics}) at {self.omega:g} rad/s")
        Na, Nb = rest_basis(self.harmonics)
        za, zb = trajectory.a @ Na, trajectory.b @ Nb
        if not (np.allclose(za @ Na.T, trajectory.a, atol=1e-9) and np.allclose(zb @ Nb.T, trajectory.b, atol=1e-9)):
            raise InputError("the series does not start at rest (sum_l a_l = 0, sum_l l b_l = 0)")
        return np.column_stack([trajectory.center, za, zb]).ravel()

    def joint(self, x: np.ndarray, i: int) -> np.ndarray:
        """Joint ``i``'s free variables (2 L - 1,) within ``x``."""
        return np.asarray(x).reshape(self.n, self.per_joint)[i]


def joint_series(space: FourierSpace, z: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One joint's position [rad], velocity [rad/s] and acceleration [rad/s²] (N,) at ``t`` (N,) from its free
    variables ``z`` (2 L - 1,) of ``space`` (a design of that joint alone)."""
    single = FourierSpace(1, space.harmonics, space.omega)
    q, qd, qdd = single.trajectory(z)(t)
    return q[:, 0], qd[:, 0], qdd[:, 0]
