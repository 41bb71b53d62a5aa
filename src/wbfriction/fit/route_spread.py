"""The route spread: what the two routes' difference shows of the friction estimate's bias, as a standard error
(issue 63).

``estimate`` computes the friction torque by two routes, the acceleration's (the equations of motion with the
positions differentiated twice) and the generalized momentum's (an observer, one differentiation fewer), and ``fit``
fits the same model on both (:func:`~wbfriction.fit.result.compare_routes`). The routes share the log and its noise
but not their errors of method: the differentiation's lag and smoothing, the observer's, a stance leg's creep seen
through one route's accelerations and the other's momenta. Each fitted value is ``theta + beta + e``: the truth, its
route's bias ``beta`` and the statistical error ``e`` the Newey-West and block errors describe. The bias is the
same in every block of the log where it does not change, so no statistical error sees it; the difference
``d = a - b`` of the routes' values holds the difference of their biases, and is the only evidence of them the log
gives.

**How it enters.** With nothing to tell the routes' biases apart, take them as exchangeable: independent, of mean 0
and one variance ``s^2``. Then ``E d^2 = 2 s^2 + var(e_a - e_b)`` and ``|d| / sqrt(2)`` (:data:`ROUTE_SHARE`) is
the moment estimate of ``s``, a share of the difference between half (the biases equal and opposite) and the whole
(one route unbiased, which one unknown). It enters each route's read error in quadrature
(:func:`~wbfriction.fit.status.read_error`). Two limits bound what it promises: where one route alone is biased
(the acceleration route's differentiation, the common case), ``±2 |d| / sqrt(2)`` covers that bias whole; where
both are, one difference is one draw, and with the read error the route spread alone ``±2`` of them covers the
bias with probability 0.76 (the normal model above; the statistical and family spreads in quadrature raise it).
The difference also holds the statistical errors' difference, counted twice with ``e``: at most a factor
``sqrt(2)`` on a read error where the routes have no bias, a conservative error chosen over one that may be
short. A bias both routes share (the robot's model, the contact model's forces in both) is not in ``d``: the
route spread cannot show it.

**What the check of the routes then tests** (:func:`~wbfriction.fit.status.routes_disagree`): the difference
against the errors each route shows of itself, the statistical ones (the Newey-West error raised to the block
jackknife's: :func:`~wbfriction.fit.block_spread.statistical_error`), never against the route spread, which is
``d`` itself (``|d| > 3 sqrt(2) |d| / sqrt(2)`` never holds: the check would be vacuous). A difference within
what the blocks show each route's value to wander by is no bias; beyond :data:`~wbfriction.fit.status.ROUTE_Z`
of those errors (and :data:`~wbfriction.fit.status.ROUTE_REL` of the value) it is, and the status says so, with
the read error now carrying it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

ROUTE_SHARE = 1.0 / math.sqrt(2.0)
"""The share of the routes' difference each route's read error carries (module docstring: the moment estimate of
one route's bias under exchangeable biases)."""


def route_spread(mine: Mapping[str, float], theirs: Mapping[str, float] | None, names: Iterable[str],
                 share: float = ROUTE_SHARE) -> dict[str, float]:
    """Per parameter of ``names`` in both ``mine`` and ``theirs`` (the two routes' values of one model, by name, in
    the parameter's unit), ``share`` (:data:`ROUTE_SHARE`) of their difference ``|a - b|`` [the parameter's unit];
    {} without the other route's values. Values that are not finite give none."""
    if theirs is None:
        return {}
    out = {}
    for n in names:
        a, b = mine.get(n), theirs.get(n)
        if a is not None and b is not None and math.isfinite(a) and math.isfinite(b):
            out[n] = share * abs(float(a) - float(b))
    return out
