"""What the data determine: the parameters a log does not excite beyond the prior, named by body and parameter.

A fixed-base arm's torques never depend on some parameters (its first link's mass), and on others
only through combinations (Khalil's regrouped base parameters: a link's mass with its parent's
first moment and inertia); a log that barely moves a joint tells little of what it carries. With
the prior in standard deviations (:class:`~wbfriction.inertia.consistency.Prior`), the regressor
``R L^-1`` says how many residual units a one-standard-deviation change of each parameter moves the
torques. Its QR factorisation with column pivoting picks, one after the other, the parameters that
move the torques most beyond those already picked; a parameter whose pivot ``r_kk`` is below
``sqrt(weight)`` (the data hold less information on it than the prior, weighted as in the fit) is
**not excited**: the fit keeps it near the prior. Each comes with the *partners* that the data
cannot tell it from: the torques stay the same (to the pivot) when the parameter moves by ``d`` and
each partner by its coefficient times ``d`` (physical units: :data:`~wbfriction.inertia.consistency.PHYSICAL`
for bodies, N·m, N·m·s/rad and kg·m^2 for friction and armature).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from wbfriction.inertia.consistency import PHYSICAL, Prior

PARTNER_SHARE = 0.05
"""A partner is listed when it moves by at least this share of the parameter's change, each in
standard deviations of the prior."""


@dataclass(frozen=True)
class Unexcited:
    """A parameter the data do not determine beyond the prior.

    Attributes:
        parameter: ``<body>.<name>`` (:data:`~wbfriction.inertia.consistency.PHYSICAL`, about the
            body's centre of mass) or ``<joint>.<friction parameter>`` / ``<joint>.armature``.
        information: the pivot ``r_kk / sqrt(weight)``: the data's information on it relative to
            the prior's (0: no effect on the torques of its own: none at all, or only with its partners,
            a pivot below the rank tolerance, whose value rounding alone would set).
        partners: the parameters the data cannot tell it from, with the change of each per unit
            change of ``parameter`` (physical units; empty: it has no effect on its own).
    """

    parameter: str
    information: float
    partners: dict[str, float] = field(default_factory=dict)


def parameter_names(bodies: tuple[str, ...] | list[str], rest: tuple[str, ...] | list[str]) -> tuple[str, ...]:
    """Names of the identification's parameters: ``<body>.<physical parameter>`` for each body (in
    the prior's physical coordinates), then ``rest`` (e.g. ``<joint>.F_v``, ``<joint>.armature``)."""
    return tuple(f"{b}.{p}" for b in bodies for p in PHYSICAL) + tuple(rest)


def physical_std(prior: Prior) -> np.ndarray:
    """The prior's standard deviations (p,) in the coordinates of :func:`parameter_names`."""
    return np.concatenate([prior.body_std.ravel(), prior.std])


def unexcited_parameters(R: np.ndarray, prior: Prior, weight: float, names: tuple[str, ...],
                         rank_tolerance: float = 1e-10) -> tuple[Unexcited, ...]:
    """The parameters the data leave to the prior (module docstring).

    Args:
        R: the compressed regressor (p, p) over ``x = (pi.ravel(), rest)`` (its triangular factor).
        prior: the prior of the fit; weight: its weight in the fit.
        names: :func:`parameter_names` (p,).
        rank_tolerance: pivots below this share of the largest count as zero whatever the weight
            (information 0: a parameter that acts only with others).

    Returns:
        One :class:`Unexcited` per parameter not determined, in the order of ``names``.
    """
    import scipy.linalg
    Rw = R @ prior.L_inv  # torques per standard deviation of each parameter
    _, r_fac, perm = scipy.linalg.qr(Rw, mode="economic", pivoting=True)
    diag = np.abs(np.diag(r_fac))
    floor = max(np.sqrt(max(weight, 0.0)), rank_tolerance * (diag[0] if diag.size else 0.0))
    rank = int(np.argmax(diag <= floor)) if np.any(diag <= floor) else len(diag)
    K = scipy.linalg.solve_triangular(r_fac[:rank, :rank], r_fac[:rank, rank:]) if rank else np.zeros((0, 0))
    std = physical_std(prior)
    ind = perm[:rank]
    out = []
    for c, j in enumerate(perm[rank:]):
        order = [r for r in np.argsort(-np.abs(K[:, c])) if abs(K[r, c]) >= PARTNER_SHARE]
        partners = {names[ind[r]]: float(-K[r, c] * std[ind[r]] / std[j]) for r in order}
        pivot = diag[rank + c] if diag[rank + c] > rank_tolerance * diag[0] else 0.0  # below: rounding's
        info = float(pivot / np.sqrt(weight)) if weight > 0 else float("inf")
        out.append((j, Unexcited(names[j], info, partners)))
    return tuple(u for _, u in sorted(out, key=lambda ju: ju[0]))
