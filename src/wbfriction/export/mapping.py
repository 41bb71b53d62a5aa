"""From the fitted friction models to the joint parameters of simulators: what each one holds, what is dropped.

The identified friction is, per joint, one of the models of :mod:`wbfriction.friction.models`,
most fully the thesis's (3.5),

.. math:: f(\\dot q) = F_v \\dot q + F_c \\tanh(a \\dot q)\\,(1 + S e^{-|\\dot q / v_s|^{\\delta_s}}) + \\tau_{os},
          \\qquad \\tau_f = -f(\\dot q),

(the ``stribeck`` model writes the static level F_s itself and ``sgn`` for ``tanh``; the
``coulomb-viscous`` model has no static level apart from F_c), and the armature (reflected rotor
inertia) a number per joint [kg·m^2]. Simulators hold less:

===================  ======================  =====================  ===================================
model (3.5)          URDF ``<dynamics>``     MJCF ``<joint>``       Isaac Lab actuator (``ActuatorBaseCfg``)
===================  ======================  =====================  ===================================
F_v [N·m·s/rad]      ``damping``             ``damping``            ``viscous_friction``
F_c [N·m]            ``friction``            ``frictionloss``       ``dynamic_friction``
F_s = (1 + S) F_c    --                      --                     ``friction`` (static)
S, v_s (Stribeck)    dropped                 dropped                shape dropped (only the level F_s)
a (tanh slope)       dropped                 dropped                dropped
tau_os (offset)      dropped                 PD: actuator bias      PD: set-point offset (header)
armature [kg·m^2]    -- (no URDF field)      ``armature``           ``armature``
load (k_L)           dropped                 dropped                dropped
direction (dF_v)     dropped                 dropped                dropped
ripple               dropped                 dropped                dropped
temperature (k_T)    dropped                 dropped                dropped
===================  ======================  =====================  ===================================

(F_s is the ``stribeck`` model's own F_s, and F_c for the ``coulomb-viscous`` model.)

* Viscous friction is exact everywhere: every simulator has a linear damping ``-F_v qd``.
* The Coulomb level F_c is what the joint sees in motion (``tanh(a qd) -> sgn(qd)`` for
  ``|qd| >> 1/a``, the Stribeck bump gone for ``|qd| >> v_s``): URDF's ``friction`` (used as one
  dry-friction level by Gazebo, by Pinocchio's dry friction limits, and by MuJoCo's URDF import as
  ``frictionloss``) and MuJoCo's ``frictionloss`` (dry friction as a soft constraint: no tanh, its
  smoothing set by the constraint's ``solref``/``solimp``; see :mod:`wbfriction.export.mjcf`) get F_c.
* Only PhysX (Isaac Sim >= 5.0, so Isaac Lab >= 2.2) has a separate static level: ``friction`` is
  the static friction effort F_s that holds a joint at rest, ``dynamic_friction`` the one in
  motion, F_c (PhysX needs ``dynamic_friction <= friction``, i.e. F_s >= F_c, S >= 0). How fast the
  friction falls from F_s to F_c (v_s, the Stribeck velocity) has no field anywhere.
* ``tau_os`` is not friction (a torque sensor's offset, removed before the energy check, thesis
  7.9): it is not exported as friction. A PD-driven joint has no torque sensor: there it is a constant torque of
  the drive, exported with the drivers as the set-point offset ``tau_os / kp`` (:mod:`wbfriction.export.drive`).
  Nor is ``a`` exported, a smoothing of the model's sign function.
* The terms beyond velocity (:mod:`wbfriction.fit.terms`) have no field in any of the three: friction that
  grows with the load or falls with the temperature, a viscous level per direction, a position ripple (which is
  not friction). A fit that kept some exports its velocity model refitted with them, at the reference conditions
  (zero load, the reference temperature ``T_ref``, no ripple), and its note says which terms were dropped and at
  which conditions the levels are (:func:`status_note`).

Friction that is not dissipative (F_c < 0, F_v < 0, or a static level F_s < 0, i.e. S < -1) and
a negative armature are refused (:class:`~wbfriction.exceptions.InputError`), never exported.

Which fits are exported (:func:`select_fits`, :func:`exported_fit`) follows their status
(:mod:`wbfriction.fit.status`): ``ok`` always; where the model ``--model auto`` chose is not ``ok``, its simplest
family's fit (:attr:`~wbfriction.fit.result.FitResult.fallback`: Coulomb-viscous, without terms) when that is ``ok``
or included, its note saying which it replaces; ``weak`` (large standard errors) and ``at bound`` (a parameter is
the bound's value) only on request (:data:`Include`, ``export --include weak,at-bound``): numbers of the data, less
certain. A fit
that is ``not excited`` (the joint hardly moved: its friction is not in the data, and the fit's numbers
are whatever the solver settled on, e.g. F_v 38 N·m·s/rad for a hip yaw of 0.2) or ``failed`` (the solver
stopped without converging) never is, and :func:`joint_export` refuses one; a joint without a fit (not
in the parameters file, or without parameters) has no friction to export. Each exported fit's status goes
into the file beside its joint (:func:`status_note`), the reason when it is not ``ok``.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping
from collections.abc import Set as AbstractSet
from dataclasses import dataclass, field
from typing import Literal, Protocol, cast, get_args

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.fit.result import FitResult
from wbfriction.fit.status import FitStatus, FitVerdict
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.friction.families.registry import family
from wbfriction.model.robot import Robot


class FrictionModelParams(Protocol):
    """The parameters of any friction model of :mod:`wbfriction.friction.models` (:class:`FrictionParams`
    of (3.5), ``StribeckParams``, ``CoulombViscousParams``): what the export reads of them."""

    @property
    def F_v(self) -> float: ...

    @property
    def F_c(self) -> float: ...


Include = Literal["weak", "at-bound", "routes-disagree", "does-not-predict"]
"""The statuses besides ``ok`` whose fits are exported on request (``export --include``; module docstring)."""
INCLUDE_CHOICES: tuple[Include, ...] = get_args(Include)
INCLUDED_STATUS: dict[Include, FitStatus] = {"weak": "weak", "at-bound": "at bound",
                                             "routes-disagree": "routes disagree",
                                             "does-not-predict": "does not predict"}
"""The fit status each choice of :data:`Include` names."""
NEVER_EXPORTED: tuple[FitStatus, ...] = ("not excited", "failed")
"""Statuses whose numbers are not the data's: never exported, whatever is included."""
NOT_FITTED = "not fitted"
"""What :class:`FitSelection` calls a robot joint that the parameters file has no fit of."""


def check_include(choices: Iterable[str], what: str = "--include") -> tuple[Include, ...]:
    """``choices`` as :data:`Include` values, in the order given, once each.

    Raises:
        InputError: a choice that is not one of :data:`INCLUDE_CHOICES` (named as ``what``); the
            statuses of :data:`NEVER_EXPORTED` are refused with their reason.
    """
    out: list[Include] = []
    for choice in choices:
        if choice not in INCLUDE_CHOICES:
            status = choice.replace("-", " ")
            why = (": fits with status ok are always exported" if status == "ok" else
                   ": a fit that is not excited, failed or not fitted has no numbers the data carry, never exported"
                   if status in (*NEVER_EXPORTED, NOT_FITTED) else "")
            raise InputError(f"{what}: '{choice}' is not one of {', '.join(INCLUDE_CHOICES)}{why}")
        if choice not in out:
            out.append(cast(Include, choice))
    return tuple(out)


@dataclass(frozen=True)
class FitSelection:
    """The fits of a parameters file that are exported, and the robot's joints that are not.

    Attributes:
        exported: joint -> fit to export (status ``ok`` or an included one, :func:`exported_fit`), in the robot's
            joint order.
        left_out: status (a :data:`~wbfriction.fit.status.FitStatus`, or :data:`NOT_FITTED` for a
            joint the file has no fit of) -> the joints left out with it, in the robot's joint order.
        include: the statuses exported besides ``ok``.
        instead: joint -> the fit chosen, where its :attr:`~wbfriction.fit.result.FitResult.fallback` (the simplest
            family's) is exported in its place.
    """

    exported: Mapping[str, FitResult]
    left_out: Mapping[str, tuple[str, ...]]
    include: tuple[Include, ...] = ()
    instead: Mapping[str, FitResult] = field(default_factory=dict)

    def instead_note(self, joint: str) -> str:
        """Where the simplest family's fit is exported in place of the model chosen (:attr:`instead`), what the
        chosen one was and why it is not (``in place of the stribeck fit chosen, at bound: ...``); else ""."""
        chosen = self.instead.get(joint)
        if chosen is None:
            return ""
        verdict = chosen.verdict()
        return (f"in place of the {chosen.model} fit chosen ({verdict.status}"
                + (f": {verdict.reason}" if verdict.reason else "") + ")")

    @property
    def exported_statuses(self) -> dict[str, int]:
        """Status -> how many exported fits have it, in the order met."""
        return dict(Counter(fit.verdict().status for fit in self.exported.values()))


def select_fits(fits: Mapping[str, FitResult], robot: Robot, include: Iterable[str] = (),
                source: str = "parameters") -> FitSelection:
    """The fits of ``fits`` that are exported (module docstring): status ``ok``, or one ``include`` names.

    Args:
        fits: joint -> fit (:func:`wbfriction.fit.params_file.read_params`); each a joint ``robot`` actuates.
        robot: the robot exported; its actuated joints without a fit in ``fits`` are :data:`NOT_FITTED`.
        include: choices of :data:`Include` (:func:`check_include`).
        source: what names ``fits`` in errors (the parameters file).

    Raises:
        InputError: an ``include`` choice that is not one (naming ``--include``), a file without joints,
            a joint ``robot`` does not actuate, or no fit that qualifies (one line counting the statuses).
    """
    included = check_include(include)
    if not fits:
        raise InputError(f"{source}: no joints: nothing to export")
    unknown = [n for n in fits if n not in robot.actuated]
    if unknown:
        raise InputError(f"{source}: joint '{unknown[0]}' is not an actuated joint of robot '{robot.name}'")
    wanted: set[str] = {"ok", *(INCLUDED_STATUS[c] for c in included)}
    exported: dict[str, FitResult] = {}
    left_out: dict[str, list[str]] = {}
    instead: dict[str, FitResult] = {}
    for joint in robot.actuated:
        fit = fits.get(joint)
        chosen = None if fit is None else exported_fit(fit, wanted)
        if fit is not None and chosen is not None:
            exported[joint] = chosen
            if chosen is not fit:
                instead[joint] = fit
        else:
            left_out.setdefault(NOT_FITTED if fit is None else fit.verdict().status, []).append(joint)
    if not exported:
        counts = Counter(fit.verdict().status for fit in fits.values())
        hint = [c for c, status in INCLUDED_STATUS.items() if counts[status] and c not in included]
        raise InputError(f"{source}: no fit qualifies for export ("
                         + ", ".join(f"{n} {status}" for status, n in counts.items()) + ")"
                         + (f": --include {','.join(hint)} exports those" if hint else ""))
    return FitSelection(exported, {status: tuple(joints) for status, joints in left_out.items()}, included, instead)


def exported_fit(fit: FitResult, wanted: AbstractSet[str]) -> FitResult | None:
    """The fit of a joint an export writes (module docstring), of the statuses ``wanted`` (``ok`` and those
    included): the fit itself where it is ``ok``; else its :attr:`~wbfriction.fit.result.FitResult.fallback` (the
    simplest family's, fitted without terms) where that is ``ok``, or is wanted (of two fits neither ``ok``, the one
    with the fewest parameters the data must carry); else the fit where it is wanted; else None (issue 64: on the
    real Aliengo, a Stribeck fit at its bound with a ripple dropped tracked its held-out stretch at 19.9 mrad in the
    exported MJCF, its Coulomb-viscous fit at 6.0)."""
    status = fit.verdict().status
    if status == "ok":
        return fit
    simple = fit.fallback
    if simple is not None and simple.verdict().status in {"ok", *wanted}:
        return simple
    return fit if status in wanted else None


FrictionLike = FitResult | FrictionModelParams
"""Fitted friction of one joint as the project stores it: a :class:`FitResult` (what
:func:`wbfriction.fit.params_file.read_params` returns; one without parameters exports no friction)
or bare parameters of a model (e.g. :class:`FrictionParams`)."""


def static_level(params: FrictionModelParams) -> float:
    """The static friction F_s [N·m], the level at rest, as the parameters' family defines it
    (:meth:`~wbfriction.friction.families.base.FrictionFamily.static_level`): ``(1 + S) F_c`` of model (3.5), the
    ``stribeck`` model's ``F_s``, ``F_c`` of the ``coulomb-viscous`` model."""
    model_params = cast(ModelParamsBase, params)
    return family(model_params.model).static_level(model_params)


@dataclass(frozen=True)
class JointExport:
    """The simulator parameters of one joint (module docstring for the mapping).

    Attributes:
        joint: joint name.
        viscous: viscous friction F_v [N·m·s/rad] (URDF/MJCF ``damping``, Isaac ``viscous_friction``),
            None without identified friction.
        coulomb: Coulomb friction F_c [N·m] (URDF ``friction``, MJCF ``frictionloss``, Isaac
            ``dynamic_friction``), None without identified friction.
        static: static friction F_s [N·m] (:func:`static_level`; Isaac ``friction``), None without
            identified friction.
        armature: reflected rotor inertia [kg·m^2] (MJCF and Isaac ``armature``), None when not given.
        params: the model parameters the friction comes from (what is dropped: S, v_s, a of (3.5), and tau_os but
            on a PD-driven joint).
        verdict: the status of the fit the friction comes from (:func:`status_note`), None for bare parameters.
        dropped: the terms beyond velocity the fit kept, which no simulator holds (module docstring).
        conditions: where the fit kept terms, the conditions its levels are at (``zero load, T_ref 40 °C``).
        instead: where the fit is the simplest family's in place of the one chosen, what that was
            (:meth:`FitSelection.instead_note`), else "".

    Raises:
        InputError: a value that is negative (not dissipative) or not finite, or friction given in part.
    """

    joint: str
    viscous: float | None = None
    coulomb: float | None = None
    static: float | None = None
    armature: float | None = None
    params: FrictionModelParams | None = None
    verdict: FitVerdict | None = None
    dropped: tuple[str, ...] = ()
    conditions: str = ""
    instead: str = ""

    def __post_init__(self) -> None:
        given = [x is not None for x in (self.viscous, self.coulomb, self.static)]
        if any(given) and not all(given):
            raise InputError(f"joint '{self.joint}': viscous, Coulomb and static friction go together")
        for name, value, unit in (("F_v", self.viscous, "N·m·s/rad"), ("F_c", self.coulomb, "N·m"),
                                  ("F_s", self.static, "N·m"), ("armature", self.armature, "kg·m^2")):
            if value is None:
                continue
            if not np.isfinite(value):
                raise InputError(f"joint '{self.joint}': {name} = {value} is not a finite number")
            if value < 0:
                what = "a negative armature" if name == "armature" else "friction that is not dissipative"
                raise InputError(f"joint '{self.joint}': {name} = {value:g} {unit} < 0: {what} is not exported")

    @property
    def has_friction(self) -> bool:
        """Whether the joint has identified friction (then :attr:`viscous`, :attr:`coulomb`, :attr:`static` are set)."""
        return self.coulomb is not None


def joint_export(joint: str, friction: FrictionLike | None = None, armature: float | None = None) -> JointExport:
    """The simulator parameters of one joint from its fitted friction and armature (module docstring).

    Args:
        joint: joint name.
        friction: the joint's fitted friction (a fit's status is kept, :attr:`JointExport.verdict`); None, or
            a fit without parameters: no friction.
        armature: [kg·m^2], or None.

    Raises:
        InputError: F_c < 0, F_v < 0, F_s < 0 (S < -1 in (3.5)), a negative armature or
            a value that is not finite: not dissipative, not exported; a fit whose status is one of
            :data:`NEVER_EXPORTED` (the message names the joint).
    """
    fit = friction if isinstance(friction, FitResult) else None
    params: FrictionModelParams | None = fit.params if fit is not None else cast(FrictionModelParams | None, friction)
    if params is None:
        return JointExport(joint, armature=None if armature is None else float(armature))
    verdict = fit.verdict() if fit is not None else None
    if verdict is not None and verdict.status in NEVER_EXPORTED:
        raise InputError(f"joint '{joint}': its fit is {verdict}: numbers the data do not carry are not exported")
    terms = None if fit is None else fit.kept_terms
    dropped: tuple[str, ...] = ()
    conditions = ""
    if terms is not None:  # its velocity model refitted with them: the levels at the reference conditions
        params = terms.params
        dropped = terms.kept
        conditions = terms.reference_conditions()
    model_params = cast(ModelParamsBase, params)
    levels = family(model_params.model)
    return JointExport(joint, viscous=levels.viscous_level(model_params), coulomb=levels.coulomb_level(model_params),
                       static=levels.static_level(model_params),
                       armature=None if armature is None else float(armature), params=params, verdict=verdict,
                       dropped=dropped, conditions=conditions)


NOTE_PREFIX = "wbfriction fit of"
"""How every :func:`status_note` begins (an export replaces the notes an earlier one wrote)."""


def status_note(exp: JointExport) -> str | None:
    """The comment every export writes beside a joint whose friction comes from a fit: the fit's status and,
    when not ``ok``, its reason, on one line that is a valid XML and YAML comment (no ``--``, no line break);
    None for a joint without (bare parameters, armature only).

    Examples:
        ``wbfriction fit of knee: ok``, ``wbfriction fit of hip: weak (large standard errors: F_v ±80 %)``,
        ``wbfriction fit of wrist: ok; terms beyond velocity dropped (no field here): ripple; levels at zero load``
    """
    if exp.verdict is None or not exp.has_friction:
        return None
    v = exp.verdict
    text = f"{NOTE_PREFIX} {exp.joint}: {v.status}" + (f" ({v.reason})" if v.reason else "")
    if exp.instead:
        text += f"; its {getattr(exp.params, 'model', '')} fit {exp.instead}"
    if exp.dropped:
        text += (f"; terms beyond velocity dropped (no field here): {', '.join(exp.dropped)}; levels at "
                 f"{exp.conditions}")
    text = " ".join(text.split())
    while "--" in text:
        text = text.replace("--", "- -")
    return text


def joint_exports(friction: Mapping[str, FrictionLike], armature: Mapping[str, float] | None = None,
                  robot: Robot | None = None) -> dict[str, JointExport]:
    """The simulator parameters of every joint with friction or armature, by name.

    Args:
        friction: joint -> fitted friction (e.g. :attr:`FitSelection.exported` of :func:`select_fits`).
        armature: joint -> reflected rotor inertia [kg·m^2], or None.
        robot: if given, every joint must be one of its actuated joints; the result is then
            in :attr:`Robot.actuated` order (otherwise: the friction's, then the armature's).

    Returns:
        joint -> :class:`JointExport`; joints whose fit has no parameters and no armature are left out.

    Raises:
        InputError: a value :func:`joint_export` refuses, or (with ``robot``) a joint the robot does not actuate.
    """
    armature = armature or {}
    names = list(dict.fromkeys([*friction, *armature]))
    if robot is not None:
        unknown = [n for n in names if n not in robot.actuated]
        if unknown:
            raise InputError(f"joint '{unknown[0]}' is not an actuated joint of robot '{robot.name}'")
        names = [n for n in robot.actuated if n in names]
    out = {}
    for name in names:
        exp = joint_export(name, friction.get(name), armature.get(name))
        if exp.has_friction or exp.armature is not None:
            out[name] = exp
    return out
