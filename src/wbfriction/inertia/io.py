"""The identification's document: the JSON of ``wbfriction identify --json`` (one writer, one reader).

:func:`identification_document` builds it from a :class:`~wbfriction.inertia.closed_loop.ClosedLoop`
(per pass the identification's size and condition, its prior and the parameters the data did not
determine; per body the changes; per torque-controlled joint the friction of both routes, the armature,
the power-generating shares and the held-out torque RMS),
:func:`write_identification` writes it, :func:`read_identification` reads and checks it
(``wbfriction report --identification``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.io import fit_to_dict
from wbfriction.inertia.closed_loop import ClosedLoop
from wbfriction.inertia.urdf import inertia_changes
from wbfriction.logs.tables import write_json


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def identification_document(loop: ClosedLoop, moved: tuple[str, ...] = (),
                            provenance: dict[str, Any] | None = None) -> dict[str, Any]:
    """The loop as a JSON-ready dict (``wbfriction identify --json``, read by the report):
    per pass the identification's size and condition, its prior's weight and the residual it is
    measured in, and the parameters the data did not determine (``not_excited``: each with the
    ones it acts with, :func:`~wbfriction.inertia.excitation.unexcited_parameters`); per body the
    changes (:func:`wbfriction.inertia.urdf.inertia_changes`); per torque-controlled joint the
    friction of both routes, the armature (``armature``: ``given`` and ``identified`` [kg·m^2],
    and how it was treated, ``armature_mode``), the share of its acceleration's power that is
    noise (``acceleration_noise``: :class:`~wbfriction.inertia.identification.InertialIdentification`),
    the power-generating shares before and after, and the held-out torque RMS. ``moved``: what
    :func:`wbfriction.inertia.urdf.write_urdf` returned; ``provenance``: recorded last.

    The gate (:mod:`~wbfriction.inertia.validation`): per pass ``verdict`` (one line), ``validation``
    (per limb ``kept``, ``reason``, ``joints``, ``rms_before``/``rms_after`` [N·m]; the held-out RMS over
    all joints and per joint of the given model with its best friction, the identified and the validated
    model) and ``solver`` (``converged``, ``meaning``, ``raw_message``, ``status``:
    :func:`~wbfriction.friction.solver.explain_solver`; ``message`` says it in words). ``bodies``
    describe the validated model (the one written), each with ``kept``, its ``limb`` and what the fit
    proposed (``identified``: mass, centre-of-mass shift, principal moments); per joint ``identified``
    is the validated model's friction, ``identified_before_validation`` the fit's, and ``holdout_rms``
    gains ``validated``."""
    final = loop.final
    ident = final.identification
    changes = inertia_changes(ident.bodies, ident.pi_given, ident.pi)
    energy_given = {e.joint: e for e in loop.given.energy}
    energy = {e.joint: e for e in final.route.energy}
    joints = {}
    for i, joint in enumerate(ident.robot.torque_controlled):
        joints[joint] = {
            "identified": dict(zip(ident.friction_names, map(float, ident.friction[i]))),
            "acceleration_route": fit_to_dict(final.route.fit(joint)),
            "acceleration_route_given_model": fit_to_dict(loop.given.fit(joint)),
            "armature": {"given": float(ident.armature_given[i]), "identified": float(ident.armature[i])},
            "acceleration_noise": float(ident.acceleration_noise[i]),
            "generating_share_given_model": _finite(energy_given[joint].generating_share),
            "generating_share": _finite(energy[joint].generating_share),
            "holdout_rms": {"given": float(ident.holdout.given[i]),
                            "given_with_friction": float(ident.holdout.given_with_friction[i]),
                            "identified": float(ident.holdout.identified[i]),
                            **({} if ident.holdout.validated is None
                               else {"validated": float(ident.holdout.validated[i])})},
            "identified_before_validation": dict(zip(ident.friction_names, map(float, ident.friction_fit[i])))
            if len(ident.friction_fit) else None,
        }
    kept = {}
    if ident.validation is not None:
        kept = {b: (g.kept, g.name) for g in ident.validation.groups for b in g.bodies}
    fit_changes = {c.body: c for c in inertia_changes(ident.bodies, ident.pi_given, ident.pi_fit)} \
        if len(ident.pi_fit) else {}
    doc = {
        "sign_convention": ("tau_f = -f(qd); f = F_v qd + F_c tanh(a qd) (+ (F_s - F_c) tanh(a qd) exp(-(qd/v_s)^2))"
                            " + tau_os"),
        "passes": [{"stribeck_velocity": p.stribeck_velocity,
                    "stribeck_joints": None if p.stribeck_joints is None else list(p.stribeck_joints),
                    "samples": p.identification.samples,
                    "base_parameters": p.identification.base.count,
                    "parameters": int(p.identification.base.combination.shape[1]),
                    "condition": _finite(p.identification.base.condition),
                    "prior": p.identification.prior,
                    "prior_scores": {f"{w:g}": v for w, v in p.identification.prior_scores.items()},
                    "residual_std": _finite(p.identification.residual_std),
                    "not_excited": [{"parameter": u.parameter, "information": _finite(u.information),
                                     "partners": u.partners} for u in p.identification.unexcited],
                    "message": p.identification.message,
                    "solver": None if p.identification.solver is None else p.identification.solver.to_dict(),
                    "verdict": None if p.identification.validation is None
                    else p.identification.validation.verdict(f"pass {k + 1}"),
                    "validation": None if p.identification.validation is None
                    else p.identification.validation.to_dict()} for k, p in enumerate(loop.passes)],
        "armature_mode": ident.armature_mode,
        "holdout_samples": ident.holdout.samples,
        "moved_to_child_link": list(moved),
        "bodies": [{"body": c.body, "mass_given": c.mass_given, "mass": c.mass, "mass_change": _finite(c.mass_change),
                    "com_shift": c.com_shift, "moments_given": c.moments_given.tolist(), "moments": c.moments.tolist(),
                    "moments_change": [_finite(x) for x in c.moments_change],
                    **_fit_entry(c.body, kept, fit_changes)} for c in changes],
        "joints": joints,
    }
    if provenance is not None:
        doc["provenance"] = provenance
    return doc


def _fit_entry(body: str, kept: dict, fit_changes: dict) -> dict[str, Any]:
    """A body's gate decision (``kept``, ``limb``) and what the fit proposed for it (``identified``)."""
    out: dict[str, Any] = {}
    if body in kept:
        out["kept"], out["limb"] = kept[body]
    c = fit_changes.get(body)
    if c is not None:
        out["identified"] = {"mass": c.mass, "mass_change": _finite(c.mass_change), "com_shift": c.com_shift,
                             "moments": c.moments.tolist(), "moments_change": [_finite(x) for x in c.moments_change]}
    return out


def write_identification(path: str | Path, doc: dict[str, Any]) -> None:
    """Write an :func:`identification_document`, whole or not at all.

    Raises:
        InputError: an output folder that does not exist.
    """
    write_json(path, doc)


def read_identification(path: str | Path) -> dict[str, Any]:
    """What ``wbfriction identify --json`` wrote (:func:`identification_document`).

    Raises:
        InputError: a file that is not such JSON (named with the key at fault).
    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: not an identification written by 'wbfriction identify --json' ({exc})") from None

    def need(ok: bool, key: str) -> None:
        if not ok:
            raise InputError(f"{path}: '{key}' is missing or malformed (not written by 'wbfriction identify --json'?)")

    need(isinstance(doc, dict) and isinstance(doc.get("joints"), dict) and doc["joints"], "joints")
    for joint, j in doc["joints"].items():
        need(isinstance(j, dict) and isinstance(j.get("holdout_rms"), dict)
             and all(isinstance(j["holdout_rms"].get(k), (int, float))
                     for k in ("given", "given_with_friction", "identified")), f"joints.{joint}.holdout_rms")
        need(isinstance(j.get("identified"), dict)
             and all(isinstance(v, (int, float)) for v in j["identified"].values()), f"joints.{joint}.identified")
        need("armature" not in j or (isinstance(j["armature"], dict) and all(
            isinstance(j["armature"].get(k), (int, float)) for k in ("given", "identified"))),
             f"joints.{joint}.armature")
    need(isinstance(doc.get("bodies"), list) and all(
        isinstance(b, dict) and isinstance(b.get("body"), str)
        and all(isinstance(b.get(k), (int, float)) for k in ("mass_given", "mass", "com_shift"))
        for b in doc["bodies"]), "bodies")
    need(isinstance(doc.get("passes"), list) and doc["passes"] and all(isinstance(p, dict) for p in doc["passes"]),
         "passes")
    for k, p in enumerate(doc["passes"]):
        need("not_excited" not in p or (isinstance(p["not_excited"], list) and all(
            isinstance(u, dict) and isinstance(u.get("parameter"), str) and isinstance(u.get("partners"), dict)
            for u in p["not_excited"])), f"passes[{k}].not_excited")
    need(isinstance(doc.get("holdout_samples"), int), "holdout_samples")
    return doc
