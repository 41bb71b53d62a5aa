"""The identification as a typed result: what ``wbfriction identify`` prints, writes as JSON (``--json``)
and the report reads back (``wbfriction report --identification``).

:class:`Identification` holds per pass the identification's size, condition, prior and the parameters
the data did not determine (:class:`PassSummary`), per body the change written (:class:`BodyWritten`),
per torque-controlled joint the friction of both routes, the armature and the held-out torques
(:class:`JointIdentified`). :meth:`Identification.to_dict` is the JSON's layout and
:meth:`Identification.from_dict` its one reader, refusing what the writer would not have written with
the key at fault. It is built from a closed loop by :func:`wbfriction.inertia.io.identification_of`.

Sign convention (every friction value): ``tau_f = -f(qd)``, the torque friction exerts on the joint
[N·m], opposite to the motion for positive parameters (thesis eq. 3.5).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from wbfriction.exceptions import InputError
from wbfriction.fit.params_file import finite_or_none, fit_from_dict, fit_to_dict
from wbfriction.fit.result import FitResult
from wbfriction.inertia.excitation import Unexcited

SIGN_CONVENTION = ("tau_f = -f(qd); f = F_v qd + F_c tanh(a qd) (+ (F_s - F_c) tanh(a qd) exp(-(qd/v_s)^2))"
                   " + tau_os")


class _Malformed(Exception):
    """A key of the document that is missing or malformed (turned into an :class:`InputError` naming it)."""


def _need(ok: bool, key: str) -> None:
    if not ok:
        raise _Malformed(key)


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _number(d: Mapping[str, Any], name: str, key: str) -> float:
    _need(_is_number(d.get(name)), key)
    return float(d[name])


def _optional(d: Mapping[str, Any], name: str, key: str) -> float | None:
    x = d.get(name)
    _need(x is None or _is_number(x), key)
    return None if x is None else float(x)


def _read_finite(x: Any) -> float:
    """Inverse of :func:`_finite` (None: not a number)."""
    return math.nan if x is None else float(x)


def _numbers(d: Any, key: str) -> dict[str, float]:
    _need(isinstance(d, dict) and all(_is_number(v) for v in d.values()), key)
    return {str(k): float(v) for k, v in d.items()}


@dataclass(frozen=True)
class PassSummary:
    """One pass of the closed loop (:class:`~wbfriction.inertia.closed_loop.ClosedLoop`).

    Attributes:
        stribeck_velocity: the pass's v_s [rad/s] (None: no Stribeck term).
        stribeck_joints: the joints it applies to (None: all).
        samples: single-support samples identified on.
        base_parameters, parameters: the identifiable combinations and the parameters in all.
        condition: condition number of the base regressor (None: not finite).
        prior: the prior's weight chosen; ``prior_scores``: held-out score per weight tried.
        residual_std: torque residual's standard deviation [N·m] (None: not finite).
        not_excited: the parameters the data did not determine
            (:func:`~wbfriction.inertia.excitation.unexcited_parameters`).
        message: the solve in words; ``solver``: its outcome
            (:meth:`~wbfriction.fit.solver.SolverOutcome.to_dict`).
        verdict: the held-out gate's one line; ``validation``: its decisions per limb
            (:mod:`~wbfriction.inertia.validation`). None: no gate ran.
    """

    stribeck_velocity: float | None
    samples: int
    base_parameters: int
    parameters: int
    condition: float | None
    prior: float
    message: str
    stribeck_joints: tuple[str, ...] | None = None
    prior_scores: dict[str, float] = field(default_factory=dict)
    residual_std: float | None = None
    not_excited: tuple[Unexcited, ...] = ()
    solver: dict[str, Any] | None = None
    verdict: str | None = None
    validation: dict[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"stribeck_velocity": self.stribeck_velocity,
                "stribeck_joints": None if self.stribeck_joints is None else list(self.stribeck_joints),
                "samples": self.samples, "base_parameters": self.base_parameters, "parameters": self.parameters,
                "condition": self.condition, "prior": self.prior, "prior_scores": dict(self.prior_scores),
                "residual_std": self.residual_std,
                "not_excited": [{"parameter": u.parameter, "information": finite_or_none(u.information),
                                 "partners": u.partners} for u in self.not_excited],
                "message": self.message, "solver": self.solver, "verdict": self.verdict,
                "validation": self.validation}

    @classmethod
    def from_dict(cls, d: Any, key: str) -> PassSummary:
        _need(isinstance(d, dict), key)
        unexcited = d.get("not_excited") or []
        _need(isinstance(unexcited, list) and all(
            isinstance(u, dict) and isinstance(u.get("parameter"), str) and isinstance(u.get("partners"), dict)
            for u in unexcited), f"{key}.not_excited")
        joints = d.get("stribeck_joints")
        _need(joints is None or isinstance(joints, list), f"{key}.stribeck_joints")
        _need(isinstance(d.get("samples"), int), f"{key}.samples")
        for name in ("solver", "validation"):
            _need(d.get(name) is None or isinstance(d[name], dict), f"{key}.{name}")
        return cls(stribeck_velocity=_optional(d, "stribeck_velocity", f"{key}.stribeck_velocity"),
                   stribeck_joints=None if joints is None else tuple(map(str, joints)),
                   samples=int(d["samples"]), base_parameters=int(d.get("base_parameters", 0)),
                   parameters=int(d.get("parameters", 0)),
                   condition=_optional(d, "condition", f"{key}.condition"),
                   prior=_number(d, "prior", f"{key}.prior") if "prior" in d else 0.0,
                   prior_scores=_numbers(d.get("prior_scores") or {}, f"{key}.prior_scores"),
                   residual_std=_optional(d, "residual_std", f"{key}.residual_std"),
                   not_excited=tuple(Unexcited(str(u["parameter"]), _read_finite(u.get("information")),
                                               {str(k): float(v) for k, v in u["partners"].items()})
                                     for u in unexcited),
                   message=str(d.get("message", "")), solver=d.get("solver"),
                   verdict=None if d.get("verdict") is None else str(d["verdict"]), validation=d.get("validation"))


@dataclass(frozen=True)
class BodyProposal:
    """What the fit proposed for a body before the held-out gate (masses [kg], ``com_shift`` [m],
    principal moments about the centre of mass [kg·m^2], ascending; changes relative, None: new body)."""

    mass: float
    mass_change: float | None
    com_shift: float
    moments: tuple[float, ...]
    moments_change: tuple[float | None, ...]

    def to_dict(self) -> dict[str, Any]:
        return {"mass": self.mass, "mass_change": self.mass_change, "com_shift": self.com_shift,
                "moments": list(self.moments), "moments_change": list(self.moments_change)}


COLLAPSED = 0.9
"""A principal moment about the centre of mass that fell by more than this share makes a written body implausible
(:meth:`BodyWritten.implausible`)."""
MASS_CHANGE = 0.5
"""A mass that changed by more than this share makes a written body implausible."""


@dataclass(frozen=True)
class BodyWritten:
    """A body as given and as written (:func:`~wbfriction.inertia.urdf.inertia_changes`).

    Attributes:
        body: the joint carrying it.
        mass_given, mass: [kg]; ``mass_change``: relative (None: the given model had no mass there).
        com_shift: displacement of its centre of mass [m].
        moments_given, moments: principal moments about the centre of mass [kg·m^2], ascending;
            ``moments_change`` relative (None: not finite).
        kept: the held-out gate kept the identified body (None: no gate); ``limb``: the group decided on.
        identified: what the fit proposed (None: not known).
    """

    body: str
    mass_given: float
    mass: float
    mass_change: float | None
    com_shift: float
    moments_given: tuple[float, ...] = ()
    moments: tuple[float, ...] = ()
    moments_change: tuple[float | None, ...] = ()
    kept: bool | None = None
    limb: str | None = None
    identified: BodyProposal | None = None

    @property
    def has_mass(self) -> bool:
        return max(self.mass_given, self.mass) > 0

    def implausible(self) -> str:
        """Why the written body is no plausible link (one phrase), or "": a principal moment that fell by more than
        :data:`COLLAPSED` (a body collapsing to a rod or a point: physically consistent, the pseudo-inertia
        semidefinite, yet no link), or a mass changed by more than :data:`MASS_CHANGE`. An arm's torques determine
        combinations of its bodies (base parameters), not each body: such values carry a combination the held-out
        torques confirm, not a body's own inertia."""
        out = []
        fell = [(k, x) for k, x in enumerate(self.moments_change, 1) if x is not None and x < -COLLAPSED]
        if fell:
            out.append("principal moments collapsed (" + ", ".join(f"I{k} {100 * x:+.0f} %" for k, x in fell) + ")")
        if self.mass_change is not None and abs(self.mass_change) > MASS_CHANGE:
            out.append(f"mass {100 * self.mass_change:+.0f} %")
        return "; ".join(out)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"body": self.body, "mass_given": self.mass_given, "mass": self.mass,
                             "mass_change": self.mass_change, "com_shift": self.com_shift,
                             "moments_given": list(self.moments_given), "moments": list(self.moments),
                             "moments_change": list(self.moments_change)}
        if self.kept is not None:
            d["kept"], d["limb"] = self.kept, self.limb
        if self.identified is not None:
            d["identified"] = self.identified.to_dict()
        return d

    @classmethod
    def from_dict(cls, b: Any, key: str) -> BodyWritten:
        _need(isinstance(b, dict) and isinstance(b.get("body"), str)
              and all(_is_number(b.get(k)) for k in ("mass_given", "mass", "com_shift")), key)
        moments = {k: b.get(k) or [] for k in ("moments_given", "moments", "moments_change")}
        _need(all(isinstance(v, list) for v in moments.values()), key)
        p = b.get("identified")
        _need(p is None or (isinstance(p, dict) and all(_is_number(p.get(k)) for k in ("mass", "com_shift"))),
              f"{key}.identified")
        proposal = None if p is None else BodyProposal(
            float(p["mass"]), _optional(p, "mass_change", f"{key}.identified"), float(p["com_shift"]),
            tuple(map(float, p.get("moments") or [])),
            tuple(None if x is None else float(x) for x in p.get("moments_change") or []))
        return cls(body=b["body"], mass_given=float(b["mass_given"]), mass=float(b["mass"]),
                   mass_change=_optional(b, "mass_change", key), com_shift=float(b["com_shift"]),
                   moments_given=tuple(map(float, moments["moments_given"])),
                   moments=tuple(map(float, moments["moments"])),
                   moments_change=tuple(None if x is None else float(x) for x in moments["moments_change"]),
                   kept=None if "kept" not in b else bool(b["kept"]),
                   limb=None if b.get("limb") is None else str(b["limb"]), identified=proposal)


@dataclass(frozen=True)
class HeldOutRms:
    """RMS of measured − predicted joint torque on the held-out samples [N·m]: the given model, the
    given model with its best friction, the identified model, and the model written (None: no gate)."""

    given: float
    given_with_friction: float
    identified: float
    validated: float | None = None

    def to_dict(self) -> dict[str, float]:
        d = {"given": self.given, "given_with_friction": self.given_with_friction, "identified": self.identified}
        return d if self.validated is None else {**d, "validated": self.validated}


@dataclass(frozen=True)
class JointIdentified:
    """One torque-controlled joint.

    Attributes:
        identified: this route's friction (the model written), by the names of
            :attr:`Identification.friction_names` [N·m, N·m·s/rad]; ``identified_before_validation``:
            the fit's before the held-out gate (None: not known).
        acceleration_route: the acceleration route's fit with the model written (5.10);
            ``acceleration_route_given_model``: with the given model.
        holdout_rms: the held-out torques.
        armature_given, armature: the drive's rotor inertia [kg·m^2] (None: not known).
        acceleration_noise: share of its acceleration's power that is noise (None: not known).
        generating_share_given_model, generating_share: share of valid samples whose friction generates
            power (eq. 7.9), given model and written (None: not finite).
    """

    identified: dict[str, float]
    acceleration_route: FitResult
    acceleration_route_given_model: FitResult
    holdout_rms: HeldOutRms
    armature_given: float | None = None
    armature: float | None = None
    acceleration_noise: float | None = None
    generating_share_given_model: float | None = None
    generating_share: float | None = None
    identified_before_validation: dict[str, float] | None = None

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"identified": dict(self.identified),
                             "acceleration_route": fit_to_dict(self.acceleration_route),
                             "acceleration_route_given_model": fit_to_dict(self.acceleration_route_given_model)}
        if self.armature is not None:
            d["armature"] = {"given": self.armature_given, "identified": self.armature}
        return {**d, "acceleration_noise": self.acceleration_noise,
                "generating_share_given_model": self.generating_share_given_model,
                "generating_share": self.generating_share, "holdout_rms": self.holdout_rms.to_dict(),
                "identified_before_validation": None if self.identified_before_validation is None
                else dict(self.identified_before_validation)}

    @classmethod
    def from_dict(cls, joint: str, j: Any, key: str) -> JointIdentified:
        _need(isinstance(j, dict), key)
        h = j.get("holdout_rms")
        _need(isinstance(h, dict) and all(_is_number(h.get(k)) for k in ("given", "given_with_friction",
                                                                           "identified")), f"{key}.holdout_rms")
        holdout = HeldOutRms(float(h["given"]), float(h["given_with_friction"]), float(h["identified"]),
                             _optional(h, "validated", f"{key}.holdout_rms"))
        arm = j.get("armature")
        _need(arm is None or (isinstance(arm, dict) and all(_is_number(arm.get(k)) for k in ("given", "identified"))),
              f"{key}.armature")
        before = j.get("identified_before_validation")
        routes = {}
        for name in ("acceleration_route", "acceleration_route_given_model"):
            _need(isinstance(j.get(name, {}), dict), f"{key}.{name}")
            try:
                routes[name] = fit_from_dict(joint, j.get(name) or {})
            except InputError:
                raise _Malformed(f"{key}.{name}") from None
        return cls(identified=_numbers(j.get("identified"), f"{key}.identified"), holdout_rms=holdout,
                   acceleration_route=routes["acceleration_route"],
                   acceleration_route_given_model=routes["acceleration_route_given_model"],
                   armature_given=None if arm is None else float(arm["given"]),
                   armature=None if arm is None else float(arm["identified"]),
                   acceleration_noise=_optional(j, "acceleration_noise", f"{key}.acceleration_noise"),
                   generating_share_given_model=_optional(j, "generating_share_given_model",
                                                          f"{key}.generating_share_given_model"),
                   generating_share=_optional(j, "generating_share", f"{key}.generating_share"),
                   identified_before_validation=None if before is None
                   else _numbers(before, f"{key}.identified_before_validation"))


@dataclass(frozen=True)
class Identification:
    """The inertia model and friction identified together (``wbfriction identify``).

    Attributes:
        passes: the closed loop's passes, in order (the last one's model is written).
        bodies: every body, as given and as written.
        joints: per torque-controlled joint, in the model's order.
        holdout_samples: single-support samples held out at the end of the log.
        armature_mode: how the armature was treated (:class:`~wbfriction.inertia.options.InertialOptions`).
        moved_to_child_link: joints whose identified body went whole to their child link
            (:func:`~wbfriction.inertia.urdf.write_urdf`).
        provenance: the log and robot (:func:`~wbfriction.pipeline.provenance.log_provenance`); None: not known.
    """

    passes: tuple[PassSummary, ...]
    bodies: tuple[BodyWritten, ...]
    joints: dict[str, JointIdentified]
    holdout_samples: int
    armature_mode: str = "given"
    moved_to_child_link: tuple[str, ...] = ()
    provenance: dict[str, Any] | None = None

    @property
    def friction_names(self) -> tuple[str, ...]:
        """The names of this route's friction parameters (the columns of every joint's ``identified``)."""
        return tuple(next(iter(self.joints.values())).identified) if self.joints else ()

    def to_dict(self) -> dict[str, Any]:
        """The JSON's content (``wbfriction identify --json``)."""
        d: dict[str, Any] = {"sign_convention": SIGN_CONVENTION, "passes": [p.to_dict() for p in self.passes],
                             "armature_mode": self.armature_mode, "holdout_samples": self.holdout_samples,
                             "moved_to_child_link": list(self.moved_to_child_link),
                             "bodies": [b.to_dict() for b in self.bodies],
                             "joints": {j: v.to_dict() for j, v in self.joints.items()}}
        return d if self.provenance is None else {**d, "provenance": self.provenance}

    @classmethod
    def from_dict(cls, doc: Any, source: str = "identification") -> Identification:
        """Inverse of :meth:`to_dict`.

        Raises:
            InputError: ``<source>: '<key>' is missing or malformed``, naming the first key at fault.
        """
        try:
            _need(isinstance(doc, dict) and isinstance(doc.get("joints"), dict) and bool(doc["joints"]), "joints")
            joints = {str(j): JointIdentified.from_dict(str(j), v, f"joints.{j}") for j, v in doc["joints"].items()}
            _need(isinstance(doc.get("bodies"), list), "bodies")
            bodies = tuple(BodyWritten.from_dict(b, "bodies") for b in doc["bodies"])
            _need(isinstance(doc.get("passes"), list) and bool(doc["passes"]), "passes")
            passes = tuple(PassSummary.from_dict(p, f"passes[{k}]") for k, p in enumerate(doc["passes"]))
            _need(isinstance(doc.get("holdout_samples"), int) and not isinstance(doc["holdout_samples"], bool),
                  "holdout_samples")
            moved = doc.get("moved_to_child_link") or []
            _need(isinstance(moved, list), "moved_to_child_link")
            prov = doc.get("provenance")
            _need(prov is None or isinstance(prov, dict), "provenance")
        except _Malformed as exc:
            raise InputError(f"{source}: '{exc}' is missing or malformed (not written by "
                             "'wbfriction identify --json'?)") from None
        return cls(passes=passes, bodies=bodies, joints=joints, holdout_samples=int(doc["holdout_samples"]),
                   armature_mode=str(doc.get("armature_mode", "given")), moved_to_child_link=tuple(map(str, moved)),
                   provenance=prov)
