"""Which period a logged foot force stands for, checked on the momentum balance (issue 63).

The momentum route (:mod:`wbfriction.friction.momentum`) integrates the measured foot forces' joint torques
``e = J^T f`` over each step ``[t_k, t_k+1]``. A log's row ``k`` holds one force per foot; the convention
(docs/reference/log-format.md) is that it is read as the torques are: with ``zoh`` torques, the force over
``[t_k, t_k+1)`` (its mean over the period, or its value just after ``t_k``: a torque-driven robot's contact force
follows its held torque), with ``sample`` torques the force at the instant ``t_k``. A logger that writes the mean over
the period before the stamp, ``[t_k-1, t_k)``, shifts it one step: a stance hip's ``J^T f`` moves tens of N·m while
its friction is a fraction of one, so a step's shift puts its impulse in the friction (issue 63: three hip
abduction ``F_v`` driven to zero on a crawl).

The check reads the forces three ways, each step's integral of ``e``

* ``held``: ``e_k Delta t_k`` (over ``[t_k, t_k+1)``),
* ``instants``: ``(e_k + e_k+1) / 2 Delta t_k`` (the trapezoid),
* ``held before``: ``e_k+1 Delta t_k`` (row ``k+1`` holds ``[t_k, t_k+1)``),

estimates the friction through the route's window with each, and fits every joint whose leg stands on a measured
foot any curve of its velocity (a step at zero and a piecewise-linear curve, :func:`friction_basis`) through the
same window (linear least squares). The friction is a function
of the joint's velocity; a wrong reading adds ``J^T f``'s derivative, which is not. The reading whose fits leave the
least residual is the one the log follows; when it is not the one used and leaves less than
:data:`RATIO` of its residual, the route warns, naming the reading.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbfriction.signals.window import MomentumWindow

READINGS = ("held", "instants", "held before")
"""The readings of a logged foot force tried (module docstring)."""
RATIO = 0.7
"""A reading other than the one used is named when its fits' residual sum of squares is below this share of the used
one's. Chosen on the ideal simulator's and MuJoCo's crawl (walk) and trot with 3-D foot forces, 4 s, noise-free and
with a real robot's noise: as logged, the used reading is the best or within 1 % of it (no warning); the forces one
row late leave the used reading 2.7-6.7 times the best's residual (0.15-0.37 of it), half a row late 0.35-0.69. With
MuJoCo's foot-force noise (2 N per component) the readings differ by less than 6 %: a shift is not seen there, and
nothing is said (``tests/friction/test_force_sampling.py``)."""
KNOTS = 9
"""Velocities of the piecewise-linear friction curve each joint is fitted (:func:`friction_basis`)."""
MIN_ROWS = 50
"""Rows a joint needs, standing on a measured foot, to enter the comparison."""


@dataclass(frozen=True)
class ForceSampling:
    """What the check found (module docstring).

    Attributes:
        used: the reading the route used (``held`` for ``zoh`` torques, ``instants`` for ``sample``).
        best: the reading whose fits leave the least residual.
        rss: each reading's residual sum of squares over the joints compared [N²·m²].
        joints: how many joints were compared (0: nothing to check, ``best`` is ``used``).
    """

    used: str
    best: str
    rss: dict[str, float]
    joints: int

    def warning(self, source: str) -> str:
        """One line naming the reading the log fits better, or "" when it is the one used (or nothing compared)."""
        if self.joints == 0 or self.best == self.used or self.rss[self.best] >= RATIO * self.rss[self.used]:
            return ""
        ratio = self.rss[self.used] / max(self.rss[self.best], 1e-300)
        return (f"{source}: the foot forces fit the momentum balance read as {_phrase(self.best)} better than as "
                f"{_phrase(self.used)} (residual {ratio:.1f} times smaller): check which period the logger's "
                f"force.* rows stand for (docs/reference/log-format.md){REMEDY.get((self.used, self.best), '')}")

    def to_dict(self) -> dict:
        """As JSON (the friction table's metadata ``foot_force_sampling``)."""
        return {"used": self.used, "best": self.best, "rss": dict(self.rss), "joints": self.joints}


REMEDY = {("held", "held before"): "; if a row late, move the force.* columns one row earlier",
          ("held", "instants"): "; if sampled at the instants, give each row the mean of it and the next",
          ("instants", "held"): "; if held like the torques, --torque-alignment zoh"}
"""What to do with the log, by (used, best) reading."""


def _phrase(reading: str) -> str:
    return {"held": "held over [t_k, t_k+1)", "instants": "sampled at the instants t_k",
            "held before": "held over [t_k-1, t_k)"}[reading]


def friction_basis(qd: np.ndarray, seen: np.ndarray) -> np.ndarray:
    """Any friction curve of the velocity ``qd`` (N,) [rad/s], as columns (N, k): an offset, the sign of ``qd``, and
    piecewise-linear hats on :data:`KNOTS` velocities at the quantiles of ``seen`` (the rows compared), so that no
    family (Stribeck, tanh) is presumed."""
    knots = np.unique(np.quantile(seen, np.linspace(0.0, 1.0, KNOTS)))
    hats = [np.interp(qd, knots, np.eye(len(knots))[i]) for i in range(len(knots))]
    return np.column_stack([np.sign(qd), *hats])


def force_integrals(e: np.ndarray, dt: np.ndarray, reading: str) -> np.ndarray:
    """Each step's integral of ``e`` (N, n) [N·m] read as ``reading`` (:data:`READINGS`): (N - 1, n) [N·m·s]."""
    dt = np.asarray(dt, dtype=float)[:, None]
    if reading == "held":
        return e[:-1] * dt
    if reading == "instants":
        return 0.5 * (e[:-1] + e[1:]) * dt
    if reading == "held before":
        return e[1:] * dt
    raise ValueError(f"unknown reading {reading!r}: one of {', '.join(READINGS)}")


def check_force_sampling(impulses: np.ndarray, e: np.ndarray, qd: np.ndarray, rows: np.ndarray,
                         window: MomentumWindow, used: str) -> ForceSampling:
    """Compare the readings of the foot forces on the momentum balance (module docstring).

    Args:
        impulses: the friction's impulse over each step (N - 1, n) [N·m·s] without the foot forces' share
            (:func:`~wbfriction.friction.momentum.step_impulses` of ``tau`` alone), NaN off the route's rows.
        e: the measured foot forces' joint torques (N, n) [N·m], zero where no measured foot is down on the leg.
        qd: the joints' velocities (N, n) [rad/s], the route's.
        rows: (N, n) the rows each joint's estimate is valid on.
        window: the route's window.
        used: the reading the route used.

    Returns:
        :class:`ForceSampling`.
    """
    n = len(qd)
    dt = window.step_durations(n)
    estimates = {r: window.over_steps(impulses - force_integrals(e, dt, r)) for r in READINGS}
    loaded = window(np.abs(e)) > 0  # a measured force in the window
    rss = dict.fromkeys(READINGS, 0.0)
    compared = 0
    for j in range(qd.shape[1]):
        use = rows[:, j] & loaded[:, j] & np.all([np.isfinite(x[:, j]) for x in estimates.values()], axis=0)
        if use.sum() < MIN_ROWS:
            continue
        X = window(friction_basis(qd[:, j], qd[use, j]))[use]
        keep = np.all(np.isfinite(X), axis=1)
        if keep.sum() < MIN_ROWS:
            continue
        X, use = X[keep], np.flatnonzero(use)[keep]
        compared += 1
        for r, est in estimates.items():
            coef, *_ = np.linalg.lstsq(X, est[use, j], rcond=None)
            rss[r] += float(np.sum((est[use, j] - X @ coef) ** 2))
    best = min(READINGS, key=lambda r: rss[r]) if compared else used
    return ForceSampling(used, best, rss, compared)
