"""PD-driven actuators identified from a hung robot's log: each joint's armature, friction and encoder offset, and
the drivers' delay, each with its standard error, Cramér-Rao bound and status (issue 55).

The balance of :mod:`wbfriction.actuator.rows` is solved by :mod:`wbfriction.actuator.solve`: the delay searched
exactly around the linear problem, then the bounded solution. Passes (:data:`~wbfriction.actuator.options.PASSES`):
the first weights each joint's rows by the noise its sensors predict, the next by its residuals' RMS, and each
takes the dynamics again about the offsets the previous one found. A check on data the fit did not see: the same
identification on the log's first windows predicts its last ``holdout`` share (:func:`held_out_rms`).

What the log determines (issue 63): a joint that hardly moved leaves its values ``not excited``, one that moved one
way its F_c and offset ``weak`` (:mod:`wbfriction.actuator.excitation`); a delay at the search's upper bound leaves
every value fitted under it ``at bound``. Where the robot TOML's PD law and the URDF's dynamics disagree (a joint's
scale of the law off 1 beyond three standard errors: :mod:`wbfriction.actuator.law_check`, which names it, and a TOML
delay that is not the one found), how far that joint's values move with the scale freed is added to their standard
errors in quadrature. What ``--config-output`` writes is chosen on held-out blocks of the log
(:mod:`wbfriction.actuator.written`), not by the statuses. Standard errors are the autocorrelation-consistent
sandwich's (:func:`~wbfriction.actuator.solve.sandwich`) with how far each value moves under a Coulomb term
:data:`~wbfriction.actuator.options.STEEPER` times as steep (the delay searched again) added in quadrature, a model
error the residuals do not show, and never below the Cramér-Rao bound: :attr:`Identified.se` is ``max(se, crb)``.
Stamps with receive-time jitter are taken on the regularised clock the log's reader found
(:mod:`wbfriction.logs.clock`), before the delay is searched.

What the delay holds back (``delayed``: the set-points, or the whole torque) is chosen by the balance: the one that
closes it best. On steady motion the two differ by a viscous torque ``kp delay qd``
(:meth:`~wbfriction.model.pd.PdDriver.viscous_equivalent`), which F_v takes up; they differ otherwise only at the
reversals. Where the best does not close the balance better than the other by more than
:data:`~wbfriction.fit.selection.GAIN_Z` Newey-West standard errors of the per-window difference
(:func:`structure_gain`), the log does not tell which: the friction's standard errors then have their distance to
the other's values added in quadrature (:data:`STRUCTURE_SPREAD`; on the real Aliengo, F_v 0 on ten joints with the
set-points delayed, 0.14-0.61 with the torque, 0.33 higher where both are interior: ``kp delay`` is 0.28), the
identification says so (:attr:`ActuatorIdentification.delayed_known`) and ``--config-output`` writes
``delayed_known = false``, from which the friction fitted afterwards carries ``kp delay`` in F_v's standard error
(:mod:`wbfriction.fit.joints`).

PACE (Bjelonic et al., "Towards Bridging the Gap: Systematic Sim-to-Real Transfer for Diverse Legged Robots",
2025) and the iit-DLSLab identification fit the same quantities by CMA-ES over simulated rollouts; here the problem
is linear but for the delay, solved in seconds on a CPU.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from threadpoolctl import threadpool_limits

from wbfriction.actuator.excitation import JointMotion, joint_motion
from wbfriction.actuator.law_check import LawCheck, check_law
from wbfriction.actuator.options import ActuatorOptions
from wbfriction.actuator.rows import BalanceRows, balance_rows, pd_joints
from wbfriction.actuator.solve import (
    KINDS,
    DelaySearch,
    Design,
    Solution,
    block_grown,
    design,
    hac_lags,
    search_delay,
    solve,
)
from wbfriction.actuator.written import WrittenChoice, choose_written
from wbfriction.exceptions import InputError
from wbfriction.fit.regression import held_out_gain
from wbfriction.fit.selection import GAIN_Z
from wbfriction.fit.status import WEAK
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot

ActuatorStatus = Literal["ok", "weak", "does not predict", "at bound", "not excited"]
"""A parameter's verdict (:func:`parameter_status`)."""
OFFSET_WEAK = 0.01
"""An encoder offset whose standard error or bound exceeds this [rad] (0.57°) is ``weak``: an a priori resolution
(a gravity torque's change over it is below the friction of the joints this is for), not fitted on data."""
OFFSET_PLAUSIBLE = 0.1
"""An encoder offset beyond this [rad] (5.7°, PACE's search bound on the Aliengo) is ``weak``: more than a joint's
encoder is mis-set by; a gravity model that is off (masses, centres of mass) fits so too. An a priori limit, not
fitted on data."""
HOLDOUT_RATIO = 2.0
"""A joint whose balance on held-out windows has more than this times the RMS of the windows fitted does not
predict (an a priori factor: with the same noise the ratio is about 1)."""
UNITS = {"armature": "kg·m²", "F_v": "N·m·s/rad", "F_c": "N·m", "offset": "rad", "delay": "s"}


@dataclass(frozen=True)
class Identified:
    """One identified value.

    Attributes:
        value: the value, in :data:`UNITS` of its kind.
        se: its standard error: the residuals' autocorrelation-consistent one
            (:func:`~wbfriction.actuator.solve.sandwich`) with the nuisance model's sensitivity
            (:data:`~wbfriction.actuator.options.STEEPER`) in quadrature, or the Cramér-Rao bound, the larger; inf
            where the data do not determine it.
        crb: its Cramér-Rao bound (the standard deviation any unbiased estimator has at the sensors' noise).
        status: :data:`ActuatorStatus`.
        reason: why, when not ``ok``.
    """

    value: float
    se: float
    crb: float
    status: ActuatorStatus = "ok"
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"value": self.value, "se": _finite(self.se), "crb": _finite(self.crb), "status": self.status,
                "reason": self.reason}


@dataclass(frozen=True)
class JointActuator:
    """One PD-driven joint's identification.

    Attributes:
        joint: its name.
        armature: the rotor's inertia at the joint [kg·m²].
        F_v, F_c: the Coulomb-viscous friction on the motor side [N·m·s/rad, N·m] (the identification's own
            model: the family is fitted afterwards on the friction estimated with this armature and delay).
        offset: the encoder offset, the logged angle minus the model's [rad] (None: not fitted).
        rms, held_out_rms: the balance's residual RMS on the windows fitted and on the held-out ones [N·m·s].
        rows: the windows used.
    """

    joint: str
    armature: Identified
    F_v: Identified
    F_c: Identified
    offset: Identified | None
    rms: float
    held_out_rms: float
    rows: int

    def parameters(self) -> dict[str, Identified]:
        out = {"armature": self.armature, "F_v": self.F_v, "F_c": self.F_c}
        return out | ({"offset": self.offset} if self.offset is not None else {})

    def with_values(self, values: dict[str, Identified]) -> JointActuator:
        """This joint with its :meth:`parameters` replaced by ``values`` (the same kinds)."""
        return replace(self, armature=values["armature"], F_v=values["F_v"], F_c=values["F_c"],
                       offset=values.get("offset"))


@dataclass(frozen=True)
class ActuatorIdentification:
    """A hung PD-driven robot's actuators identified from one log (module docstring).

    Attributes:
        joints: one :class:`JointActuator` per PD-driven joint.
        delay: the drivers' set-point delay [s] (one for the robot).
        period: the log's sampling period [s].
        window: the window the balance is summed over [s].
        profile: (K + 2, 2) the delay [s] and the weighted squared residual at every whole period searched.
        position_noise, velocity_noise: joint -> the encoders' and drivers' white noise [rad, rad/s].
        source: the log.
        options: the options used (``velocity`` the one kept).
        sigma: each joint's balance noise per window the sensors predict [N·m·s].
        velocity_reason: which velocity the dynamics took and what the delay holds back, and why.
        clock: what the log's time stamps are and the time base taken (:attr:`Clock.reason
            <wbfriction.logs.clock.Clock.reason>`; "" for a log built in memory).
        law: the robot TOML's PD law checked against the log (:class:`~wbfriction.actuator.law_check.LawCheck`).
        warnings: what the identification found wrong in its input, one line each (the PD law's mismatches).
        delayed_known: whether the log tells what the delay holds back (module docstring; True where only one was
            tried).
        written: what ``--config-output`` writes, each value chosen against the robot TOML's on held-out blocks of
            the log (:mod:`wbfriction.actuator.written`); None for a result built without it.
        residuals: (W, n) each window's balance residual over the noise its sensors predict (NaN where not used),
            for comparing identifications of one log; not written.
        balance, weight: the balance solved (its last pass) and its joints' weights, for :attr:`written`; not
            written.
    """

    joints: tuple[JointActuator, ...]
    delay: Identified
    period: float
    window: float
    profile: np.ndarray
    position_noise: dict[str, float]
    velocity_noise: dict[str, float]
    source: str
    options: ActuatorOptions = field(default_factory=ActuatorOptions)
    sigma: tuple[float, ...] = ()
    velocity_reason: str = ""
    clock: str = ""
    law: LawCheck | None = None
    warnings: tuple[str, ...] = ()
    delayed_known: bool = True
    written: WrittenChoice | None = None
    residuals: np.ndarray | None = field(default=None, repr=False, compare=False)
    balance: BalanceRows | None = field(default=None, repr=False, compare=False)
    weight: np.ndarray | None = field(default=None, repr=False, compare=False)

    def joint(self, name: str) -> JointActuator:
        return next(j for j in self.joints if j.joint == name)

    def to_dict(self) -> dict[str, Any]:
        """The JSON document (``identify --actuator pd --json``)."""
        return {"kind": "pd actuators", "source": self.source, "period": self.period, "window": self.window,
                "velocity": {"used": self.options.velocity, "why": self.velocity_reason},
                "delayed": self.options.delayed, "delayed_known": self.delayed_known,
                "clock": self.clock, "warnings": list(self.warnings),
                "pd_law": None if self.law is None else {
                    "gain": dict(zip(self.law.joints, map(float, self.law.gain))),
                    "gain_se": {j: _finite(s) for j, s in zip(self.law.joints, self.law.gain_se)},
                    "toml_delay": self.law.toml_delay},
                "delay": self.delay.to_dict() | {"steps": self.delay.value / self.period},
                "units": UNITS,
                "joints": {j.joint: {k: v.to_dict() for k, v in j.parameters().items()}
                           | {"rms": j.rms, "held_out_rms": _finite(j.held_out_rms), "rows": j.rows,
                              "position_noise": self.position_noise[j.joint],
                              "velocity_noise": self.velocity_noise[j.joint]} for j in self.joints},
                "delay_profile": self.profile.tolist(),
                "written": None if self.written is None else self.written.to_dict()}


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def identify_actuators(robot: Robot, log: Log, options: ActuatorOptions = ActuatorOptions()
                       ) -> ActuatorIdentification:
    """Identify the PD-driven actuators of a hung robot from a log of its set-points (module docstring).

    Args:
        robot: a fixed-base robot whose actuated joints are all PD-driven (``[pd]`` in its TOML); its URDF's
            rigid bodies are taken as they are; its ``[encoder_offset]`` is the first guess of the offsets.
        log: the log: ``q.<joint>``, ``qd.<joint>`` (the drivers' velocity), ``q_des.<joint>`` and the rest of
            :mod:`wbfriction.logs.pd`; torque from the PD law.
        options: :class:`~wbfriction.actuator.options.ActuatorOptions`.

    Returns:
        :class:`ActuatorIdentification`.

    Raises:
        InputError: a robot or log the identification cannot take (:func:`~wbfriction.actuator.rows.pd_joints`),
            a log too short, ``velocity="logged"`` on a log without the drivers' velocities.
    """
    pd_joints(robot, log)
    if options.velocity == "logged" and log.qd_logged is None:  # else the positions' would be taken in its name
        raise InputError(f"{log.source}: --velocity logged needs the drivers' velocities, the columns qd.<joint> "
                         "(none in this log): give --velocity positions or auto")
    assert robot.pd is not None
    velocities = [options.velocity] if options.velocity != "auto" else (
        ["positions", "logged"] if log.qd_logged is not None else ["positions"])
    held = [options.delayed] if options.delayed != "auto" else ["setpoints", "torque"]
    with threadpool_limits(1, user_api="blas"):  # small dense problems: threads cost more than they give
        runs = [_identify(robot, log, replace(options, velocity=v, delayed=h)) for v in velocities for h in held]
    closes = [float(np.sum([j.rms**2 for j in r.joints])) for r in runs]  # the same balance, closed better or worse
    order = np.argsort(closes, kind="stable")
    best = runs[int(order[0])]
    why = f"{best.options.velocity} velocity, {best.options.delayed} delayed"
    if len(runs) > 1:
        second = runs[int(order[1])]
        why += (f": the balance closes best so (squared residual {closes[order[0]] / closes[order[1]]:.2f} of the "
                f"next, {second.options.velocity} velocity, {second.options.delayed} delayed)")
    elif log.qd_logged is None and options.velocity == "auto":
        why += ": no qd.<joint> column"
    others = [runs[int(k)] for k in order if runs[int(k)].options.delayed != best.options.delayed]
    if others:
        gain, se = structure_gain(best, others[0])
        if not gain > GAIN_Z * se:
            why += (f"; {others[0].options.delayed} delayed closes it as well (its squared residual per window over "
                    f"the sensors' noise higher by {gain:.3g} ± {se:.2g}, within {GAIN_Z:g} standard errors): the log "
                    "does not tell what the delay holds back")
            if best.options.delayed != UNDECIDED:
                best, others[0] = others[0], best
                why = (f"{best.options.velocity} velocity, {UNDECIDED} delayed, as a simulator's actuator delays: the "
                       f"log does not tell what the delay holds back ({others[0].options.delayed} delayed closes the "
                       f"balance as well, its squared residual per window over the sensors' noise lower by "
                       f"{gain:.3g} ± {se:.2g}, within {GAIN_Z:g} standard errors)")
            best = structure_widened(best, others[0])
    return replace(best, velocity_reason=why, clock=log.clock.reason if log.clock is not None else "",
                   written=written_choice(robot, log, best))


def written_choice(robot: Robot, log: Log, result: ActuatorIdentification) -> WrittenChoice | None:
    """What ``--config-output`` writes for ``result`` (:func:`~wbfriction.actuator.written.choose_written`): each
    value against the robot TOML's on held-out blocks of the log; None without the balance."""
    rows, weight = result.balance, result.weight
    if rows is None or weight is None:
        return None
    assert robot.pd is not None
    index = pd_joints(robot, log)
    n = len(rows.joints)
    offsets = all(j.offset is not None for j in result.joints)
    values = [[j.parameters()[kind] for j in result.joints] for kind in (KINDS if offsets else KINDS[:3])]
    x = np.array([p.value for column in values for p in column])
    se = np.array([p.se for column in values for p in column])
    moved = [m.excited for m in joint_motion(rows)]  # an at-bound status may hide a joint that did not move
    excited = {kind: np.array([moved[k] and kind in j.parameters() and j.parameters()[kind].status != "not excited"
                               for k, j in enumerate(result.joints)]) for kind in ("armature", "offset")}
    top = (rows.max_steps + 1) * rows.period
    beyond = result.delay.status == "at bound" and result.delay.value >= top - 1e-12
    with threadpool_limits(1, user_api="blas"):
        return choose_written(rows, weight, result.options, offsets,
                              robot.model.armature[robot.act_v_index[index]][:n], robot.offset_vector[index],
                              robot.pd.delay, x, se, result.delay.value, result.delay.se, excited, beyond,
                              result.delay.status != "not excited")


def structure_gain(best: ActuatorIdentification, other: ActuatorIdentification) -> tuple[float, float]:
    """How much ``best`` lowers the balance's squared residual per window (over the sensors' noise, summed over the
    joints both use there) against ``other``, an identification of the same log holding back another part of the
    law, and the Newey-West standard error of that lowering (:func:`~wbfriction.fit.regression.held_out_gain`);
    (nan, inf) without residuals to compare."""
    a, b = best.residuals, other.residuals
    if a is None or b is None or a.shape != b.shape:
        return float("nan"), float("inf")
    both = np.isfinite(a) & np.isfinite(b)
    windows = np.flatnonzero(both.any(axis=1))
    mine = np.sqrt(np.sum(np.where(both, a, 0.0) ** 2, axis=1))[windows]
    theirs = np.sqrt(np.sum(np.where(both, b, 0.0) ** 2, axis=1))[windows]
    return held_out_gain(theirs, mine, windows)


UNDECIDED = "setpoints"
"""What the delay holds back where the log does not tell (:func:`structure_gain` within
:data:`~wbfriction.fit.selection.GAIN_Z` standard errors): the set-points, the structure every simulator
``export`` writes represents (a MuJoCo or Isaac actuator delays its target, not its feedback), so the armatures and
the delay written stay the ones a simulator can replay; the friction's standard errors carry the other structure's
values either way (:func:`structure_widened`). A tie-break between two models the data support alike, not a
threshold: on the real Aliengo the two close the balance within 2 standard errors of each other."""
STRUCTURE_SPREAD = ("F_v", "F_c")
"""The values whose standard error carries what the delay holds back where the log does not tell
(:func:`structure_widened`): the friction, which a user reads as the joint's. The armature, the offsets and the delay
are written to ``--config-output`` beside the ``delayed`` they were fitted under, a pair that closes the balance as
the other pair does (the real Aliengo's calves: armature 0.012 with the set-points delayed, 0.016 with the torque;
neither written would leave 0, worse than both)."""


def structure_widened(best: ActuatorIdentification, other: ActuatorIdentification) -> ActuatorIdentification:
    """``best`` with its friction's standard errors (:data:`STRUCTURE_SPREAD`) grown by their distance to ``other``'s
    (module docstring) and their status again, one demoted naming both values; ``delayed_known`` False."""
    here, there = best.options.delayed, other.options.delayed

    def widened(kind: str, p: Identified, q: Identified | None) -> Identified:
        if q is None or not (np.isfinite(p.value) and np.isfinite(q.value)):
            return p
        se = float(np.hypot(p.se, p.value - q.value))
        status, reason = parameter_status(kind, p.value, se, p.crb, p.status == "at bound")
        grown = replace(p, se=se)
        if status == "ok":
            return grown
        return _demoted(grown, status, f"{kind} {p.value:.3g} with the {here} delayed, {q.value:.3g} with the "
                                       f"{there}: the log does not tell which ({reason})")

    joints = []
    for j in best.joints:
        theirs = other.joint(j.joint).parameters()
        joints.append(j.with_values({k: widened(k, p, theirs.get(k)) if k in STRUCTURE_SPREAD else p
                                     for k, p in j.parameters().items()}))
    return replace(best, joints=tuple(joints), delayed_known=False)


def _identify(robot: Robot, log: Log, options: ActuatorOptions) -> ActuatorIdentification:
    index = pd_joints(robot, log)
    offsets = options.offset_bound > 0
    offset = robot.offset_vector[index].copy()
    weight: np.ndarray | None = None
    for _ in range(options.passes):
        rows = balance_rows(robot, log, offset, options)
        windows = np.arange(len(rows.rest))
        d = design(rows, windows, offsets)
        weight = 1.0 / np.maximum(rows.sigma, 1e-12) if weight is None else weight
        search = _delay(rows, d, weight, options)
        y = d.rhs(rows, rows.balance(search.delay))
        sol = solve(d, y, weight, rows.sigma, options.offset_bound, _lags(rows, options))
        solved_with = weight
        weight = 1.0 / np.maximum(sol.rms, 1e-12)
        if offsets:
            offset = sol.x[3 * len(index):]
    assert weight is not None
    sol = block_grown(sol, d, y, solved_with, _lags(rows, options))  # the block spread: actuator.solve
    steep = design(rows, windows, offsets, steep=True)  # the nuisance model's sensitivity: options.STEEPER
    steep_delay = _delay(rows, steep, weight, options).delay
    moved = solve(steep, steep.rhs(rows, rows.balance(steep_delay)), weight, rows.sigma, options.offset_bound)
    sol = replace(sol, covariance=sol.covariance + np.diag((moved.x - sol.x) ** 2))
    held = held_out_rms(rows, offsets, weight, options)
    delay = _delay_value(search, rows, sol, options, abs(steep_delay - search.delay))
    assert robot.pd is not None
    motion = joint_motion(rows)
    law = check_law(rows, d, weight, delay.value, _lags(rows, options), options.delay is None, delay.se,
                    robot.pd.delay, np.array([m.excited for m in motion]), sol.x)
    sol = replace(sol, covariance=sol.covariance + np.diag(law.moved**2))  # the law's disagreement: law_check
    result = _result(rows, d, sol, delay, search.profile, held, log.source, options)
    e = d.rhs(rows, rows.balance(search.delay)) - d.A @ sol.x
    residuals = np.full(rows.rest.shape, np.nan)
    residuals[d.window, d.joint] = e / np.maximum(rows.sigma[d.joint], 1e-300)
    return _verdicts(replace(result, law=law, residuals=residuals, balance=rows, weight=weight), motion,
                     rows.max_steps)


def _lags(rows: BalanceRows, options: ActuatorOptions) -> int:
    return hac_lags(len(rows.rest), options.window)


def _delay(rows: BalanceRows, d: Design, weight: np.ndarray, options: ActuatorOptions) -> DelaySearch:
    if options.delay is not None:
        return DelaySearch(options.delay, 0.0, np.empty((0, 2)))
    return search_delay(rows, d, weight)


def held_out_rms(rows: BalanceRows, offsets: bool, weight: np.ndarray, options: ActuatorOptions) -> np.ndarray:
    """Each joint's balance RMS (n,) [N·m·s] on the last ``options.holdout`` share of the windows, predicted by
    the identification (delay searched again) on the others; NaN without a held-out share."""
    n = len(rows.joints)
    count = len(rows.rest)
    cut = int(round(count * (1.0 - options.holdout)))
    if options.holdout == 0 or cut < 2 or cut >= count:
        return np.full(n, np.nan)
    fit = design(rows, np.arange(cut), offsets)
    search = _delay(rows, fit, weight, options)
    sol = solve(fit, fit.rhs(rows, rows.balance(search.delay)), weight, rows.sigma, options.offset_bound)
    test = design(rows, np.arange(cut, count), offsets)
    e = test.rhs(rows, rows.balance(search.delay)) - test.A @ sol.x
    used = np.bincount(test.joint, minlength=n)
    return np.sqrt(np.bincount(test.joint, weights=e**2, minlength=n) / np.maximum(used, 1))


def parameter_status(kind: str, value: float, se: float, crb: float, at_bound: bool,
                     reference: float | None = None) -> tuple[ActuatorStatus, str]:
    """A parameter's status, the first that applies: ``not excited`` (its bound is infinite: the data do not
    determine it), ``at bound`` (left on a bound of the search: an offset at ``--offset-bound``, or an armature at
    zero, which a rotor never has), ``weak`` (a standard error or bound above :data:`~wbfriction.fit.status.WEAK`
    of its value, or of ``reference`` where given (a drive's constant torque ``tau_os`` against the larger of it
    and F_c [N·m]); for an offset, above :data:`OFFSET_WEAK`, or the offset itself beyond :data:`OFFSET_PLAUSIBLE`),
    ``ok``."""
    unit = {**UNITS, "tau_os": "N·m"}[kind]
    if not np.isfinite(crb):
        return "not excited", f"{kind}: the log does not determine it"
    if at_bound or (kind == "armature" and value <= 0):
        return "at bound", f"{kind} at the search's bound ({value:.4g} {unit})"
    worst = max(se, crb)
    if kind == "offset":
        if abs(value) > OFFSET_PLAUSIBLE:
            return "weak", (f"offset {value:+.3g} rad: more than an encoder is mis-set by ({OFFSET_PLAUSIBLE:g}); "
                            "the gravity model (masses, centres of mass) may be off instead")
        if worst > OFFSET_WEAK:
            return "weak", f"offset ±{worst:.2g} rad (more than {OFFSET_WEAK:g})"
        return "ok", ""
    scale = abs(value) if reference is None else abs(reference)
    if not np.isfinite(worst) or worst > WEAK * scale:
        rel = worst / scale if scale else np.inf
        return "weak", f"{kind} ±{rel:.0%}" if np.isfinite(rel) else f"{kind} not determined"
    return "ok", ""


def delay_status(delay: float, se: float, top: float, period: float, crb: float | None = None
                 ) -> tuple[ActuatorStatus, str]:
    """The drivers' delay's status, the first that applies: ``not excited`` (an infinite bound ``crb``, or without
    one an infinite standard error ``se`` [s]: the set-points do not determine it), ``at bound`` (at zero or at the
    search's longest, ``top`` [s]), ``weak`` (a standard error above :data:`~wbfriction.fit.status.WEAK` of it and
    above a log ``period`` [s], or infinite), ``ok``. ``identify --actuator pd``'s and ``refine``'s."""
    if not np.isfinite(se if crb is None else crb):
        return "not excited", "the set-points do not determine it"
    if delay <= 0 or delay >= top - 1e-12:
        return "at bound", f"at the search's bound ({delay * 1e3:.3g} ms; --max-delay)"
    if not np.isfinite(se) or se > max(WEAK * delay, period):
        return "weak", f"±{se * 1e3:.2g} ms"
    return "ok", ""


def fitted_under(delay: Identified, top: float, bound: str = "--max-delay") -> str:
    """Why every value fitted under the delay ``delay`` is not ``ok`` where it is at the search's longest ``top``
    [s], what sets it named by ``bound`` (round 4: the delay may be longer, and the values then hold what it
    leaves), "" otherwise."""
    if delay.status == "at bound" and delay.value >= top - 1e-12:
        return f"fitted under a delay at the search's bound ({delay.value * 1e3:.3g} ms; {bound})"
    return ""


def judged(p: Identified, kind: str, motion: JointMotion | None, under: str = "") -> Identified:
    """``p`` (of ``kind``) demoted by what its data do not determine (round 4's rule, ``identify``'s and
    ``refine``'s alike): what its joint's ``motion`` does not excite (:meth:`~wbfriction.actuator.excitation.
    JointMotion.verdict`), then a delay at its search's bound (``under``: :func:`fitted_under`'s reason)."""
    by_motion = motion.verdict(kind) if motion is not None else None
    if by_motion is not None:
        p = _demoted(p, by_motion[0], by_motion[1])  # type: ignore[arg-type]
    if under:
        p = _demoted(p, "at bound", f"{kind}: {under}")
    return p


def _result(rows: BalanceRows, d: Design, sol: Solution, delay: Identified, profile: np.ndarray, held: np.ndarray,
            source: str, options: ActuatorOptions) -> ActuatorIdentification:
    n = len(rows.joints)
    crb = np.sqrt(np.abs(np.diag(sol.bound)))
    se = np.sqrt(np.abs(np.diag(sol.covariance)))
    se = np.where(np.isfinite(crb), np.maximum(se, crb), se)  # never below the bound (module docstring)

    def value(kind: str, j: int) -> Identified:
        k = KINDS.index(kind) * n + j
        status, reason = parameter_status(kind, float(sol.x[k]), float(se[k]), float(crb[k]), bool(sol.at_bound[k]))
        return Identified(float(sol.x[k]), float(se[k]), float(crb[k]), status, reason)

    joints = []
    for j, name in enumerate(rows.joints):
        rms, ho = float(sol.rms[j]), float(held[j])
        arm = value("armature", j)
        if np.isfinite(ho) and ho > HOLDOUT_RATIO * rms and arm.status == "ok":
            arm = Identified(arm.value, arm.se, arm.crb, "does not predict",
                             f"held-out balance RMS {ho:.3g} against {rms:.3g} fitted")
        joints.append(JointActuator(name, arm, value("F_v", j), value("F_c", j),
                                    value("offset", j) if d.offsets else None, rms, ho, int(sol.rows[j])))
    return ActuatorIdentification(tuple(joints), delay, rows.period, options.window, profile,
                                  dict(zip(rows.joints, map(float, rows.position_noise))),
                                  dict(zip(rows.joints, map(float, rows.velocity_noise))), source, options,
                                  tuple(map(float, rows.sigma)))


def _delay_value(search: DelaySearch, rows: BalanceRows, sol: Solution, options: ActuatorOptions,
                 moved: float = 0.0) -> Identified:
    if options.delay is not None:
        return Identified(options.delay, 0.0, 0.0, "ok", "given (--delay)")
    # weights 1/rms make the residual's variance 1; with 1/sigma the bound's: the curvature is in the first
    scale = np.median(sol.rms / np.maximum(rows.sigma, 1e-300))
    se = float(1.0 / np.sqrt(search.curvature)) if search.curvature > 0 else np.inf
    crb = se / scale if np.isfinite(se) and scale > 0 else np.inf
    se = max(float(np.hypot(se, moved)), crb) if np.isfinite(crb) else se  # with the nuisance model's sensitivity
    status, reason = delay_status(search.delay, se, (rows.max_steps + 1) * rows.period, rows.period)
    return Identified(search.delay, se, crb, status, reason)


def _demoted(p: Identified, status: ActuatorStatus, reason: str) -> Identified:
    """``p`` with ``status`` and ``reason`` where its own is ``ok`` or ``weak`` (a worse one is kept)."""
    if p.status not in ("ok", "weak") or (status == "weak" and p.status == "weak"):
        return p
    return replace(p, status=status, reason=reason)


def _verdicts(result: ActuatorIdentification, motion: tuple[JointMotion, ...], max_steps: int
              ) -> ActuatorIdentification:
    """The statuses of what the log does not determine (module docstring): a joint that did not move, a delay at the
    search's upper bound. The PD law's check names a disagreement (:attr:`ActuatorIdentification.warnings`) and
    changes no status: it cannot tell the drivers' gains from the URDF's masses (:mod:`wbfriction.actuator.
    law_check`)."""
    d = result.delay
    under = fitted_under(d, (max_steps + 1) * result.period)
    law = None if under else result.law  # a law checked under a wrong delay says nothing of the gains
    joints = [j.with_values({kind: judged(p, kind, m, under) for kind, p in j.parameters().items()})
              for j, m in zip(result.joints, motion)]
    lines = law.lines() if law is not None else []
    if under:
        lines.insert(0, f"the drivers' delay is beyond the search ({d.value * 1e3:.3g} ms, its bound): raise "
                        "--max-delay; every value fitted under it is at bound and none is written")
    return replace(result, joints=tuple(joints), delay=d, law=law, warnings=tuple(lines))
