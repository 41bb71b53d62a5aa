"""A MuJoCo model (MJCF) of the robot with the identified friction, armature and inertias: the robot's whole
model, loadable and steppable in MuJoCo as it is (issue 67).

Built from the robot's URDF by MuJoCo's own URDF import (:func:`~wbfriction.model.mjspec.urdf_model_spec`): the
URDF's collision geometry (meshes at their absolute path in the installed package, nothing copied; ``<visual>``
dropped: Collada ``.dae``, which MuJoCo does not read, or finer copies of the collision meshes; a collision mesh
MuJoCo cannot read, or not found, left out and named in a warning), the robot's geoms colliding with the floor and
what a user adds but not with each other (``contype 1``, ``conaffinity 0``), no mass from the geometry
(``inertiafromgeom`` off), the URDF's ``<dynamics>`` dropped (the friction is the exported one only), static links
fused into their bodies as Pinocchio merges them, each such link kept as a ``<site>`` of its name at its frame (a
sole, an IMU: the frames a robot TOML names; Pinocchio's MJCF parser reads sites as frames). A robot loaded from an
MJCF (:attr:`Robot.model_format`) starts from that file as it is. A floating-base robot gets a free joint at its
root link and a ``floor`` plane at ``z = 0``; a fixed-base one (:attr:`Robot.floating_base` false, e.g. the KUKA
LWR4+, a hung Go2) has its root link welded to the world where the URDF puts it, and no floor. The robot's locked
joints (:attr:`Robot.locked_joints`) are welded at their positions, so that the joints are :attr:`Robot.actuated`,
as in the Pinocchio model; the equality constraints, actuators and sensors on a locked joint go with it (the
Panda's fingers: the URDF's ``<mimic>`` of ``panda_finger_joint2`` is such a constraint). Every actuated joint has
an actuator named as it: a ``<motor>`` (``ctrl`` = the torque [N·m], ``ctrlrange`` the URDF's effort limit) where
the joint is torque-controlled, a position actuator with the drivers' gains where it is PD-driven (below), the
model file's own where it has one. The keyframe :data:`~wbfriction.export.mjcf_scene.STANCE` holds the reference
configuration standing on the floor (:func:`~wbfriction.export.mjcf_scene.add_stance`); a model file's keyframes
are dropped.

Per actuated joint (:mod:`wbfriction.export.mapping`): ``damping = F_v`` [N·m·s/rad],
``frictionloss = F_c`` [N·m], ``armature`` [kg·m^2] (the given one, else the robot model's
``armature``, zero unless its configuration sets one); a joint without identified friction holds none
(``damping`` and ``frictionloss`` 0: the URDF's ``<dynamics>`` are dropped, and the ``.urdf`` export sets them to 0
alike, :mod:`wbfriction.export.urdf`) but from a robot's MJCF, whose own values it keeps. The written file has a
comment before each joint with friction from a fit, its status (:func:`~wbfriction.export.mapping.status_note`).
Identified inertias (a ``pin.Model`` of the robot) go through :func:`wbfriction.inertia.urdf.write_urdf` into the
URDF the model is built from.

What ``mujoco.mj_inverse`` returns with these fields (MuJoCo 4 defaults: continuous-time inverse,
``invdiscrete`` off; no contact: a base off the floor, the robot's geoms not colliding with each other; joint
limits inactive inside them):

.. math::

    \\texttt{qfrc\\_inverse} = M(q)\\,\\ddot q + c(q, \\dot q) + \\texttt{damping}\\,\\dot q - f_{loss},
    \\qquad f_{loss} = \\operatorname{clip}\\Big(-\\frac{\\ddot q + b\\,\\dot q}{R},\\,
                     -\\texttt{frictionloss},\\, \\texttt{frictionloss}\\Big)

with ``M`` including the armature on its diagonal (as Pinocchio's ``rnea`` with ``model.armature``),
``f_loss`` the friction-loss constraint force (``efc_force`` of the rows with ``efc_type ==
mjCNSTR_FRICTION_DOF``). MuJoCo's soft-constraint inverse (computation chapter, "Dual problem":
``f = argmin_{|f| <= frictionloss} R f^2 / 2 + f (a_c - a_ref)``) gives it analytically, with
``a_c = qdd`` and the reference acceleration ``a_ref = -b qd`` of a friction row (no position
residual): ``b = 2 / (solimp[1] solref[0])`` (default ``2 / (0.95 * 0.02) = 105.3 1/s``) and
``R = (1 - solimp[0]) / solimp[0] * dof_invweight0`` (default ``solimp[0] = 0.9``; MuJoCo's
diagonal approximation of ``M^-1``, frozen at ``qpos0``). So mj_inverse's dry friction is

* ``frictionloss * sgn(qdd + b qd)`` outside a narrow band ``|qdd + b qd| < frictionloss * R``:
  Coulomb friction whose sign follows ``qd + qdd / b``, i.e. it reverses about ``qdd / b`` before
  the velocity does (at 5 rad/s² that is 0.05 rad/s), where model (3.5) reverses with ``tanh(a qd)``;
* linear, ``(qdd + b qd) / R``, inside the band; zero at rest (``qd = qdd = 0``: mj_inverse holds
  no static friction).

Compared with the torque of model (3.5), ``tau = rnea + F_v qd + F_c tanh(a qd)(1 + S e^...) + tau_os``,
the MuJoCo model keeps ``F_v qd`` exactly and ``F_c`` away from reversals, and drops the
Stribeck bump, the tanh and ``tau_os`` (:mod:`wbfriction.export.mapping`), which a PD-driven joint's actuator holds
(below).

**PD-driven joints** (a robot with :attr:`Robot.pd`, :mod:`wbfriction.export.drive`): each gets MuJoCo's position
actuator, named as its joint (the model file's own actuators of those joints are replaced): ``gainprm[0] = kp``,
``biasprm = [-kp * offset - tau_os, -kp, -kd]``, so that

.. math::

    \\texttt{actuator\\_force} = k_p\\,(\\texttt{ctrl} - \\text{offset} - \\texttt{qpos}) - k_d\\,\\texttt{qvel}
                               - \\tau_{os},

clipped at ``forcerange = [-tau_max, tau_max]`` (none where the driver has no limit; the joint's
``actuatorfrcrange``, MuJoCo's import of the URDF's effort limit, is lifted: the driver's limit is the one, and
it defaults to the URDF's): ``ctrl`` is the set-point
``q_des`` as the robot commands it (the encoder's frame), ``qpos`` the model's angle, which the encoder reads as
``qpos + offset``. The encoder offset goes in the actuator's bias, where the driver meets it, rather than in the
joint's ``ref`` (which would move ``qpos``'s zero for everything that reads it: ranges, keyframes, Pinocchio's
reading of the file). With the ``biasprm[0]`` term MuJoCo's writer spells the actuator ``<general ...
biastype="affine">``, what ``<position kp kv>`` compiles to. The set-points' delay is MuJoCo 4's actuator
``delay`` [s] (less 1 ns, :data:`~wbfriction.export.drive.HOLD_EDGE`: a delay of whole timesteps would sit on
the hold's edge) with ``interp`` zero-order hold (the driver holds each set-point) and a history of ``nsample``
samples, enough at the model's ``timestep`` and any down to 0.5 ms (:func:`~wbfriction.export.drive.history_samples`;
a smaller timestep needs more: MuJoCo reads a too-short buffer's oldest sample, silently). The history starts at
zero (``mj_resetData``): fill it with the first set-point (``mujoco.mj_initCtrlHistory``) before stepping. The
driver's ``qd_des`` and ``tau_ff`` have no input in a position actuator (a ``<motor>`` beside it can carry
``kd qd_des + tau_ff``). ``tau_os`` is the constant of the joint's exported friction fit
(:attr:`~wbfriction.export.drive.DriveExport.torque_offset`: a set-point offset ``tau_os / kp``; 0 without one).
A comment at the top of ``<actuator>`` says all this and lists the encoder offsets and the set-point offsets.

The written MJCF (:func:`write_mjcf`) is MuJoCo's own ``MjSpec.to_xml`` with every number at full precision, its
sibling bodies in the robot model's joint order (:func:`~wbfriction.export.mjcf_text.mjcf_xml`).
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import ModelError
from wbfriction.export.catalog import MJCF
from wbfriction.export.drive import (
    HOLD_EDGE,
    DriveExport,
    drive_export,
    held_back_warning,
    history_samples,
    offset_lines,
    setpoint_offset_lines,
)
from wbfriction.export.mapping import FrictionLike, JointExport, joint_exports, status_note
from wbfriction.export.mjcf_scene import add_floor, add_motors, add_stance
from wbfriction.export.mjcf_text import mjcf_xml
from wbfriction.export.target import ExportReport, ExportTarget
from wbfriction.export.urdf import identified_parameters
from wbfriction.inertia.urdf import write_urdf
from wbfriction.logs.tables import write_atomic
from wbfriction.model.mjspec import mujoco_message, urdf_model_spec
from wbfriction.model.mjspec import urdf_spec as urdf_spec  # re-exported: wbfriction.export.urdf_spec
from wbfriction.model.robot import Robot

if TYPE_CHECKING:
    import mujoco

def robot_spec(robot: Robot, inertias_urdf: str | Path | None = None) -> tuple[mujoco.MjSpec, tuple[str, ...]]:
    """The MuJoCo spec of ``robot``'s own description, and the collision elements it skipped: its URDF with its
    collision geometry, without its joints' ``<dynamics>`` (:func:`~wbfriction.model.mjspec.urdf_model_spec`; read from
    ``inertias_urdf``, a copy with identified inertias, when given, the meshes found from the robot's URDF), or its
    MJCF as it is (with a free joint added at its top body if it is a floating base that has none).

    Raises:
        ModelError: a file MuJoCo cannot read.
    """
    import mujoco
    if robot.model_format == "urdf":
        spec, skipped = urdf_model_spec(robot.urdf if inertias_urdf is None else inertias_urdf, robot.floating_base,
                                        robot.urdf)
        for geom in spec.geoms:  # the robot's own: no self-collision (its meshes overlap at the joints)
            geom.conaffinity = 0
        return spec, skipped
    try:
        spec = mujoco.MjSpec.from_file(str(robot.urdf))
    except Exception as exc:  # mujoco raises ValueError with its parser's message
        raise ModelError(f"{robot.urdf}: MuJoCo cannot read the MJCF: {mujoco_message(exc)}") from None
    base = spec.worldbody.first_body()
    if robot.floating_base and base is not None and not any(j.type == mujoco.mjtJoint.mjJNT_FREE
                                                            for j in base.joints):
        base.add_freejoint()
    return spec, ()


def _add_link_sites(spec: mujoco.MjSpec) -> None:
    """A ``<site>`` at the origin of every body MuJoCo fuses into its parent (``fusestatic``: a URDF link on
    a fixed joint, a sole, an IMU link; a locked joint's link), named as the body: the fused site keeps the
    link's frame, which a robot TOML may name (contact frames, sensors)."""
    compiled = compile_spec(spec.copy())  # compiling fuses the static bodies of the spec it compiles
    kept = {compiled.body(i).name for i in range(compiled.nbody)}
    for body in spec.bodies:
        if body.name and body.name not in kept:
            body.add_site(name=body.name)


def _drop_references(spec: mujoco.MjSpec, name: str) -> None:
    """Delete what refers to joint ``name`` by name: joint equality constraints (MuJoCo's URDF import turns a
    ``<mimic>`` into one: the Panda's ``panda_finger_joint2`` follows ``panda_finger_joint1``), actuators
    that drive it, sensors that read it. A welded joint has nothing left to couple, drive or read, and
    Pinocchio's model (``buildModelFromUrdf`` without ``mimic``, then ``buildReducedModel``) has no such
    coupling either: the joint that was coupled to it moves freely in both."""
    import mujoco
    for eq in list(spec.equalities):
        if eq.type == mujoco.mjtEq.mjEQ_JOINT and name in (eq.name1, eq.name2):
            spec.delete(eq)
    for act in list(spec.actuators):
        if act.trntype == mujoco.mjtTrn.mjTRN_JOINT and act.target == name:
            spec.delete(act)
    for sensor in list(spec.sensors):
        if sensor.objtype == mujoco.mjtObj.mjOBJ_JOINT and sensor.objname == name:
            spec.delete(sensor)


def _lock_joint(spec: mujoco.MjSpec, name: str, value: float) -> None:
    """Weld a hinge or slide joint at ``value`` [rad or m]: its body placed there, the joint deleted with
    what refers to it (:func:`_drop_references`)."""
    import mujoco
    joint = spec.joint(name)
    if joint is None:
        raise ModelError(f"MuJoCo model has no joint '{name}' to lock")
    body = joint.parent
    flat = np.zeros(9)
    mujoco.mju_quat2Mat(flat, np.asarray(body.quat, dtype=float))
    rot = flat.reshape(3, 3)
    axis = np.asarray(joint.axis, dtype=float) / np.linalg.norm(joint.axis)
    if joint.type == mujoco.mjtJoint.mjJNT_HINGE:
        dq, q, turn = np.zeros(4), np.zeros(4), np.zeros(9)
        mujoco.mju_axisAngle2Quat(dq, axis, value)
        mujoco.mju_quat2Mat(turn, dq)
        p = np.asarray(joint.pos, dtype=float)  # the rotation is about the axis through the joint's position
        body.pos = np.asarray(body.pos, dtype=float) + rot @ (p - turn.reshape(3, 3) @ p)
        mujoco.mju_mulQuat(q, np.asarray(body.quat, dtype=float), dq)
        body.quat = q
    elif joint.type == mujoco.mjtJoint.mjJNT_SLIDE:
        body.pos = np.asarray(body.pos, dtype=float) + rot @ axis * value
    else:
        raise ModelError(f"locked joint '{name}' is neither a hinge nor a slide in MuJoCo")
    _drop_references(spec, name)
    spec.delete(joint)


def _armature(robot: Robot, name: str, exp: JointExport | None) -> float:
    if exp is not None and exp.armature is not None:
        return exp.armature
    model = robot.model
    return float(model.armature[model.idx_vs[model.getJointId(name)]])


def mujoco_spec(robot: Robot, friction: Mapping[str, FrictionLike], armature: Mapping[str, float] | None = None,
                inertias: pin.Model | None = None) -> mujoco.MjSpec:
    """The MuJoCo spec of ``robot`` with the identified friction and armature (module docstring).

    Args:
        robot: the robot; its URDF (or MJCF) is read (:func:`robot_spec`), :attr:`Robot.floating_base` decides
            the free joint.
        friction: joint -> fitted friction of model (3.5) (:func:`wbfriction.fit.params_file.read_params`).
        armature: joint -> reflected rotor inertia [kg·m^2]; a joint not in it keeps the robot
            model's ``armature``.
        inertias: a model of ``robot`` with identified inertias, or None (the URDF's).

    Raises:
        InputError: friction that is not dissipative, a joint the robot does not actuate, an
            inertia model of another robot, inertias of a robot loaded from an MJCF.
        ModelError: a URDF MuJoCo cannot read, or whose joints are not the robot's.
    """
    return _spec(robot, joint_exports(friction, armature, robot), inertias).spec


@dataclass
class _Built:
    """What :func:`_spec` built: the spec, the collision elements skipped, notes beside joints."""

    spec: mujoco.MjSpec
    skipped: tuple[str, ...]
    notes: dict[str, str]


def _spec(robot: Robot, joints: Mapping[str, JointExport], inertias: pin.Model | None) -> _Built:
    """:func:`mujoco_spec` of the joints' simulator parameters (:func:`joint_exports`), with what was skipped."""
    import mujoco
    if inertias is None:
        spec, skipped = robot_spec(robot)
    else:
        robot.require_urdf("exporting identified inertias")
        pi = identified_parameters(robot, inertias)
        with tempfile.TemporaryDirectory(prefix="wbfriction-mjcf-") as tmp:
            path = Path(tmp) / Path(robot.urdf).name
            write_urdf(robot, pi, path)
            spec, skipped = robot_spec(robot, path)
    for key in list(spec.keys):  # a model file's keyframes: their sizes are that file's
        spec.delete(key)
    for name, value in robot.locked_joints.items():
        _lock_joint(spec, name, value)
    names = {j.name for j in spec.joints if j.type != mujoco.mjtJoint.mjJNT_FREE}
    if names != set(robot.actuated):
        odd = sorted(names.symmetric_difference(robot.actuated))
        raise ModelError(f"{robot.urdf}: the MuJoCo model's joints are not robot '{robot.name}''s "
                         f"(e.g. '{odd[0]}')")
    _add_link_sites(spec)
    notes: dict[str, str] = {}
    for name in robot.actuated:
        joint, exp = spec.joint(name), joints.get(name)
        if exp is not None and exp.viscous is not None and exp.coulomb is not None:
            damping = np.zeros_like(np.asarray(joint.damping, dtype=float))
            damping[0] = exp.viscous
            joint.damping = damping
            joint.frictionloss = exp.coulomb
        joint.armature = _armature(robot, name, exp)
    drive = drive_export(robot, joints)
    if drive is not None:
        _add_drives(spec, drive)
    add_motors(spec, robot, () if drive is None else drive.joints)
    if robot.floating_base:
        add_floor(spec)
    add_stance(spec, robot, drive, compile_spec(spec.copy(), robot.urdf))
    return _Built(spec, skipped, notes)


def _add_drives(spec: mujoco.MjSpec, drive: DriveExport) -> None:
    """A position actuator per PD-driven joint, named as the joint (module docstring), replacing the model file's
    actuators of those joints."""
    import mujoco
    for act in list(spec.actuators):
        if act.trntype == mujoco.mjtTrn.mjTRN_JOINT and act.target in drive.joints:
            spec.delete(act)
    timestep = float(spec.option.timestep)
    for name in drive.joints:
        kp, kd, limit = drive.kp[name], drive.kd[name], drive.torque_limit[name]
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp, kv=kd)
        bias = np.array(act.biasprm, dtype=float)
        bias[0] = 0.0 - kp * drive.setpoint_offset(name)  # 0.0, not -0.0, without an offset
        act.biasprm = bias
        if np.isfinite(limit):
            act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.forcerange = [-limit, limit]
        joint = spec.joint(name)  # the URDF's effort limit, as MuJoCo's import sets it: the driver's limit instead
        joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_FALSE
        joint.actfrcrange = [0.0, 0.0]
        if drive.delay > HOLD_EDGE:
            act.delay = drive.delay - HOLD_EDGE
            act.nsample = history_samples(drive.delay, timestep)
            act.interp = 0  # zero-order hold


def drive_note(drive: DriveExport, model: mujoco.MjModel) -> str:
    """The comment at the top of ``<actuator>`` of a PD-driven robot (module docstring), no ``--`` in it."""
    lines = ["PD drivers (wbfriction): each <general> is MuJoCo's <position> with its set-point offset:",
             "force = gainprm[0] ctrl + biasprm[0] + biasprm[1] qpos + biasprm[2] qvel",
             "      = kp (ctrl - offset - qpos) - kd qvel (gainprm kp, biasprm -kp offset, -kp, -kd),",
             "clipped at forcerange (the driver's torque limit): ctrl is the set-point q_des as the robot commands",
             "it (encoder frame), qpos the model's angle (the encoder reads qpos + offset). qd_des and tau_ff have",
             "no input here (a <motor> beside it can carry kd qd_des + tau_ff)."]
    if drive.torque_offset:
        lines += ["The friction fits' constant tau_os (the joint gets -tau_os) is in the bias as a set-point offset",
                  "tau_os / kp: biasprm[0] = -kp (offset + tau_os / kp) [rad], per joint:",
                  *(f"  {line}" for line in setpoint_offset_lines(drive))]
    if drive.delay > HOLD_EDGE:
        samples = min((int(model.actuator_history[i, 0]) for i in range(model.nu)
                       if model.actuator(i).name in drive.joints), default=0)
        step, least = model.opt.timestep, drive.delay / samples
        lines += [f"delay {drive.delay!r} s, zero-order hold, written 1 ns less (a delay of whole timesteps would",
                  "sit on the hold's edge, read one step early or late as the floating-point time rounds);",
                  f"nsample {samples} holds it at timesteps >= {least:.6g} s (this model's: {step!r} s).",
                  "The history starts at zero: fill it with the first set-point (mujoco.mj_initCtrlHistory)."]
    if drive.encoder_offset:
        lines += ["encoder offsets [rad] (the logged angle minus the model's):",
                  *(f"  {line}" for line in offset_lines(drive))]
    return "\n".join(f" {line}" for line in lines) + "\n"


def compile_spec(spec: mujoco.MjSpec, source: str | Path = "MJCF") -> mujoco.MjModel:
    """``spec.compile()``, its errors as :class:`ModelError` (named with ``source``, on one line)."""
    try:
        return spec.compile()
    except Exception as exc:  # mujoco raises ValueError with the compiler's message
        raise ModelError(f"{source}: MuJoCo cannot compile the model: {mujoco_message(exc)}") from None


def mujoco_model(robot: Robot, friction: Mapping[str, FrictionLike], armature: Mapping[str, float] | None = None,
                 inertias: pin.Model | None = None) -> mujoco.MjModel:
    """The compiled MuJoCo model of :func:`mujoco_spec` (same arguments and errors).

    Joints are addressed by name (``mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)``,
    ``model.jnt_dofadr``): MuJoCo orders them by its own tree traversal.

    Examples:
        >>> mj = mujoco_model(robot, read_params("params.json"), {"lwr_0_joint": 0.01})  # doctest: +SKIP
        >>> mj0 = mujoco_model(robot, {})  # the same robot without friction (nor given armature)  # doctest: +SKIP
    """
    return compile_spec(mujoco_spec(robot, friction, armature, inertias), robot.urdf)


def write_mjcf(robot: Robot, friction: Mapping[str, FrictionLike], path: str | Path,
               armature: Mapping[str, float] | None = None, inertias: pin.Model | None = None) -> mujoco.MjModel:
    """Write the MJCF of :func:`mujoco_spec` at full precision, its joints in :attr:`Robot.actuated`
    order, each joint with friction from a fit after a comment of its status (:func:`mjcf_xml`), atomically.

    Returns:
        the compiled model the file holds.

    Raises:
        what :func:`mujoco_spec` raises; InputError: an output folder that does not exist.
    """
    return write_model(path, robot, joint_exports(friction, armature, robot), inertias)[0]


def write_model(path: str | Path, robot: Robot, joints: Mapping[str, JointExport],
                inertias: pin.Model | None = None) -> tuple[mujoco.MjModel, tuple[str, ...]]:
    """:func:`write_mjcf` of the joints' simulator parameters (joint -> :class:`JointExport`,
    :func:`~wbfriction.export.mapping.joint_exports`): same errors.

    Returns:
        the compiled model the file holds, and the URDF's collision elements left out (one
        ``"<link>: <file> (<why>)"`` each: :func:`~wbfriction.model.mjspec.keep_collision_geometry`).
    """
    import mujoco
    built = _spec(robot, joints, inertias)
    spec = built.spec
    model = compile_spec(spec, robot.urdf)
    notes = {name: note for name, exp in joints.items() if (note := status_note(exp)) is not None}
    notes.update(built.notes)
    drive = drive_export(robot, joints)
    note = None if drive is None else drive_note(drive, model)
    text = mjcf_xml(spec, model, robot.actuated, notes, () if drive is None else drive.joints, note)
    write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    if [model.joint(j).name for j in range(model.njnt) if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE] \
            != list(robot.actuated):  # bodies reordered in the file: its model, in its order
        model = compile_spec(mujoco.MjSpec.from_file(str(path)), path)
    return model, built.skipped


class MjcfTarget(ExportTarget, kind=MJCF):
    """``.xml``, ``.mjcf``: a MuJoCo model of the robot with the friction and armature, and position actuators for
    PD-driven joints (module docstring)."""


    def write(self, path: Path, robot: Robot, joints: Mapping[str, JointExport]) -> ExportReport:
        """:func:`write_model` (the URDF's inertias); a warning names the collision meshes left out."""
        _, skipped = write_model(path, robot, joints)
        held_back = held_back_warning(robot)
        warnings: tuple[str, ...] = () if held_back is None else (held_back,)
        if skipped:  # one line within 100 columns with "warning: " before it (a long file name aside)
            links = sorted({line.split(":", 1)[0] for line in skipped})
            named = links[0] + (f" and {len(links) - 1} more" if len(links) > 1 else "")
            warnings += (f"{path.name}: left out {len(skipped)} collision mesh(es) MuJoCo cannot load: {named}",)
        return self.report(path, joints, warnings)
