"""The loop the thesis proposed (ch. 8): identify the inertia model, then estimate the friction with it.

1. The acceleration route with the given model (:func:`~wbfriction.estimate.estimate_log`,
   fit of (3.5) per joint) gives a first Stribeck velocity ``v_s``: the median over the
   joints whose fit determines it.
2. The inertia model and the friction are identified together from the torques
   (:func:`~wbfriction.inertial.identify_inertia`, prior toward the given model), with
   the Stribeck term's ``v_s`` held at that value (it enters non-linearly).
3. The acceleration route is run again with the identified model. Its fits give a better
   ``v_s``, and step 2 is repeated from the given model with it, ``passes`` times in all.

Each pass is kept, so that a user sees both routes' friction side by side and how the
identification moved between passes.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable, Literal

import numpy as np

from .energy import JointEnergy, energy_consistency
from .estimate import EstimateOptions, FrictionEstimate, estimate_log
from .identify import FitResult, fit_table_estimate, fitted_offsets
from .inertial import InertialIdentification, InertialOptions, identify_inertia
from .log import Log
from .robot import Robot
from .urdf import inertia_changes


@dataclass
class Route:
    """The acceleration route (thesis ch. 5) on one model: estimate, fits and energy check."""

    estimate: FrictionEstimate
    fits: list[FitResult]
    energy: list[JointEnergy]

    def fit(self, joint: str) -> FitResult:
        return next(f for f in self.fits if f.joint == joint)


@dataclass
class LoopPass:
    """One identification (its ``v_s``, and the joints given a Stribeck term: None for all)
    and the acceleration route with its model."""

    stribeck_velocity: float | None
    stribeck_joints: tuple[str, ...] | None
    identification: InertialIdentification
    route: Route


@dataclass
class ClosedLoop:
    """Result of :func:`identify_and_estimate`: the given model's route, then each pass."""

    given: Route
    passes: list[LoopPass]

    @property
    def final(self) -> LoopPass:
        return self.passes[-1]


def acceleration_route(robot: Robot, log: Log, options: EstimateOptions, min_samples: int = 20,
                       workers: int = 1) -> Route:
    """Estimate (5.10-5.13) and fit (3.5) every torque-controlled joint (on ``workers``
    processes), and check energy (7.9)."""
    est = estimate_log(robot, log, options)
    fits = fit_table_estimate(est, min_samples=min_samples, workers=workers)
    return Route(est, fits, energy_consistency(est, fitted_offsets(fits)))


def stribeck_velocity(fits: list[FitResult], max_relative_error: float = 0.5) -> tuple[float | None, tuple[str, ...]]:
    """The joints whose fit determines a Stribeck effect (``v_s``, ``F_c`` and the height ``S``
    with standard errors below ``max_relative_error`` of their values), and their median
    Stribeck velocity [rad/s] (None if there are none)."""
    def determined(f: FitResult) -> bool:
        p = f.params
        return p is not None and all(getattr(p, n) > 0 and f.stderr.get(n, np.inf) < max_relative_error * getattr(p, n)
                                     for n in ("v_s", "F_c", "S"))
    good = [f for f in fits if determined(f)]
    return (float(np.median([f.params.v_s for f in good])) if good else None), tuple(f.joint for f in good)


def identify_and_estimate(robot: Robot, log: Log, estimate_options: EstimateOptions = EstimateOptions(),
                          options: InertialOptions = InertialOptions(),
                          stribeck: float | Literal["auto"] | None = "auto", passes: int = 2,
                          progress: Callable[[str], None] | None = None, workers: int = 1) -> ClosedLoop:
    """Run the loop (module docstring).

    Args:
        robot: the given model (its URDF's inertias).
        log: a walking log with single-support stretches.
        estimate_options: the acceleration route's options; the identification differentiates alike.
        options: the identification's (:class:`~wbfriction.inertial.InertialOptions`; its
            ``stribeck_velocity`` is set here).
        stribeck: ``"auto"``: ``v_s`` from the acceleration route, ``passes`` times; a number
            [rad/s]: that ``v_s``, one pass; None: no Stribeck term, one pass.
        passes: identifications with ``"auto"`` (at least 1).
        progress: called with a label as each stage starts.
        workers: processes fitting the joints of the acceleration route side by side.

    Raises:
        InputError: what :func:`~wbfriction.estimate.estimate_log` and
            :func:`~wbfriction.inertial.identify_inertia` raise.
    """
    say = progress or (lambda label: None)
    say("acceleration route with the given model")
    given = acceleration_route(robot, log, estimate_options, workers=workers)
    if stribeck != "auto":
        passes = 1
    v_s, joints = stribeck_velocity(given.fits) if stribeck == "auto" else (stribeck, None)
    done: list[LoopPass] = []
    for k in range(max(passes, 1)):
        say(f"identifying the inertia model (pass {k + 1}, v_s = {v_s if v_s is None else round(v_s, 4)})")
        ident = identify_inertia(robot, log, estimate_options,
                                 replace(options, stribeck_velocity=v_s, stribeck_joints=joints))
        say(f"acceleration route with the identified model (pass {k + 1})")
        route = acceleration_route(ident.robot, log, estimate_options, workers=workers)
        done.append(LoopPass(v_s, joints, ident, route))
        if stribeck == "auto":
            found = stribeck_velocity(route.fits)
            if found[0] is not None:
                v_s, joints = found
    return ClosedLoop(given, done)


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def loop_document(loop: ClosedLoop, moved: tuple[str, ...] = ()) -> dict:
    """The loop as a JSON-ready dict (``wbfriction identify --json``, read by the report):
    per pass the identification's size and condition; per body the changes
    (:func:`wbfriction.urdf.inertia_changes`); per torque-controlled joint the friction of
    both routes, the power-generating shares before and after, and the held-out torque RMS.
    ``moved``: what :func:`wbfriction.urdf.write_urdf` returned."""
    final = loop.final
    ident = final.identification
    changes = inertia_changes(ident.bodies, ident.pi_given, ident.pi)
    energy_given = {e.joint: e for e in loop.given.energy}
    energy = {e.joint: e for e in final.route.energy}
    joints = {}
    for i, joint in enumerate(ident.robot.torque_controlled):
        joints[joint] = {
            "identified": dict(zip(ident.friction_names, map(float, ident.friction[i]))),
            "acceleration_route": final.route.fit(joint).to_dict(),
            "acceleration_route_given_model": loop.given.fit(joint).to_dict(),
            "generating_share_given_model": _finite(energy_given[joint].generating_share),
            "generating_share": _finite(energy[joint].generating_share),
            "holdout_rms": {"given": float(ident.holdout.given[i]),
                            "given_with_friction": float(ident.holdout.given_with_friction[i]),
                            "identified": float(ident.holdout.identified[i])},
        }
    return {
        "sign_convention": "tau_f = -f(qd); f = F_v qd + F_c tanh(a qd) (+ (F_s - F_c) tanh(a qd) exp(-(qd/v_s)^2)) + tau_os",
        "passes": [{"stribeck_velocity": p.stribeck_velocity,
                    "stribeck_joints": None if p.stribeck_joints is None else list(p.stribeck_joints),
                    "samples": p.identification.samples,
                    "base_parameters": p.identification.base.count,
                    "parameters": int(p.identification.base.combination.shape[1]),
                    "condition": _finite(p.identification.base.condition),
                    "prior": p.identification.prior,
                    "prior_scores": {f"{w:g}": v for w, v in p.identification.prior_scores.items()},
                    "message": p.identification.message} for p in loop.passes],
        "holdout_samples": ident.holdout.samples,
        "moved_to_child_link": list(moved),
        "bodies": [{"body": c.body, "mass_given": c.mass_given, "mass": c.mass, "mass_change": _finite(c.mass_change),
                    "com_shift": c.com_shift, "moments_given": c.moments_given.tolist(), "moments": c.moments.tolist(),
                    "moments_change": [_finite(x) for x in c.moments_change]} for c in changes],
        "joints": joints,
    }
