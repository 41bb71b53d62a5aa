"""What makes the exported MJCF a model to simulate beside the robot's bodies, geometry and friction
(:mod:`wbfriction.export.mjcf`, issue 67): a motor on every torque-controlled joint (:func:`add_motors`), a floor
under a floating base (:func:`add_floor`), the keyframe :data:`STANCE` (:func:`add_stance`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from wbfriction.export.drive import DriveExport
from wbfriction.model.robot import Robot

if TYPE_CHECKING:
    import mujoco


def add_floor(spec: mujoco.MjSpec) -> None:
    """A ``floor`` plane at ``z = 0`` in the world (MuJoCo's default contact parameters), unless the world has a
    plane."""
    import mujoco
    if not any(g.type == mujoco.mjtGeom.mjGEOM_PLANE for g in spec.worldbody.geoms):
        spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1])


def add_motors(spec: mujoco.MjSpec, robot: Robot, driven: Sequence[str]) -> None:
    """A ``<motor>`` (``ctrl`` = the joint torque [N·m]) named as its joint on every actuated joint that is not
    PD-driven and has no actuator in the model file, ``ctrlrange`` the joint's ``actuatorfrcrange`` (MuJoCo's import
    of the URDF's effort limit) where it has one."""
    import mujoco
    has = {a.target for a in spec.actuators if a.trntype == mujoco.mjtTrn.mjTRN_JOINT}
    for name in robot.actuated:
        if name in driven or name in has:
            continue
        joint = spec.joint(name)
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_motor()
        frc = np.asarray(joint.actfrcrange, dtype=float)
        if joint.actfrclimited == mujoco.mjtLimited.mjLIMITED_TRUE and frc[1] > frc[0]:
            act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.ctrlrange = frc


STANCE = "stance"
"""The name of the exported MJCF's keyframe: the robot at its reference configuration, its lowest geometry on the
floor (a floating base), each PD driver's set-point there."""


def add_stance(spec: mujoco.MjSpec, robot: Robot, drive: DriveExport | None, model: mujoco.MjModel) -> None:
    """Add the keyframe :data:`STANCE` to ``spec`` (compiled as ``model``, without keyframes): ``qpos`` the robot's
    reference angles (:attr:`Robot.reference_angles`, clipped into the joints' ranges), a free joint at the origin,
    level, raised until its lowest colliding geometry touches the floor; ``ctrl`` each PD driver's set-point at those
    angles (the encoder's frame: angle + offset), 0 for a motor."""
    import mujoco
    data = mujoco.MjData(model)
    qpos = model.qpos0.copy()
    for name, value in zip(robot.actuated, robot.reference_angles):
        j = model.joint(name).id
        lo, hi = model.jnt_range[j] if model.jnt_limited[j] else (-np.inf, np.inf)
        qpos[model.jnt_qposadr[j]] = min(max(value, lo), hi)  # the Panda's zeros: joint 4's range is below 0
    free = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
    floors = [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE]
    if free and floors:
        adr = model.jnt_qposadr[free[0]]
        qpos[adr:adr + 7] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
        data.qpos[:] = qpos
        mujoco.mj_forward(model, data)
        robot_geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] != 0 and model.geom_contype[g]]
        gaps = [mujoco.mj_geomDistance(model, data, floors[0], g, 10.0, None) for g in robot_geoms]
        if gaps:
            qpos[adr + 2] = -min(gaps)
    ctrl = np.zeros(model.nu)
    if drive is not None:
        for a in range(model.nu):
            name = model.actuator(a).name
            if name in drive.joints:
                ctrl[a] = qpos[model.jnt_qposadr[model.joint(name).id]] + drive.encoder_offset.get(name, 0.0)
    spec.add_key(name=STANCE, qpos=qpos, ctrl=ctrl)
