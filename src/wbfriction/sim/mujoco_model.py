"""A MuJoCo model of a robot, built at run time from the URDF of its Pinocchio model.

The realistic simulator (thesis 6.2) must not share code with the estimator, so it runs on
MuJoCo (PyPI ``mujoco``). The model comes from the same URDF: visual and collision
meshes are dropped, the URDF's ``<dynamics>`` (damping, friction) too (friction is injected
explicitly), a free joint is added at the root, a floor plane, one motor per actuated
joint (torque = ``ctrl``, clipped at the URDF's effort limit), and one box per contact
frame: the footprint of the foot's collision mesh (from the installed robot package;
:func:`~wbfriction.model.footprint.sole_footprint`),
flat under the contact frame, with sliding and torsional friction, and a touch sensor
(the sum of the normal forces of the contacts within the sole) on it. Joints are mapped
by name; configurations and velocities convert both ways (:class:`MujocoRobot`).

Conventions that differ (field notes): MuJoCo orders joints by its own tree traversal,
writes quaternions (w, x, y, z) where Pinocchio writes (x, y, z, w), and gives the free
joint's linear velocity in the world frame where Pinocchio gives it in the base frame.
"""

from __future__ import annotations

import logging
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import ModelError
from wbfriction.model.footprint import sole_footprint
from wbfriction.model.mjspec import urdf_spec
from wbfriction.model.robot import Robot

if TYPE_CHECKING:
    import mujoco

SOLE_THICKNESS = 0.01  # [m], the contact boxes' height, their bottom face on the contact frame's plane
TOUCH_MARGIN = 0.005  # [m], how far beyond the sole's edges its touch sensor reaches
SOLE_FRICTION = (1.0, 0.02, 0.0)
"""Sliding and torsional [m] friction of the soles (``condim`` 4). Without the torsional
part a stance foot spins about the vertical (measured: the hip yaw lost track and TALOS
fell within 3 s). Rolling friction (``condim`` 6) made the landing of a loaded foot blow up
(NaN accelerations at the ankle within 40 ms of a touch-down)."""


@dataclass
class MujocoRobot:
    """A robot's MuJoCo model and the maps between its coordinates and Pinocchio's.

    Attributes:
        robot: the Pinocchio-side robot.
        model: the compiled ``mujoco.MjModel``.
        qpos_index: MuJoCo ``qpos`` address of each actuated joint, in :attr:`Robot.actuated` order.
        dof_index: MuJoCo ``qvel`` address of each actuated joint.
        sole_geoms: geom id of each contact frame's box, in :attr:`Robot.contact_frames` order.
        touch_index: ``sensordata`` address of each sole's touch sensor (normal force [N]).
        ft_index: ``sensordata`` addresses (n_sensors, 6) of each force-torque sensor's force and torque,
            in :attr:`Robot.ft_sensors <wbfriction.model.robot.Robot.ft_sensors>` order (the sign of
            MuJoCo's turned into :mod:`wbfriction.model.force_torque`'s by :meth:`wrenches`).
        imu_index: ``sensordata`` addresses (6,) of the IMU's gyro and accelerometer, or empty.
        joint_ids: MuJoCo joint id of each actuated joint.
        base_body: body id of the floating base (the free joint's body).

    Actuator ``i`` is the motor of joint ``robot.actuated[i]``: ``data.ctrl`` takes the
    joint torques [N·m] in :attr:`Robot.actuated` order.
    """

    robot: Robot
    model: mujoco.MjModel
    qpos_index: np.ndarray
    dof_index: np.ndarray
    sole_geoms: tuple[int, ...]
    touch_index: np.ndarray
    joint_ids: np.ndarray
    base_body: int
    ft_index: np.ndarray
    imu_index: np.ndarray

    def wrenches(self, sensordata: np.ndarray) -> np.ndarray:
        """The force-torque sensors' wrenches (..., n_sensors, 6) in :mod:`wbfriction.model.force_torque`'s
        convention (the plate's push on the link, sensor frame) from MuJoCo's ``sensordata`` (..., nsensordata),
        whose force and torque sensors give the link's push on the plate."""
        return -sensordata[..., self.ft_index]

    def qpos(self, q: np.ndarray) -> np.ndarray:
        """MuJoCo ``qpos`` (nq,) of a Pinocchio configuration (nq,)."""
        out = np.zeros(self.model.nq)
        out[:3] = q[:3]
        out[3:7] = q[[6, 3, 4, 5]]  # (w, x, y, z)
        out[self.qpos_index] = q[self.robot.act_q_index]
        return out

    def q(self, qpos: np.ndarray) -> np.ndarray:
        """Pinocchio configurations (..., nq) of MuJoCo ``qpos`` (..., nq_mj)."""
        qpos = np.asarray(qpos)
        out = np.zeros(qpos.shape[:-1] + (self.robot.model.nq,))
        out[..., :3] = qpos[..., :3]
        out[..., 3:7] = qpos[..., [4, 5, 6, 3]]
        out[..., self.robot.act_q_index] = qpos[..., self.qpos_index]
        return out

    def v(self, qpos: np.ndarray, qvel: np.ndarray) -> np.ndarray:
        """Pinocchio velocities (..., nv) of MuJoCo states: the inverse of :meth:`velocity_map`."""
        from scipy.spatial.transform import Rotation
        qpos, qvel = np.asarray(qpos), np.asarray(qvel)
        out = np.zeros(qvel.shape[:-1] + (self.robot.model.nv,))
        base = Rotation.from_quat(qpos.reshape(-1, qpos.shape[-1])[:, [4, 5, 6, 3]])  # scalar last
        out[..., :3] = base.inv().apply(qvel.reshape(-1, qvel.shape[-1])[:, :3]).reshape(qvel.shape[:-1] + (3,))
        out[..., 3:6] = qvel[..., 3:6]
        out[..., self.robot.act_v_index] = qvel[..., self.dof_index]
        return out

    def base_acceleration(self, qpos: np.ndarray, qvel: np.ndarray, qacc: np.ndarray) -> np.ndarray:
        """Pinocchio's free-flyer acceleration (..., 6) (the time derivative of the base-frame twist) from
        MuJoCo's free joint's ``qpos``, ``qvel`` and ``qacc`` (..., 6): world-frame ``p_ddot`` turned into
        the base frame, less ``omega x v`` (:mod:`wbfriction.signals.base_motion`)."""
        from scipy.spatial.transform import Rotation
        qpos, qvel, qacc = np.asarray(qpos), np.asarray(qvel), np.asarray(qacc)
        R_inv = Rotation.from_quat(qpos.reshape(-1, qpos.shape[-1])[:, [4, 5, 6, 3]]).inv()
        v_lin = R_inv.apply(qvel.reshape(-1, qvel.shape[-1])[:, :3])
        omega = qvel.reshape(-1, qvel.shape[-1])[:, 3:6]
        a_lin = R_inv.apply(qacc.reshape(-1, 6)[:, :3]) - np.cross(omega, v_lin)
        return np.hstack([a_lin, qacc.reshape(-1, 6)[:, 3:6]]).reshape(qacc.shape[:-1] + (6,))

    def velocity_map(self, q: np.ndarray) -> np.ndarray:
        """``T`` (nv, nv) with ``qvel = T v`` at configuration ``q`` (Pinocchio's): the base
        linear velocity turns from the base frame into the world frame."""
        nv = self.model.nv
        T = np.zeros((nv, nv))
        T[:3, :3] = pin.Quaternion(q[3:7]).normalized().matrix()
        T[3:6, 3:6] = np.eye(3)
        T[self.dof_index, self.robot.act_v_index] = 1.0
        return T


LOG = logging.getLogger("wbfriction.mujoco")
"""Where MuJoCo's warnings go (:func:`route_mujoco_warnings`)."""


def route_mujoco_warnings() -> None:
    """Send MuJoCo's warnings ("Nan, Inf or huge value in QACC ...") to the ``wbfriction.mujoco`` logger
    instead of MuJoCo's default: stdout and a ``MUJOCO_LOG.TXT`` appended in the working directory, which a
    library must not write where it is run. The simulators still stop on an unstable step (they read
    MuJoCo's warning counters: :class:`~wbfriction.exceptions.SimulationError`)."""
    import mujoco
    mujoco.set_mju_user_warning(_log_warning)


def _log_warning(message: str) -> None:
    LOG.warning("MuJoCo: %s", message)


def build_mujoco_robot(robot: Robot, timestep: float = 1e-4) -> MujocoRobot:
    """Build the MuJoCo model of ``robot`` (module docstring).

    Args:
        robot: a robot with a free-flyer root and contact frames.
        timestep: physics step [s].

    Raises:
        InputError: a robot loaded from an MJCF (:meth:`Robot.require_urdf`).
        ModelError: the URDF does not compile in MuJoCo, a joint missing, no sole mesh.
    """
    route_mujoco_warnings()
    urdf = robot.require_urdf("the MuJoCo simulator (soles from the URDF's collision geometry)")
    root = ET.parse(urdf).getroot()
    footprints = [sole_footprint(robot, f, root) for f in robot.contact_frames]
    spec = _urdf_spec(robot, timestep)
    _add_soles(spec, robot, footprints)
    _add_imu(spec, robot)
    _add_motors(spec, robot)
    try:
        mj = spec.compile()
    except Exception as exc:
        raise ModelError(f"{robot.urdf}: MuJoCo cannot compile the model: {exc}") from None
    _plates_weigh_as_their_links(mj, robot)
    return _mujoco_robot(robot, mj)


def _plates_weigh_as_their_links(mj: mujoco.MjModel, robot: Robot) -> None:
    """Give each sole plate the ``body_invweight0`` of its link. MuJoCo scales a contact's softness by
    it (the constraint regulariser ``R`` is proportional to an approximation of ``J M^-1 J^T`` built from
    the bodies' ``invweight0``): a plate, a light body of its own, would otherwise make the sole 1.8
    times softer than the same sole on the link (measured on TALOS; the combined walk then fell at
    6.9 s). The plate is welded to its link, so they are one rigid body: the same weight is right."""
    import mujoco
    for s in robot.ft_sensors:
        plate = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, f"ft_{s.name}")
        mj.body_invweight0[plate] = mj.body_invweight0[mj.body_parentid[plate]]


def _urdf_spec(robot: Robot, timestep: float) -> mujoco.MjSpec:
    """The MuJoCo spec of the robot's URDF (:func:`wbfriction.model.mjspec.urdf_spec`: kinematic tree and
    inertias only), with a free joint at the root, the physics step and a floor."""
    import mujoco
    spec = urdf_spec(robot.urdf, free_joint=True)
    spec.option.timestep = timestep
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1])
    return spec


def _add_soles(spec: mujoco.MjSpec, robot: Robot, footprints: list[tuple[np.ndarray, np.ndarray]]) -> None:
    """One box per contact frame on its footprint (centre, half sizes), with a touch sensor; on the sole
    plate below the contact's force-torque sensor, if it has one (:func:`_add_sensor_plates`)."""
    import mujoco
    model = robot.model
    plates = _add_sensor_plates(spec, robot)
    for frame, (centre, half) in zip(robot.contact_frames, footprints):
        fr = model.frames[model.getFrameId(frame)]
        body = spec.body(_body_of_joint(model, fr.parentJoint))
        if body is None:
            raise ModelError(f"MuJoCo has no body for the link carrying '{frame}'")
        placement = fr.placement  # the contact frame in the body's frame
        if frame in plates:
            body, in_body = plates[frame]
            placement = in_body.actInv(fr.placement)
        pos = placement.act(np.array([centre[0], centre[1], SOLE_THICKNESS / 2]))
        quat = pin.Quaternion(placement.rotation).coeffs()[[3, 0, 1, 2]]
        body.add_geom(name=f"sole_{frame}", type=mujoco.mjtGeom.mjGEOM_BOX,
                      size=[half[0], half[1], SOLE_THICKNESS / 2], pos=pos, quat=quat,
                      condim=4, friction=list(SOLE_FRICTION))
        # the touch sensor counts the contacts whose point lies in its site: the sole, grown
        body.add_site(name=f"touch_{frame}", type=mujoco.mjtGeom.mjGEOM_BOX, pos=pos,
                      size=[half[0] + TOUCH_MARGIN, half[1] + TOUCH_MARGIN, SOLE_THICKNESS], quat=quat)
        spec.add_sensor(name=f"touch_{frame}", type=mujoco.mjtSensor.mjSENS_TOUCH,
                        objtype=mujoco.mjtObj.mjOBJ_SITE, objname=f"touch_{frame}")


def _add_sensor_plates(spec: mujoco.MjSpec, robot: Robot) -> dict[str, tuple[mujoco.MjsBody, pin.SE3]]:
    """For each force-torque sensor (:mod:`wbfriction.model.force_torque`): its link's body keeps the part
    above the sensor, and a child body without a joint, at the sensor frame, the sole plate below it, with
    a site and MuJoCo ``force`` and ``torque`` sensors on it (``ft_<name>``): they measure the interaction
    between the plate and the link. Returns the plate body and its placement in the link's body, per
    contact frame."""
    import mujoco
    model = robot.model
    plates = {}
    for s in robot.ft_sensors:
        body = spec.body(_body_of_joint(model, s.joint))
        if body is None:
            raise ModelError(f"MuJoCo has no body for the link of force-torque sensor '{s.name}'")
        # the body's own inertia, less the plate's (the URDF's fixed links below it are fused in later,
        # by MuJoCo: Pinocchio's joint inertia, which holds them already, would count them twice)
        above = pin.Inertia.FromDynamicParameters(_spec_inertia(body).toDynamicParameters()
                                                  - s.below_in_joint.toDynamicParameters())
        _set_inertia(body, above)
        plate = body.add_body(name=f"ft_{s.name}", pos=s.placement.translation,
                              quat=pin.Quaternion(s.placement.rotation).coeffs()[[3, 0, 1, 2]])
        _set_inertia(plate, s.below)
        plate.add_site(name=f"ft_{s.name}")
        for kind in (mujoco.mjtSensor.mjSENS_FORCE, mujoco.mjtSensor.mjSENS_TORQUE):
            spec.add_sensor(name=f"ft_{s.name}_{'force' if kind == mujoco.mjtSensor.mjSENS_FORCE else 'torque'}",
                            type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname=f"ft_{s.name}")
        plates[s.contact] = (plate, s.placement)
    return plates


def _add_imu(spec: mujoco.MjSpec, robot: Robot) -> None:
    """The robot's IMU (:mod:`wbfriction.model.imu`), if any: a site at its frame with MuJoCo's ``gyro`` and
    ``accelerometer`` sensors (``imu_gyro``, ``imu_acc``: angular velocity and specific force, site frame)."""
    import mujoco
    if robot.imu is None:
        return
    model = robot.model
    frame = model.frames[robot.imu.frame]
    body = spec.body(_body_of_joint(model, frame.parentJoint))
    if body is None:
        raise ModelError("MuJoCo has no body for the link carrying the IMU")
    body.add_site(name="imu", pos=frame.placement.translation,
                  quat=pin.Quaternion(frame.placement.rotation).coeffs()[[3, 0, 1, 2]])
    for name, kind in (("imu_gyro", mujoco.mjtSensor.mjSENS_GYRO), ("imu_acc", mujoco.mjtSensor.mjSENS_ACCELEROMETER)):
        spec.add_sensor(name=name, type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname="imu")


def _spec_inertia(body: mujoco.MjsBody) -> pin.Inertia:
    """The explicit inertia of a MuJoCo spec body (from its URDF ``<inertial>``) as Pinocchio's, in its frame."""
    if np.isfinite(body.fullinertia[0]):
        xx, yy, zz, xy, xz, yz = body.fullinertia
        inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    else:
        R = pin.Quaternion(*body.iquat).toRotationMatrix()  # (w, x, y, z)
        inertia = R @ np.diag(body.inertia) @ R.T
    return pin.Inertia(float(body.mass), np.array(body.ipos), inertia)


def _set_inertia(body: mujoco.MjsBody, inertia: pin.Inertia) -> None:
    """Give a MuJoCo body Pinocchio's spatial ``inertia`` (in the body's frame): mass, centre of mass, and
    the principal moments about it with their axes."""
    moments, axes = np.linalg.eigh(inertia.inertia)
    if np.linalg.det(axes) < 0:
        axes[:, 0] *= -1
    body.explicitinertial = True
    body.mass = max(inertia.mass, 1e-9)
    body.ipos = inertia.lever
    body.iquat = pin.Quaternion(axes).coeffs()[[3, 0, 1, 2]]
    body.inertia = np.maximum(moments, 1e-12)
    body.fullinertia = [np.nan, 0, 0, 0, 0, 0]  # unset: the principal moments above hold


def _add_motors(spec: mujoco.MjSpec, robot: Robot) -> None:
    """One motor per actuated joint, its torque clipped at the URDF's effort limit (if any)."""
    import mujoco
    model = robot.model
    for name in robot.actuated:
        jid = model.getJointId(name)
        effort = float(model.effortLimit[model.joints[jid].idx_v])
        motor = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        motor.set_to_motor()
        if np.isfinite(effort) and effort > 0:
            motor.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            motor.forcerange = [-effort, effort]


def _mujoco_robot(robot: Robot, mj: mujoco.MjModel) -> MujocoRobot:
    """The :class:`MujocoRobot` of a compiled model: the addresses of the joints, soles and sensors."""
    import mujoco
    qpos_index, dof_index, joint_ids = [], [], []
    for name in robot.actuated:
        jid = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid < 0:
            raise ModelError(f"MuJoCo model has no joint '{name}'")
        qpos_index.append(mj.jnt_qposadr[jid])
        dof_index.append(mj.jnt_dofadr[jid])
        joint_ids.append(jid)
    soles = tuple(mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, f"sole_{f}") for f in robot.contact_frames)
    touch = np.array([mj.sensor_adr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SENSOR, f"touch_{f}")]
                      for f in robot.contact_frames])
    base = int(mj.jnt_bodyid[np.flatnonzero(mj.jnt_type == mujoco.mjtJoint.mjJNT_FREE)[0]])
    ft = np.array([np.r_[[mj.sensor_adr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SENSOR, f"ft_{s.name}_{kind}")] + i
                          for kind in ("force", "torque") for i in range(3)]] for s in robot.ft_sensors],
                  dtype=int).reshape(len(robot.ft_sensors), 6)
    imu = (np.r_[[mj.sensor_adr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SENSOR, name)] + i
                  for name in ("imu_gyro", "imu_acc") for i in range(3)]].astype(int)
           if robot.imu is not None else np.zeros(0, dtype=int))
    return MujocoRobot(robot, mj, np.array(qpos_index), np.array(dof_index), soles, touch, np.array(joint_ids), base,
                       ft, imu)


def _body_of_joint(model: pin.Model, joint: int) -> str:
    """URDF link name of the body a Pinocchio joint moves (the joint's child link)."""
    for f in model.frames:
        if f.type == pin.FrameType.BODY and f.parentJoint == joint and f.placement.isIdentity():
            return f.name
    raise ModelError(f"no body frame for joint '{model.names[joint]}'")



