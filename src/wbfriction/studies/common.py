"""What the thesis's studies share: the simulator they walk on, the leg joints they score, the sensors they add.

The studies (:mod:`~wbfriction.studies.simulation`, :mod:`~wbfriction.studies.filters`,
:mod:`~wbfriction.studies.realistic`) score the leg joints of a biped with the thesis's joint
groups (``hip_roll`` ... ``ankle_pitch``) against the thesis's Tables 6.1 and 6.2, in the
thesis's numbering (1-6 right leg, 7-12 left leg).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions
from wbfriction.fit.result import FitResult
from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import PARAM_NAMES, ModelParams
from wbfriction.model.robot import Robot
from wbfriction.progress import Steps
from wbfriction.sim.options import IdealOptions
from wbfriction.studies.thesis import TABLE_6_1, TABLE_6_2, thesis_number

SIMULATOR = IdealOptions(substeps=10)
"""The study's simulator: the controller at 1 kHz, physics at 10 kHz (semi-implicit Euler).

The log then samples a trajectory close to continuous time, as a robot's log does. With
one Euler step per sample the discrete trajectory leaves an O(dt) ambiguity between the
state's velocity and the position differences the estimator sees (semi-implicit Euler:
``(q[k] - q[k-1]) / dt`` is ``qd[k]`` exactly, the central difference is half an
acceleration step off), which biases the Coriolis terms and the fitted F_v: measured on
the combined walk, F_v off by 3.7 % at one step per sample, 1.8 % at 5, 0.9 % at 10,
0.4 % at 20 (the thesis's forward Euler at 1 kHz: 25 %)."""


ENCODER_BITS = 19
"""Encoder resolution of the studies' sensor model [bits per turn]."""
TORQUE_STD = 0.05
"""Torque-sensor noise of the studies' sensor model [N·m]."""

LegJoint = tuple[str, str, str]
"""A leg joint of the studies: (joint name, side ``left``/``right``, thesis group)."""


@dataclass
class LegRow:
    """One leg joint of the identification table."""

    joint: str
    side: str
    group: str
    number: int  # thesis numbering (1-6 right, 7-12 left)
    fit: FitResult
    thesis_6_1: tuple[float, ...] | None
    thesis_6_2: tuple[float, ...] | None


def leg_joints(robot: Robot) -> list[LegJoint]:
    """(joint, side, group) of the leg joints with a thesis group, in thesis order."""
    out = []
    for c, frame in enumerate(robot.contact_frames):
        side = "left" if "left" in frame else "right" if "right" in frame else str(c)
        for joint in robot.limb(frame):
            group = robot.group_of(joint)
            if group in THESIS_TARGETS and joint in robot.torque_controlled:
                out.append((joint, side, group))
    return sorted(out, key=lambda x: thesis_number(x[1], x[2]) if x[1] in ("left", "right") else 0)


def right_knee(legs: list[LegJoint]) -> str:
    """The right knee among the leg joints: the joint the studies' figures follow."""
    return next(j for j, side, g in legs if side == "right" and g == "knee")


def fit_legs(est: FrictionEstimate, legs: list[LegJoint], targets: Mapping[str, ModelParams] | None = None,
             fixed: dict[str, float] | None = None, progress: Steps | None = None) -> list[FitResult]:
    """Fit model (3.5) to every leg joint of an estimate on its valid samples, as
    :func:`~wbfriction.fit.joints.fit_estimate` fits every joint (its noise record, the other route), with the
    estimate's true friction and ``targets`` for the errors; ``fixed``: parameters held; ``progress``: told of the
    joints fitted."""
    return fit_estimate(est, FitOptions(model="thesis"), joints=[j for j, _, _ in legs], targets=targets or {},
                        fixed=fixed, progress=progress)


def leg_rows(legs: list[LegJoint], fits: list[FitResult]) -> list[LegRow]:
    """The rows of Tables 6.1/6.2: each leg joint's fit with its thesis number and the thesis's errors."""
    return [LegRow(j, side, g, thesis_number(side, g), f, TABLE_6_1.get((side, g)), TABLE_6_2.get((side, g)))
            for (j, side, g), f in zip(legs, fits)]


def leg_params_extra(rows: list[LegRow], thesis_errors: bool = True) -> dict[str, dict[str, Any]]:
    """Per leg joint, what a study's parameters JSON records beside the fit: thesis number, group
    and (``thesis_errors``) the thesis's errors for that joint."""
    out: dict[str, dict[str, Any]] = {}
    for r in rows:
        out[r.joint] = {"thesis_number": r.number, "group": r.group}
        if thesis_errors:
            out[r.joint].update(thesis_error_percent_table_6_1=r.thesis_6_1,
                                thesis_error_percent_table_6_2=r.thesis_6_2)
    return out


def worst_errors(rows: list[LegRow], params: tuple[str, ...] = PARAM_NAMES) -> dict[str, float]:
    """Largest error [%] of each of ``params`` over the leg joints (every row needs a fit and a target; NaN for
    no row)."""
    errors = [r.fit.error_percent() for r in rows]
    assert all(e is not None for e in errors), "a study's leg joints all have a fit and a target"
    return {n: max((e[n] for e in errors if e is not None), default=float("nan")) for n in params}


def not_ok(rows: list[LegRow]) -> list[LegRow]:
    """The rows whose fit's status is not ``ok`` (:mod:`wbfriction.fit.status`): a short walk that did not
    excite a joint (the hip yaws of a 2-step combined walk hardly turn) makes its error a statement about the
    walk, not about the estimate."""
    return [r for r in rows if not r.fit.verdict().ok]
