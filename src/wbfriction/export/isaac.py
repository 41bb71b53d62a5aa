"""The identified friction and armature as an Isaac Lab actuator dictionary (YAML).

Isaac Lab's ``ActuatorBaseCfg`` (``isaaclab.actuators``) takes per joint, by name, the fields

* ``armature`` [kg·m^2]: added to the joint-space inertia (the reflected rotor inertia);
* ``friction`` [N·m]: the static friction effort, the most that holds a joint at rest;
* ``dynamic_friction`` [N·m]: the dynamic (kinetic) friction effort, opposing a moving joint;
* ``viscous_friction`` [N·m·s/rad]: ``-viscous_friction * qd`` on a moving joint,

which PhysX applies as ``PxJointFrictionParams`` (static, dynamic effort, viscous coefficient;
dynamic <= static). These meanings hold from Isaac Sim 5.0 (Isaac Lab 2.2 on); in Isaac Sim 4.5
``friction`` was a unitless coefficient and the other two were not applied. Not Isaac Lab's
``damping``: that is the drive's PD gain, not friction.

From model (3.5) (:mod:`wbfriction.export.mapping`): ``friction = (1 + S) F_c`` (the static level
F_s; the ``stribeck`` model's F_s, the ``coulomb-viscous`` model's F_c), ``dynamic_friction = F_c``,
``viscous_friction = F_v``; the Stribeck velocity v_s and the tanh slope a are dropped, and so is the offset tau_os
but on a PD-driven joint, where it is the drivers' set-point offset ``tau_os / kp`` (listed in the header,
:mod:`wbfriction.export.drive`). A joint with F_s < F_c (S < 0: static below Coulomb friction, which PhysX does not
allow) is refused.

The document: ``joint_names_expr`` (the joints, each with friction from a fit followed by a comment of
its status, :func:`~wbfriction.export.mapping.status_note`), then one mapping per field, joint -> value,
the fields without any value left out (Isaac Lab then keeps the USD's). Isaac Lab reads the names as
regular expressions matched in full: they are written ``re.escape``-d (unchanged for names of
letters, digits and underscores). Use::

    cfg = ImplicitActuatorCfg(stiffness=..., damping=..., **yaml.safe_load(open("actuators.yaml")))

The YAML is written by hand (:func:`isaac_yaml`): names as double-quoted strings, numbers with a
dot in the mantissa and a signed exponent (``1.0e-05``), so that YAML 1.1 readers (PyYAML, what
Isaac Lab uses) and YAML 1.2 ones read the same floats back, exactly.

**PD-driven joints** (a robot with :attr:`Robot.pd`, :mod:`wbfriction.export.drive`): the document is then a
``DelayedPDActuatorCfg`` (Isaac Lab 3.0: the set-points delayed, the PD law on the simulated state, clipped) of the
PD-driven joints, every one of them (their gains are the robot's, whatever their fits), each field a mapping joint
-> value as above: ``stiffness = kp`` [N·m/rad], ``damping = kd`` [N·m·s/rad] (the driver's gains: here Isaac Lab's
``damping`` *is* the D gain), ``armature`` (the exported one, else the robot model's), the three frictions of the
joints with exported fits, ``actuator_effort_limit`` = the driver's torque limit [N·m] (joints without one left
out; Isaac Lab 2.x names it ``effort_limit``, 3.x reads that as a deprecated alias), and ``min_delay = max_delay``
= the delay in physics steps of ``physics_dt`` (Isaac Lab counts the delay in physics steps; rounded to the
nearest, :func:`~wbfriction.export.drive.delay_steps`, with a warning when it is not whole). Isaac Lab has no
encoder-offset field: the header lists the offsets and how to apply them. Joints with exported friction that
are not PD-driven are refused (one actuator group has one drive model). Use::

    cfg = DelayedPDActuatorCfg(**yaml.safe_load(open("actuators.yaml")))
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.export.catalog import ISAAC
from wbfriction.export.drive import (
    DEFAULT_PHYSICS_DT,
    DelaySteps,
    DriveExport,
    delay_steps,
    drive_export,
    held_back_warning,
    offset_lines,
    setpoint_offset_lines,
)
from wbfriction.export.mapping import FrictionLike, JointExport, joint_exports, status_note
from wbfriction.export.target import ExportOptions, ExportReport, ExportTarget
from wbfriction.logs.tables import write_atomic
from wbfriction.model.robot import Robot

ISAAC_FIELDS = ("armature", "friction", "dynamic_friction", "viscous_friction")
"""The per-joint fields of Isaac Lab's ``ActuatorBaseCfg`` this export fills, in the order written."""
PD_FIELDS = ("stiffness", "damping", *ISAAC_FIELDS, "actuator_effort_limit")
"""The per-joint fields of a ``DelayedPDActuatorCfg`` written for PD-driven joints, in the order written (then
``min_delay``, ``max_delay``)."""


def isaac_actuator_dict(friction: Mapping[str, FrictionLike], armature: Mapping[str, float] | None = None,
                        robot: Robot | None = None, physics_dt: float = DEFAULT_PHYSICS_DT) -> dict[str, Any]:
    """The Isaac Lab actuator dictionary (module docstring): ``joint_names_expr`` and, per field of
    :data:`ISAAC_FIELDS` that has values, ``{re.escape(joint): value}``; for a robot with PD-driven joints, the
    ``DelayedPDActuatorCfg`` of those (:data:`PD_FIELDS`, ``min_delay``, ``max_delay``).

    Args:
        friction: joint -> fitted friction of model (3.5) (:func:`wbfriction.fit.params_file.read_params`).
        armature: joint -> reflected rotor inertia [kg·m^2], or None.
        robot: if given, the joints must be its actuated joints (and are written in its order).
        physics_dt: Isaac Lab's physics step [s] the drivers' delay is counted in (a robot with PD-driven joints).

    Raises:
        InputError: friction that is not dissipative, F_s < F_c (PhysX needs ``dynamic_friction <=
            friction``), a negative armature, a joint ``robot`` does not actuate; with PD-driven joints, a joint
            with friction that is not PD-driven, a physics step that is not > 0.
    """
    joints = joint_exports(friction, armature, robot)
    drive = None if robot is None else drive_export(robot, joints)
    return _actuator_dict(joints) if drive is None else pd_actuator_dict(joints, drive, delay_steps(drive.delay,
                                                                                                   physics_dt))


def _check_static(joints: Mapping[str, JointExport]) -> None:
    for exp in joints.values():
        if exp.static is not None and exp.coulomb is not None and exp.static < exp.coulomb:
            raise InputError(f"joint '{exp.joint}': static friction F_s = {exp.static:g} N·m below the Coulomb "
                             f"friction F_c = {exp.coulomb:g} N·m (S < 0), which Isaac Lab (PhysX) does not allow")


def _actuator_dict(joints: Mapping[str, JointExport]) -> dict[str, Any]:
    """:func:`isaac_actuator_dict` of the joints' simulator parameters (:func:`joint_exports`)."""
    _check_static(joints)
    key = re.escape
    values = {
        "armature": {key(n): e.armature for n, e in joints.items() if e.armature is not None},
        "friction": {key(n): e.static for n, e in joints.items() if e.static is not None},
        "dynamic_friction": {key(n): e.coulomb for n, e in joints.items() if e.coulomb is not None},
        "viscous_friction": {key(n): e.viscous for n, e in joints.items() if e.viscous is not None},
    }
    return {"joint_names_expr": [key(n) for n in joints], **{f: values[f] for f in ISAAC_FIELDS if values[f]}}


def pd_actuator_dict(joints: Mapping[str, JointExport], drive: DriveExport, delay: DelaySteps) -> dict[str, Any]:
    """The ``DelayedPDActuatorCfg`` dictionary of the PD-driven joints (module docstring): ``joint_names_expr`` (every
    PD-driven joint), per field of :data:`PD_FIELDS` that has values ``{re.escape(joint): value}``, then
    ``min_delay = max_delay = delay.steps``.

    Args:
        joints: the joints' exported friction and armature (:func:`joint_exports`).
        drive: the robot's drivers (:func:`~wbfriction.export.drive.drive_export`).
        delay: the drivers' delay in physics steps (:func:`~wbfriction.export.drive.delay_steps`).

    Raises:
        InputError: F_s < F_c, a joint of ``joints`` that is not PD-driven.
    """
    _check_static(joints)
    others = [n for n in joints if n not in drive.joints]
    if others:
        raise InputError(f"joint '{others[0]}' has friction to export but is not PD-driven ([pd] joints): an Isaac Lab "
                         "actuator group has one drive model; list it in [pd] joints or export the others apart")
    key = re.escape
    pd = drive.joints

    def level(attr: str) -> dict[str, float]:
        return {key(n): v for n in pd if n in joints and (v := getattr(joints[n], attr)) is not None}

    values = {"stiffness": {key(n): drive.kp[n] for n in pd}, "damping": {key(n): drive.kd[n] for n in pd},
              "armature": {key(n): drive.armature[n] for n in pd if n in drive.armature},
              "friction": level("static"), "dynamic_friction": level("coulomb"), "viscous_friction": level("viscous"),
              "actuator_effort_limit": {key(n): v for n in pd if np.isfinite(v := drive.torque_limit[n])}}
    return {"joint_names_expr": [key(n) for n in pd], **{f: values[f] for f in PD_FIELDS if values[f]},
            "min_delay": delay.steps, "max_delay": delay.steps}


def yaml_float(x: float) -> str:
    """A finite float as YAML 1.1 and 1.2 both read back exactly: ``repr`` with ``.0`` added to a
    mantissa without a dot (``1e-05`` -> ``1.0e-05``; ``repr``'s exponents are signed)."""
    text = repr(float(x))
    mantissa, e, exponent = text.partition("e")
    return text if "." in mantissa or not e else f"{mantissa}.0e{exponent}"


def isaac_yaml(doc: Mapping[str, Any], header: str = "", notes: Mapping[str, str] | None = None) -> str:
    """The YAML text of :func:`isaac_actuator_dict`'s document (``header``: comment lines first; ``notes``:
    a one-line comment after each of the ``joint_names_expr`` entries it names)."""
    notes = notes or {}
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    for field, value in doc.items():
        if isinstance(value, int) and not isinstance(value, bool):
            lines.append(f"{field}: {value}")
            continue
        lines.append(f"{field}:")
        if isinstance(value, Mapping):
            lines += [f"  {json.dumps(k)}: {yaml_float(v)}" for k, v in value.items()]
        else:
            lines += [f"  - {json.dumps(k)}" + (f"  # {notes[k]}" if k in notes else "") for k in value]
    return "\n".join(lines) + "\n"


HEADER = """Isaac Lab actuator parameters (isaaclab.actuators.ActuatorBaseCfg, Isaac Sim >= 5.0) written by wbfriction
from model (3.5): friction = (1 + S) F_c (static), dynamic_friction = F_c, viscous_friction = F_v [N·m·s/rad],
armature [kg·m^2]; the Stribeck velocity, the tanh slope and the torque offset are dropped.
Use: ImplicitActuatorCfg(stiffness=..., damping=..., **yaml.safe_load(open(this_file)))"""


def pd_header(drive: DriveExport, delay: DelaySteps) -> str:
    """The header of a PD-driven robot's document: the mapping, the delay in steps, the encoder offsets (Isaac Lab
    has no field for them) and how to apply them, the use."""
    rounded = "" if delay.whole else f" (rounded: {delay.steps * delay.physics_dt:.6g} s)"
    lines = [
        "Isaac Lab actuator (isaaclab.actuators.DelayedPDActuatorCfg, Isaac Lab 3.0, Isaac Sim >= 5.0) of the "
        "PD-driven joints, written by wbfriction:",
        "stiffness = kp [N·m/rad], damping = kd [N·m·s/rad] (the drivers' gains), actuator_effort_limit = the drivers' "
        "torque limit [N·m] (Isaac Lab 2.x: effort_limit);",
        "friction = (1 + S) F_c (static), dynamic_friction = F_c, viscous_friction = F_v [N·m·s/rad] (model (3.5); the "
        "Stribeck velocity and the tanh slope dropped), armature [kg·m^2].",
        f"delay: {delay.delay!r} s = {delay.exact:.6g} physics steps of {delay.physics_dt!r} s (sim.dt): "
        f"min_delay = max_delay = {delay.steps}{rounded}.",
    ]
    if drive.encoder_offset:
        lines += ["encoder offset [rad] (the logged angle minus the model's: q_enc = q + offset) has no Isaac Lab "
                  "field: the drivers' PD runs on q_enc, so command q_des - offset",
                  "(e.g. the action term's offset) and observe joint_pos + offset; PACE's PaceDCMotorCfg: "
                  "encoder_bias = -offset.",
                  *(f"  {line}" for line in offset_lines(drive))]
    if drive.torque_offset:
        lines += ["the friction fits' constant tau_os [N·m] (the joint gets -tau_os) has no Isaac Lab field: it is the "
                  "drivers' set-point offset tau_os / kp, so command q_des - offset - tau_os / kp; per joint, "
                  "offset + tau_os / kp [rad]:",
                  *(f"  {line}" for line in setpoint_offset_lines(drive))]
    lines.append("Use: DelayedPDActuatorCfg(**yaml.safe_load(open(this_file)))")
    return "\n".join(lines)


NO_FRICTION = "wbfriction: PD drive only, no friction exported (the USD's kept)"
"""The note beside a PD-driven joint whose friction is not exported (no fit, or a fit not exported)."""


def write_isaac_yaml(path: str | Path, friction: Mapping[str, FrictionLike],
                     armature: Mapping[str, float] | None = None, robot: Robot | None = None,
                     physics_dt: float = DEFAULT_PHYSICS_DT) -> tuple[str, ...]:
    """Write :func:`isaac_actuator_dict` as YAML (:func:`isaac_yaml`, with a header that says the
    mapping and each joint's fit status after its name), atomically.

    Returns:
        the warnings of the export (a PD-driven robot's delay rounded to whole physics steps), one line each.

    Raises:
        what :func:`isaac_actuator_dict` raises; InputError: an output folder that does not exist.
    """
    return write_actuators(path, joint_exports(friction, armature, robot), robot, physics_dt)


def write_actuators(path: str | Path, joints: Mapping[str, JointExport], robot: Robot | None = None,
                    physics_dt: float = DEFAULT_PHYSICS_DT) -> tuple[str, ...]:
    """:func:`write_isaac_yaml` of the joints' simulator parameters (joint -> :class:`JointExport`,
    :func:`~wbfriction.export.mapping.joint_exports`, in the order written): same returns and errors; ``robot``
    (when it has PD-driven joints) makes the document theirs (module docstring)."""
    notes = {re.escape(name): note for name, exp in joints.items() if (note := status_note(exp)) is not None}
    drive = None if robot is None else drive_export(robot, joints)
    warnings: tuple[str, ...] = ()
    if drive is None or robot is None:
        text = isaac_yaml(_actuator_dict(joints), HEADER, notes)
    else:
        delay = delay_steps(drive.delay, physics_dt)
        notes |= {re.escape(n): NO_FRICTION for n in drive.joints
                  if not (n in joints and joints[n].has_friction)}
        text = isaac_yaml(pd_actuator_dict(joints, drive, delay), pd_header(drive, delay), notes)
        warnings = tuple(w for w in (delay.warning, held_back_warning(robot)) if w is not None)
    write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return warnings


class IsaacTarget(ExportTarget, kind=ISAAC):
    """``.yaml``, ``.yml``: an Isaac Lab actuator dictionary (module docstring).

    Attributes:
        physics_dt: Isaac Lab's physics step [s] a PD-driven robot's delay is counted in (``--physics-dt``).
    """


    def __init__(self, physics_dt: float = DEFAULT_PHYSICS_DT):
        delay_steps(0.0, physics_dt)  # checked
        self.physics_dt = float(physics_dt)

    reads = ("physics_dt",)

    def configure(self, options: ExportOptions) -> IsaacTarget:
        """A target counting the delay in steps of ``options.physics_dt``.

        Raises:
            InputError: a physics step that is not > 0 (naming ``--physics-dt``).
        """
        return IsaacTarget(options.physics_dt)

    def write(self, path: Path, robot: Robot, joints: Mapping[str, JointExport]) -> ExportReport:
        """:func:`write_actuators` (``robot``'s drivers, if it has PD-driven joints; its joints are already
        ``joints``')."""
        warnings = write_actuators(path, joints, robot, self.physics_dt)
        return self.report(path, joints, warnings)
