"""Whether a log resolves a friction family's transitions (issue 63): a shape kept only where the data carry it.

A family's shape parameters act at a speed (:meth:`~wbfriction.friction.families.base.FrictionFamily.transitions`):
the Stribeck velocity ``v_s`` (3.3), ``1 / a`` of the thesis's ``tanh(a qd)`` (3.5). A fit places them wherever they
lower its residual, and where few samples lie around them they fit the noise, or a joint's creep: a walking robot's
stance leg creeps at 0.003-0.02 rad/s, its friction there a function of the load and the contact, not of the
velocity, and a Stribeck curve whose ``v_s`` sits among those samples predicts nothing the next step does (issue 63:
such fits `ok` and 100 % off on a crawl made elsewhere). A transition is *resolved* when at least
:data:`TRANSITION_SAMPLES` of the samples fitted (and :data:`TRANSITION_SHARE` of them) lie below its speed, above
three standard deviations of the velocity's noise (:func:`creep_floor`), and as many where it has settled (beyond
:data:`SETTLED` times its speed): a curve placed where no sample is, or only noise, is no finding, and one that decays
over the whole range of the data's speeds (a Stribeck velocity near the top speed: the crawl's noisy calf, F_c = 0
and F_v 16 % off, called `ok`) trades its levels for its shape, with nothing to tell F_c and F_v from F_s. The
parameter's standard error is not required to be small: a shape parameter correlated with the magnitudes (``a`` with
F_c) can be poorly determined while the curve it draws predicts held-out data better (the KUKA's repeat runs: a
rule that passed over such fits made the two runs' lwr_4 curves differ by 13 %).
A joint slower than the stick floor (:data:`~wbfriction.fit.options.STICK_FLOOR`, ``fit --stick-floor``) for longer
than a pass through zero takes is left out as one that may stick (:func:`~wbfriction.fit.solve.stuck_rows`): with the
floor above a stance leg's creep, what lies below a transition are passes through it. A family with a transition its
data do not resolve is not chosen by the automatic choice (:mod:`~wbfriction.fit.selection`): the simplest model
within the tolerance of the best is chosen as before, the best among every candidate; only where that is one whose
transition is unresolved is the choice made again among the others (an unresolved model still says how well the
data can be fitted).
"""

from __future__ import annotations

import numpy as np

from wbfriction.friction.families.registry import family
from wbfriction.friction.models import ModelParamsBase

TRANSITION_SAMPLES = 5
"""The fewest samples below a transition's speed that resolve it: a guard against a curve placed where no sample is.
A walking humanoid's joint at 1 kHz passes through a tanh transition at 0.025 rad/s with 6-16 samples below it in
its training blocks (the README's tour), and (3.5) predicts its held-out blocks 10-20 times better than a step
there."""
TRANSITION_SHARE = 0.001
"""... and the smallest share of the samples fitted."""
SETTLED = 2.0
"""A transition has settled at this multiple of its speed (a Stribeck term, ``exp(-(qd / v_s)^2)``, is 2 % of its
height there; ``tanh(a qd)`` 96 % of its step): samples there separate the levels it joins (F_c and F_v from F_s)."""
NOISE_SIGMAS = 3.0
"""Speeds below this many standard deviations of the velocity's noise are noise, not a transition's evidence."""


def creep_floor(velocity_noise: float = 0.0) -> float:
    """The speed [rad/s] below which samples are no evidence of a transition: :data:`NOISE_SIGMAS` standard
    deviations of the velocity's noise ``velocity_noise`` [rad/s] (0 for a noise-free velocity)."""
    return NOISE_SIGMAS * float(velocity_noise)


def transition_counts(speed: float, qd: np.ndarray, floor: float) -> tuple[int, int]:
    """How many of the velocities ``qd`` (n,) [rad/s] lie below a transition at ``speed`` [rad/s] (``|qd|`` in
    ``[floor, speed)``) and where it has settled (``|qd| >= max(SETTLED * speed, floor)``, :data:`SETTLED`)."""
    v = np.abs(np.asarray(qd, dtype=float))
    v = v[np.isfinite(v)]
    inside = (v >= floor) & (v < speed)
    settled = v >= max(SETTLED * speed, floor)
    return int(inside.sum()), int(settled.sum())


def unresolved(params: ModelParamsBase, qd: np.ndarray, velocity_noise: float = 0.0) -> tuple[str, ...]:
    """The transitions of ``params`` (:meth:`~wbfriction.friction.families.base.FrictionFamily.transitions`) the
    velocities ``qd`` (n,) [rad/s] of the samples fitted do not resolve (module docstring), one phrase each, e.g.
    ``"v_s 0.008 rad/s (0 samples below, 3 beyond)"``; empty when every one is resolved."""
    qd = np.asarray(qd, dtype=float)
    need = max(TRANSITION_SAMPLES, int(np.ceil(TRANSITION_SHARE * np.isfinite(qd).sum())))
    floor = creep_floor(velocity_noise)
    out = []
    for name, speed in family(params.model).transitions(params).items():
        inside, settled = transition_counts(speed, qd, floor)
        if inside < need or settled < need:
            out.append(f"{'1/a' if name == 'a' else name} {speed:.2g} rad/s ({inside} samples below"
                       + (f" and above {floor:.2g} rad/s" if floor > 0 else "")
                       + f", {settled} beyond {SETTLED:g} times it)")
    return tuple(out)
