"""The loop the thesis proposed (ch. 8): identify the inertia model, then estimate the friction with it.

1. The acceleration route with the given model (:func:`~wbfriction.friction.estimate.estimate_log`,
   fit of (3.5) per joint, Coulomb-viscous for a joint that hardly moved) gives a first Stribeck velocity
   ``v_s``: the median over the joints whose fit determines it.
2. The inertia model and the friction are identified together from the torques
   (:func:`~wbfriction.inertia.identification.identify_inertia`, prior toward the given model), with
   the Stribeck term's ``v_s`` held at that value (it enters non-linearly).
3. The acceleration route is run again with the identified model. Its fits give a better
   ``v_s``, and step 2 is repeated from the given model with it, ``passes`` times in all.

Each pass is kept, so that a user sees both routes' friction side by side and how the
identification moved between passes. What does not depend on the model or on ``v_s`` is done once:
the choice of differentiation (``diff = "auto"``) and the log's kinematics and split of its samples
(:func:`~wbfriction.inertia.samples.log_samples`). An armature identified in step 2 is the
identified model's (``model.armature``): step 3's acceleration route uses it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from wbfriction.fit.energy import JointEnergy, energy_consistency
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions
from wbfriction.fit.result import FitResult, fitted_offsets
from wbfriction.friction.estimate import FrictionEstimate, estimate_log, resolve_differentiation
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.identification import InertialIdentification, identify_inertia
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.samples import log_samples
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot
from wbfriction.progress import StageProgress, Steps
from wbfriction.signals.choice import DiffChoice


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
    """Result of :func:`identify`: the given model's route, then each pass."""

    given: Route
    passes: list[LoopPass]

    @property
    def final(self) -> LoopPass:
        return self.passes[-1]


def acceleration_route(robot: Robot, log: Log, options: EstimateOptions, min_samples: int = 20,
                       workers: int = 1, choice: DiffChoice | None = None, steps: Steps | None = None) -> Route:
    """Estimate (5.10-5.13) and fit (3.5) every torque-controlled joint (on ``workers``
    processes), and check energy (7.9). A joint that hardly moved (status ``not excited``) is given the
    Coulomb-viscous model instead, as ``wbfriction fit`` gives it: its data hold an offset, no Stribeck term.
    ``choice``: how ``options``' differentiation was chosen
    (:func:`~wbfriction.friction.estimate.resolve_differentiation`, done once for several routes),
    recorded in the estimate's metadata as :func:`~wbfriction.friction.estimate.estimate_log` does. ``steps``: told
    of the fit's stages, counted in joints (:func:`~wbfriction.fit.joints.fit_estimate`)."""
    est = estimate_log(robot, log, options)
    if choice is not None:
        est.metadata["differentiation"] = choice.to_dict()
    fits = fit_estimate(est, FitOptions(model="thesis", min_samples=min_samples), workers=workers,
                        still="coulomb-viscous", progress=steps)
    return Route(est, fits, energy_consistency(est, fitted_offsets(fits)))


def stribeck_velocity(fits: list[FitResult], max_relative_error: float = 0.5) -> tuple[float | None, tuple[str, ...]]:
    """The joints whose fit determines a Stribeck effect (``v_s``, ``F_c`` and the height ``S``
    with standard errors below ``max_relative_error`` of their values; a fit of a model without them, none), and
    their median Stribeck velocity [rad/s] (None if there are none)."""
    stribeck = ("v_s", "F_c", "S")
    good = {f.joint: f.params.v_s for f in fits if f.params is not None
            and set(stribeck) <= set(f.params.names)
            and all(getattr(f.params, n) > 0 and f.stderr.get(n, np.inf) < max_relative_error * getattr(f.params, n)
                    for n in stribeck)}
    return (float(np.median(list(good.values()))) if good else None, tuple(good))


def identify(robot: Robot, log: Log, estimate_options: EstimateOptions = EstimateOptions(),
                          options: InertialOptions = InertialOptions(),
                          stribeck: float | Literal["auto"] | None = "auto", passes: int = 2,
                          progress: StageProgress | None = None, workers: int = 1,
                          steps: Steps | None = None) -> ClosedLoop:
    """Run the loop (module docstring).

    Args:
        robot: the given model (its URDF's inertias).
        log: a walking log with single-support stretches.
        estimate_options: the acceleration route's options; the identification differentiates alike.
        options: the identification's (:class:`~wbfriction.inertia.options.InertialOptions`; its
            ``stribeck_velocity`` is set here).
        stribeck: ``"auto"``: ``v_s`` from the acceleration route, ``passes`` times; a number
            [rad/s]: that ``v_s``, one pass; None: no Stribeck term, one pass.
        passes: identifications with ``"auto"`` (at least 1).
        progress: called with a label as each stage starts.
        workers: processes fitting the joints of the acceleration route side by side.
        steps: told of the stages of counted items (each route's fit, its joints; :data:`~wbfriction.progress.Steps`).

    Raises:
        InputError: what :func:`~wbfriction.friction.estimate.estimate_log` and
            :func:`~wbfriction.inertia.identification.identify_inertia` raise.
    """
    say = progress or (lambda label: None)
    estimate_options, choice = resolve_differentiation(estimate_options, log)  # once for every route and pass
    say("estimating with the given model (acceleration route)")
    given = acceleration_route(robot, log, estimate_options, workers=workers, choice=choice, steps=steps)
    if stribeck != "auto":
        passes = 1
    v_s, joints = stribeck_velocity(given.fits) if stribeck == "auto" else (stribeck, None)
    done: list[LoopPass] = []
    say("the identification's samples (its dynamics at every sample)")
    samples = log_samples(robot, log, estimate_options, options)  # the passes differ in v_s only
    for k in range(max(passes, 1)):
        say(f"identifying the inertia model (pass {k + 1}, v_s = {v_s if v_s is None else round(v_s, 4)})")
        ident = identify_inertia(robot, log, estimate_options,
                                 replace(options, stribeck_velocity=v_s, stribeck_joints=joints), shared=samples)
        say(f"estimating with the identified model (pass {k + 1})")
        route = acceleration_route(ident.robot, log, estimate_options, workers=workers, choice=choice, steps=steps)
        done.append(LoopPass(v_s, joints, ident, route))
        if stribeck == "auto":
            found = stribeck_velocity(route.fits)
            if found[0] is not None:
                v_s, joints = found
    return ClosedLoop(given, done)
