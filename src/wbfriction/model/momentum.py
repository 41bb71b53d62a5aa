"""The generalized momentum of a tree and its rate of change without friction (issue 38).

On a tree with configuration ``q`` and velocity ``v`` (Pinocchio's conventions), the generalized momentum
is ``p = M(q) v`` and, since ``dM/dt = C + C^T``, the equation of motion
``M qdd + C(q, v) v + g(q) = S^T (tau + tau_f) + sum_e J_e^T f_e`` reads

.. math::

    \\dot p = S^T (\\tau + \\tau_f) + C(q, v)^T v - g(q) + \\sum_e J_e^T f_e ,

with no acceleration in it: the friction's impulse over a step is ``Delta p`` less the integral of the
other terms (De Luca and Mattone's momentum residual: A. De Luca, R. Mattone, "Actuator failure detection
and isolation using generalized momenta", IEEE ICRA 2003; M. Gautier's energy model of identification is
the same integral taken along ``v``). Each row holds on its own: a row whose joint torque is unknown (a
position-controlled joint) is simply not used.

:func:`momentum_and_drift` computes ``p``, ``b = C^T v - g`` and ``e = sum_e J_e^T f_e`` per sample with
Pinocchio (``crba``, ``computeCoriolisMatrix``, ``computeGeneralizedGravity``; the external wrenches through
``rnea`` with ``fext`` at rest, ``rnea(q, 0, 0, fext) = g - sum J^T f``). ``e`` is apart from ``b`` because a
sensor's wrench is read as the torques are (held over a period, or at the instants) and is integrated as they
are, where ``b`` is a smooth function of the state.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

from wbfriction.progress import Progress


def momentum_and_drift(model: pin.Model, q: np.ndarray, v: np.ndarray, rows: np.ndarray | None = None,
                       fext: Callable[[int], list] | None = None, gravity: np.ndarray | None = None,
                       progress: Progress | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``p = M(q) v``, ``b = C(q, v)^T v - g(q)`` and ``e = sum_e J_e^T f_e`` (module docstring) of each sample.

    Args:
        model: the tree (its armature is in ``M``: ``crba`` includes it).
        q: configurations (N, nq); v: velocities (N, nv).
        rows: the rows (M,) of ``rows`` of ``v`` (default all) to compute; the others are NaN.
        fext: the external forces of sample ``k`` as Pinocchio's per-joint list (joint frames), or None
            (no external force on the tree).
        gravity: the gravity vector of each sample (N, 3) [m/s²] in the tree's root frame, or None (the
            model's own): a welded foot that is not flat sees gravity tilted.
        progress: optional callable receiving numbers of samples done.

    Returns:
        ``(p, b, e)``, (N, nv) each: [kg·m²/s or kg·m/s], [N·m or N], [N·m or N] in the rows of ``v``; ``e`` zero
        without ``fext``.
    """
    n = len(q)
    p, b, e = (np.full((n, model.nv), np.nan) for _ in range(3))
    if gravity is not None:
        model = pin.Model(model)  # a copy whose gravity changes sample by sample
    data = model.createData()
    zero = np.zeros(model.nv)
    todo = np.arange(n) if rows is None else np.asarray(rows)
    for count, k in enumerate(todo, 1):
        if gravity is not None:
            model.gravity = pin.Motion(gravity[k], np.zeros(3))
        p[k] = pin.crba(model, data, q[k]) @ v[k]  # Pinocchio 4: both triangles filled
        C = pin.computeCoriolisMatrix(model, data, q[k], v[k])
        g = pin.computeGeneralizedGravity(model, data, q[k])
        b[k] = C.T @ v[k] - g
        # rnea at rest with the external forces: g - sum J^T f
        e[k] = 0.0 if fext is None else g - pin.rnea(model, data, q[k], zero, zero, fext(k))
        if progress is not None and count % 1024 == 0:
            progress(1024)
    if progress is not None and len(todo) % 1024:
        progress(len(todo) % 1024)
    return p, b, e
