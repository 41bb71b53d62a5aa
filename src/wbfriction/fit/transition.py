"""Whether a log resolves a friction family's transitions (issue 63): a shape kept only where the data carry it.

A family's shape parameters act at a speed (:meth:`~wbfriction.friction.families.base.FrictionFamily.transitions`):
the Stribeck velocity ``v_s`` (3.3), ``1 / a`` of the thesis's ``tanh(a qd)`` (3.5). A fit places them wherever they
lower its residual, and where few samples lie around them they fit the noise, or a joint's creep: a walking robot's
stance leg creeps at 0.003-0.02 rad/s, its friction there a function of the load and the contact, not of the
velocity, and a Stribeck curve whose ``v_s`` sits among those samples predicts nothing the next step does (issue 63:
such fits `ok` and 100 % off on a crawl made elsewhere). A transition is *resolved* when at least
:data:`TRANSITION_SAMPLES` samples (and :data:`TRANSITION_SHARE` of those fitted) lie inside it, between half its
speed and its speed, and as many beyond it, between its speed and three times it; speeds below the creep floor
(:func:`creep_floor`: :data:`~wbfriction.fit.status.MIN_SPEED`, or three standard deviations of the velocity's
noise) count as neither. A family with a transition its data do not resolve is not a candidate of the automatic
choice (:mod:`~wbfriction.fit.selection`): creep below a transition is not evidence for it.
"""

from __future__ import annotations

import numpy as np

from wbfriction.fit.status import MIN_SPEED
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import ModelParamsBase

TRANSITION_SAMPLES = 20
"""The fewest samples inside a transition, and beyond it, that resolve it."""
TRANSITION_SHARE = 0.005
"""... and the smallest share of the samples fitted, in each."""
NOISE_SIGMAS = 3.0
"""Speeds below this many standard deviations of the velocity's noise are noise, not a transition's evidence."""


def creep_floor(velocity_noise: float = 0.0) -> float:
    """The speed [rad/s] below which samples are no evidence of a transition: :data:`MIN_SPEED` (what the statuses
    call not moving), or :data:`NOISE_SIGMAS` standard deviations of the velocity's noise ``velocity_noise``
    [rad/s] where that is more."""
    return max(MIN_SPEED, NOISE_SIGMAS * float(velocity_noise))


def transition_counts(speed: float, qd: np.ndarray, floor: float) -> tuple[int, int]:
    """How many of the velocities ``qd`` (n,) [rad/s] lie inside a transition at ``speed`` [rad/s] (``|qd|`` in
    ``[max(speed / 2, floor), speed)``) and beyond it (in ``[max(speed, floor), 3 speed)``)."""
    v = np.abs(np.asarray(qd, dtype=float))
    v = v[np.isfinite(v)]
    inside = (v >= max(0.5 * speed, floor)) & (v < speed)
    beyond = (v >= max(speed, floor)) & (v < 3.0 * speed)
    return int(inside.sum()), int(beyond.sum())


def unresolved(params: ModelParamsBase, qd: np.ndarray, velocity_noise: float = 0.0) -> tuple[str, ...]:
    """The transitions of ``params`` (:meth:`~wbfriction.friction.families.base.FrictionFamily.transitions`) the
    velocities ``qd`` (n,) [rad/s] of the samples fitted do not resolve (module docstring), one phrase each, e.g.
    ``"v_s 0.008 rad/s (0 samples inside, 3 beyond, above 0.02 rad/s)"``; empty when every one is resolved."""
    qd = np.asarray(qd, dtype=float)
    need = max(TRANSITION_SAMPLES, int(np.ceil(TRANSITION_SHARE * np.isfinite(qd).sum())))
    floor = creep_floor(velocity_noise)
    out = []
    for name, speed in family(params.model).transitions(params).items():
        inside, beyond = transition_counts(speed, qd, floor)
        if min(inside, beyond) < need:
            out.append(f"{'1/a' if name == 'a' else name} {speed:.2g} rad/s ({inside} samples inside, {beyond} beyond, above {floor:.2g} "
                       "rad/s)")
    return tuple(out)
