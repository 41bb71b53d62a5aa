"""What ``wbfriction excite`` writes of a design (a hung PD-driven robot's, a fixed-base arm's, a biped's on one
foot, a quadruped's on three): the set-points table
a robot plays (:mod:`wbfriction.logs.setpoint_table`) and the JSON document of the prediction, the margins and the
search (one writer each; the reader of the table is ``simulate --play``'s, the document is for the user and the
benchmark).

The document::

    {"robot": ..., "kind": "hung PD-driven", "criterion": ..., "worst": {"joint", "parameter", "share"},
     "chosen": {"amplitude", "reversal"},
     "candidates": [{"amplitude", "reversal", "worst", "within", "dropped" (a dropped one's: why)}, ...],
     "predicted": {"<joint>": {"<parameter>": {"value", "se", "model_error", "bound", "limit", "share", "status",
                                               "reason"}}},
     "delay": {...}, "delayed_known": bool,
     "margins": {"<joint>": {"position", "velocity", "torque"}},
     "after": {"params", "moving", "held", "prior_from_fit",                       (--after only)
               "logged": {"<joint>": {"status", "reason", "F_v": {"value", "se"}, "F_c": {...}}}}}

Units: each parameter's own (:data:`~wbfriction.actuator.identification.UNITS`); ``share`` is ``se / limit``, below
1 where the parameter is predicted ``ok``; margins are shares of each limit left unused (0: at it). A candidate the
search dropped unscored (:attr:`~wbfriction.excite.pd_design.Candidate.dropped`) has ``worst`` null and says why.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pyarrow as pa

from wbfriction.excite.arm_design import ArmDesign
from wbfriction.excite.design import ExciteOptions
from wbfriction.excite.information import limit_shares
from wbfriction.excite.next import NextRecording
from wbfriction.excite.one_foot import OneFootExcitation, OneFootOptions
from wbfriction.excite.pd_design import SHARE_LIMITS, PdDesign
from wbfriction.excite.predict import Predicted
from wbfriction.excite.tripod import TripodExcitation, TripodOptions
from wbfriction.fit.params_file import finite_or_none
from wbfriction.fit.status import WEAK
from wbfriction.fit.targets import THESIS_TARGETS, friction_by_group
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.logs.setpoint_table import setpoint_table
from wbfriction.model.robot import Robot
from wbfriction.sim.quadruped import default_quadruped_friction
from wbfriction.walking.fourier import FourierTrajectory
from wbfriction.walking.single_support import SIDES

CRITERION = ("the worst share of its status's limit (offsets 0.01 rad, others 0.25 x value) that a parameter's "
             "predicted reported standard error comes to")


def pd_setpoints(design: PdDesign) -> pa.Table:
    """The set-points table of a hung PD-driven robot's design."""
    return setpoint_table(design.robot, design.joints, design.time, design.q_des, design.qd_des,
                          kind="hung PD-driven", amplitude=design.chosen.amplitude,
                          reversal=list(design.chosen.reversal), seed=design.options.seed)


def _parameter(name: str, p: Predicted) -> dict[str, Any]:
    limit = SHARE_LIMITS.get(name, WEAK * abs(p.value))
    return {"value": p.value, "se": p.se, "model_error": p.model_error, "bound": p.bound, "limit": limit,
            "share": p.se / limit if limit > 0 else None, "status": p.status, "reason": p.reason}


def pd_document(design: PdDesign) -> dict[str, Any]:
    """The JSON document (module docstring) of a hung PD-driven robot's design."""
    joint, name, share = design.worst()
    m = design.margins
    return {
        "robot": design.robot, "kind": "hung PD-driven", "criterion": CRITERION,
        "duration": design.options.duration, "rate": design.options.rate,
        "worst": {"joint": joint, "parameter": name, "share": share},
        "chosen": {"amplitude": design.chosen.amplitude, "reversal": list(design.chosen.reversal)},
        "candidates": [{"amplitude": c.amplitude, "reversal": list(c.reversal), "worst": c.worst[2],
                        "within": c.within, **({} if c.dropped is None else {"dropped": c.dropped})}
                       for c in design.candidates],
        "predicted": {j: {n: _parameter(n, p) for n, p in params.items()}
                      for j, params in design.prediction.joints.items()},
        "delay": _parameter("delay", design.prediction.delay),
        "delayed_known": design.prediction.delayed_known,
        "margins": {j: {"position": float(m.position[i]), "velocity": float(m.velocity[i]),
                        "torque": float(m.torque[i])} for i, j in enumerate(design.joints)},
    }


def arm_setpoints(design: ArmDesign, offset) -> pa.Table:
    """The set-points table of a fixed-base arm's design, its angles in the encoders' coordinates (plus ``offset``
    (n,) [rad], the robot's ``[encoder_offset]``), its Fourier coefficients the model's."""
    d = design.design
    return setpoint_table(d.robot, d.joints, design.time, design.q_des + offset, design.qd_des, design.fourier(),
                          kind="fixed-base arm", seed=d.options.seed)


def arm_document(design: ArmDesign) -> dict[str, Any]:
    """The JSON document of a fixed-base arm's design: as :func:`pd_document`'s, its ``predicted`` the parameters of
    the family each joint's fit is predicted to choose (``models``), F_c's and F_v's with their share of the ``weak``
    limit, and ``statistical``: the standard errors without the families' spread; the design's own Cramér-Rao
    shares (``design_shares``)."""
    joint, name, share = design.prediction.worst(WEAK)
    m = design.design.margins
    return {
        "robot": design.design.robot, "kind": "fixed-base arm",
        "criterion": "the worst share of 0.25 x its value that F_c's or F_v's Cramér-Rao bound comes to (the design); "
                     "the prediction: the identification's report on the motion simulated with the sensors' noise",
        "duration": design.design.options.duration, "rate": design.design.options.rate,
        "worst": {"joint": joint, "parameter": name, "share": share},
        "models": design.prediction.models,
        "predicted": {j: {n: _parameter(n, p) if n in ("F_c", "F_v") else
                          {"value": p.value, "se": p.se, "status": p.status} for n, p in params.items()}
                      for j, params in design.prediction.joints.items()},
        "statistical": design.prediction.statistical,
        "design_shares": design.design.shares,
        "margins": {j: {"position": float(m.position[i]), "velocity": float(m.velocity[i]),
                        "torque": float(m.torque[i])} for i, j in enumerate(design.design.joints)},
    }


def swing_setpoints(robot: Robot, time: np.ndarray, angles: np.ndarray, velocities: np.ndarray,
                    joints: tuple[str, ...], trajectory: FourierTrajectory, kind: str, seed: int,
                    **where: Any) -> pa.Table:
    """The set-points table of a floating base standing while one leg swings: every actuated joint's ``angles``
    (N, n_act) [rad] (the model's) in the encoders' coordinates (plus the robot's ``[encoder_offset]``) and
    ``velocities`` (N, n_act) [rad/s] at ``time`` (N,) [s]; its metadata the swing ``joints``' series (the model's
    angles), the ``kind``, the design's ``seed`` and ``where`` it stands (``stance`` a biped's foot; ``swing``,
    ``base_height`` a quadruped's), from which ``simulate --play`` rebuilds the reference."""
    t = trajectory
    fourier = {"center": t.center, "a": t.a, "b": t.b, "omega": t.omega}
    return setpoint_table(robot.name, robot.actuated, time, angles + robot.offset_vector, velocities, fourier,
                          fourier_joints=joints, kind=kind, seed=seed, **where)


def one_foot_setpoints(robot: Robot, excitation: OneFootExcitation, options: OneFootOptions) -> pa.Table:
    """The set-points table of a biped's one-foot stance (:func:`swing_setpoints`: its metadata the stance foot and
    the swing leg's series), from which ``simulate --play`` rebuilds the reference
    (:func:`~wbfriction.walking.single_support.single_support_reference`)."""
    ref = excitation.reference
    return swing_setpoints(robot, ref.time, robot.angles(ref.q), ref.v[:, robot.act_v_index], excitation.joints,
                           excitation.trajectory, "biped on one foot", options.design.seed,
                           stance=SIDES[excitation.stance])


def tripod_setpoints(robot: Robot, excitation: TripodExcitation, options: TripodOptions) -> pa.Table:
    """The set-points table of a quadruped on three feet (:func:`swing_setpoints`: its metadata the swing foot, the
    base's height and the swing leg's series), from which ``simulate --play`` rebuilds the reference
    (:func:`~wbfriction.walking.tripod_support.tripod_support_reference`)."""
    ref = excitation.reference
    return swing_setpoints(robot, ref.time, ref.q, ref.qd, excitation.joints, excitation.trajectory,
                           "quadruped on three feet", options.design.seed,
                           swing=robot.contact_frames[excitation.swing], base_height=options.height)


def swing_rows(robot: Robot, joints: tuple[str, ...], band: tuple[np.ndarray, np.ndarray], angles: np.ndarray,
               speed: np.ndarray, bounds: Mapping[str, Mapping[str, float]],
               prior: Mapping[str, ModelParamsBase], asked: tuple[str, ...]) -> dict[str, dict[str, Any]]:
    """Each swing joint's row of a standing design's document: its band ``(lower, upper)`` (n,) each [rad], the
    range its ``angles`` (N, n) [rad] reach, the peak of its ``speed`` (N, n) [rad/s], its Cramér-Rao ``bounds``
    and their shares of :data:`~wbfriction.fit.status.WEAK` times its ``prior``'s values (the ``asked``
    parameters)."""
    rows = {}
    for i, j in enumerate(joints):
        shares = limit_shares(bounds[j], prior[j], asked)
        rows[j] = {"band": [float(band[0][i]), float(band[1][i])],
                   "reached": [float(angles[:, i].min()), float(angles[:, i].max())],
                   "peak_velocity": float(speed[:, i].max()), "bound": dict(bounds[j]),
                   "share": {n: float(x) for n, x in zip(asked, shares)}}
    return rows


def _standing(robot: Robot, kind: str, design: ExciteOptions, velocity: float) -> dict[str, Any]:
    """The fields a standing design's document opens with."""
    return {"robot": robot.name, "kind": kind,
            "criterion": f"each swing joint's worst share of {WEAK:g} x its prior's value that F_c's or F_v's "
                         "Cramér-Rao bound comes to, within its posture band and below the velocity cap",
            "duration": design.duration, "rate": design.rate, "period": design.period,
            "harmonics": design.harmonics, "velocity_cap": velocity}


def one_foot_document(robot: Robot, excitation: OneFootExcitation, options: OneFootOptions,
                    bounds: Mapping[str, Mapping[str, float]]) -> dict[str, Any]:
    """The JSON document of a biped's one-foot stance::

        {"robot", "kind": "biped on one foot", "stance": "left"|"right", "duration" [s], "rate" [Hz], "period" [s],
         "harmonics", "velocity_cap" [rad/s], "zmp_margin" [m], "clearance" [m], "limits": {"zmp_margin",
         "clearance"} [m],
         "swing": {"<joint>": {"band": [lower, upper] [rad], "reached": [min, max] [rad], "peak_velocity" [rad/s],
                               "bound": {"<parameter>": its Cramér-Rao bound}, "share": {"F_c", "F_v"}}}}

    ``bounds``: each swing joint's Cramér-Rao bounds (:func:`~wbfriction.excite.one_foot.swing_bounds`); ``share``
    is the bound over :data:`~wbfriction.fit.status.WEAK` of the prior's value (below 1: ``ok`` at best)."""
    ref = excitation.reference
    act = [robot.actuated.index(j) for j in excitation.joints]
    angles, speed = robot.angles(ref.q)[:, act], np.abs(ref.v[:, robot.act_v_index[act]])
    swing = swing_rows(robot, excitation.joints, (excitation.lower, excitation.upper), angles, speed, bounds,
                       friction_by_group(robot.groups, THESIS_TARGETS), options.design.asked)
    return {**_standing(robot, "biped on one foot", options.design, options.velocity),
            "stance": SIDES[excitation.stance], "zmp_margin": excitation.zmp_margin,
            "clearance": excitation.clearance,
            "limits": {"zmp_margin": options.zmp_margin, "clearance": options.clearance}, "swing": swing}


def tripod_document(robot: Robot, excitation: TripodExcitation, options: TripodOptions,
                    bounds: Mapping[str, Mapping[str, float]]) -> dict[str, Any]:
    """The JSON document of a quadruped on three feet: as :func:`one_foot_document`'s, with ``"kind": "quadruped on
    three feet"``, ``"swing_foot"`` (the lifted foot's contact frame), ``"stance_feet"`` (the three others),
    ``"base_height"`` [m], the margins ``"com_margin"``, ``"zmp_margin"`` (to the stance triangle's edges),
    ``"clearance"`` (the swing foot's sphere above the ground), ``"spacing"`` (the swing leg to the others) [m] and
    their ``"limits"``; ``bounds``: :func:`~wbfriction.excite.tripod.swing_bounds`' (the prior: the quadruped
    simulators' default friction)."""
    ref = excitation.reference
    act = [robot.actuated.index(j) for j in excitation.joints]
    swing = swing_rows(robot, excitation.joints, (excitation.lower, excitation.upper), ref.q[:, act],
                       np.abs(ref.qd[:, act]), bounds, default_quadruped_friction(robot), options.design.asked)
    limits = {n: getattr(options, n) for n in ("com_margin", "zmp_margin", "clearance", "spacing")}
    return {**_standing(robot, "quadruped on three feet", options.design, options.velocity),
            "swing_foot": robot.contact_frames[excitation.swing],
            "stance_feet": [robot.contact_frames[c] for c in excitation.stance], "base_height": options.height,
            **{n: float(getattr(excitation, n)) for n in limits}, "limits": limits, "swing": swing}


def next_document(following: NextRecording[PdDesign] | NextRecording[ArmDesign], params: str) -> dict[str, Any]:
    """The ``after`` entry of a design's document (module docstring) made after the log whose parameters file is
    ``params`` (:mod:`~wbfriction.excite.next`): the joints moved and held, those whose prior is their fit, and per
    moving joint what the log's fit gave (its status and reason, each compared parameter's value and the standard
    error a user reads; null where the file has none)."""
    design = following.design
    logged = {j: {"status": lg.status, "reason": lg.reason,
                  **{n: {"value": finite_or_none(v), "se": finite_or_none(se)} for n, (v, se) in lg.values.items()}}
              for j, lg in following.logged.items()}
    return {"params": params, "moving": list(design.moving),
            "held": [j for j in design.joints if j not in design.moving],
            "prior_from_fit": list(following.prior_from_fit), "logged": logged}
