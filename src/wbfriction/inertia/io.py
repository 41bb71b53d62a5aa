"""The identification's file: the JSON of ``wbfriction identify --json`` (one writer, one reader).

:func:`identification_of` builds the typed result (:class:`~wbfriction.inertia.document.Identification`)
from a :class:`~wbfriction.inertia.closed_loop.ClosedLoop`, :func:`write_identification` writes it,
:func:`read_identification` reads and checks it (``wbfriction report --identification``).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from wbfriction.exceptions import InputError
from wbfriction.fit.params_file import finite_or_none
from wbfriction.inertia.closed_loop import ClosedLoop
from wbfriction.inertia.document import (
    BodyProposal,
    BodyWritten,
    HeldOutRms,
    Identification,
    JointIdentified,
    PassSummary,
)
from wbfriction.inertia.urdf import BodyChange, inertia_changes
from wbfriction.logs.tables import write_json


def identification_of(loop: ClosedLoop, moved: tuple[str, ...] = (),
                      provenance: dict[str, Any] | None = None) -> Identification:
    """The loop as the typed result the CLI prints and ``--json`` writes (:class:`~wbfriction.inertia.document.
    Identification`): per pass the identification's size and condition, its prior's weight and the residual
    it is measured in, the parameters the data did not determine
    (:func:`~wbfriction.inertia.excitation.unexcited_parameters`) and the held-out gate's verdict and solver
    outcome (:mod:`~wbfriction.inertia.validation`, :func:`~wbfriction.fit.solver.explain_solver`);
    per body the change written (:func:`wbfriction.inertia.urdf.inertia_changes`), the gate's decision and
    what the fit proposed; per torque-controlled joint the friction of both routes, the armature, the share
    of its acceleration's power that is noise, the power-generating shares before and after and the
    held-out torque RMS. ``moved``: what :func:`wbfriction.inertia.urdf.write_urdf` returned;
    ``provenance``: the log's (:func:`~wbfriction.pipeline.provenance.log_provenance`)."""
    final = loop.final
    ident = final.identification
    energy_given = {e.joint: e for e in loop.given.energy}
    energy = {e.joint: e for e in final.route.energy}
    joints = {}
    for i, joint in enumerate(ident.robot.torque_controlled):
        h = ident.holdout
        joints[joint] = JointIdentified(
            identified=dict(zip(ident.friction_names, map(float, ident.friction[i]))),
            acceleration_route=final.route.fit(joint), acceleration_route_given_model=loop.given.fit(joint),
            armature_given=float(ident.armature_given[i]), armature=float(ident.armature[i]),
            acceleration_noise=float(ident.acceleration_noise[i]),
            generating_share_given_model=finite_or_none(energy_given[joint].generating_share),
            generating_share=finite_or_none(energy[joint].generating_share),
            holdout_rms=HeldOutRms(float(h.given[i]), float(h.given_with_friction[i]), float(h.identified[i]),
                                   None if h.validated is None else float(h.validated[i])),
            identified_before_validation=dict(zip(ident.friction_names, map(float, ident.friction_fit[i])))
            if len(ident.friction_fit) else None)
    kept = {}
    if ident.validation is not None:
        kept = {b: (g.kept, g.name) for g in ident.validation.groups for b in g.bodies}
    proposed = {c.body: c for c in inertia_changes(ident.bodies, ident.pi_given, ident.pi_fit)} \
        if len(ident.pi_fit) else {}
    bodies = tuple(BodyWritten(
        body=c.body, mass_given=c.mass_given, mass=c.mass, mass_change=finite_or_none(c.mass_change),
        com_shift=c.com_shift,
        moments_given=tuple(c.moments_given.tolist()), moments=tuple(c.moments.tolist()),
        moments_change=tuple(finite_or_none(x) for x in c.moments_change),
        kept=kept[c.body][0] if c.body in kept else None, limb=kept[c.body][1] if c.body in kept else None,
        identified=_proposal(proposed.get(c.body))) for c in inertia_changes(ident.bodies, ident.pi_given, ident.pi))
    passes = tuple(PassSummary(
        stribeck_velocity=p.stribeck_velocity,
        stribeck_joints=None if p.stribeck_joints is None else tuple(p.stribeck_joints),
        samples=p.identification.samples, base_parameters=p.identification.base.count,
        parameters=int(p.identification.base.combination.shape[1]),
        condition=finite_or_none(p.identification.base.condition), prior=p.identification.prior,
        prior_scores={f"{w:g}": v for w, v in p.identification.prior_scores.items()},
        residual_std=finite_or_none(p.identification.residual_std), not_excited=tuple(p.identification.unexcited),
        message=p.identification.message,
        solver=None if p.identification.solver is None else p.identification.solver.to_dict(),
        verdict=None if p.identification.validation is None
        else p.identification.validation.verdict(f"pass {k + 1}"),
        validation=None if p.identification.validation is None else p.identification.validation.to_dict())
        for k, p in enumerate(loop.passes))
    return Identification(passes=passes, bodies=bodies, joints=joints, holdout_samples=ident.holdout.samples,
                          armature_mode=ident.armature_mode, moved_to_child_link=tuple(moved),
                          provenance=provenance)


def _proposal(c: BodyChange | None) -> BodyProposal | None:
    """What the fit proposed for a body (None: nothing known)."""
    if c is None:
        return None
    return BodyProposal(mass=c.mass, mass_change=finite_or_none(c.mass_change), com_shift=c.com_shift,
                        moments=tuple(c.moments.tolist()),
                        moments_change=tuple(finite_or_none(x) for x in c.moments_change))


def write_identification(path: str | Path, identification: Identification) -> None:
    """Write an identification's JSON (:meth:`~wbfriction.inertia.document.Identification.to_dict`),
    whole or not at all.

    Raises:
        InputError: an output folder that does not exist.
    """
    write_json(path, identification.to_dict())


def read_identification(path: str | Path) -> Identification:
    """What ``wbfriction identify --json`` wrote (:meth:`~wbfriction.inertia.document.Identification.from_dict`).

    Raises:
        InputError: a file that is not such JSON (named with the key at fault).
    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: not an identification written by 'wbfriction identify --json' ({exc})") from None
    return Identification.from_dict(doc, str(path))
