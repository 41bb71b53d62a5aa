"""A walking quadruped's MuJoCo model, built at run time from the URDF of its Pinocchio model (issue 56).

The robot's URDF as MuJoCo reads it (:func:`wbfriction.model.mjspec.urdf_spec`: kinematic tree and inertias; visual
and collision geometry and the URDF's ``<dynamics>`` dropped), with

* a free joint at the root (a floating base) and a ground plane (``z = 0``, flat and horizontal);
* one sphere per contact frame (:attr:`Robot.contact_frames <wbfriction.model.robot.Robot.contact_frames>`, the
  robot's point feet), of the gait's radius (:func:`wbfriction.walking.quadruped.foot_sphere`: the robot's
  ``foot_radius``, else the Go2's 2.3 cm: where the gait plans a standing foot's frame), **centred on the contact
  frame's origin** (Unitree's feet are rubber balls about 2 cm in radius round the ``<leg>_foot`` frame), the only
  geometry that collides: soft point
  contacts with MuJoCo's default ``solref``/``solimp``, ``condim`` 3 (normal and sliding friction, no torsional or
  rolling friction: the ground's action on a foot is one force at the contact point), sliding friction
  :data:`FOOT_FRICTION`;
* an IMU site at the robot's IMU frame (``[imu]``) with MuJoCo's ``gyro`` and ``accelerometer`` on it (angular
  velocity and specific force in the IMU frame: :mod:`wbfriction.model.imu`'s convention);
* one motor per joint (``ctrl`` = the joint torque [N·m], not clipped: the controller or the drivers clip), no joint
  limit (the reference stays inside the ranges);
* the constraint solver's tolerance :data:`SOLVER_TOLERANCE` (the logged forces then balance the dynamics exactly).

MuJoCo's default contacts are soft (a pyramidal friction cone, ``impratio`` 1, ``solref`` 20 ms): a loaded foot
sinks 3-7 mm and creeps on the ground at a median 1.4-1.6 cm/s while it stands (issue 82: the legs' velocity from
the true state then 7-26 % off the base's, ``docs/explanation/leg-odometry.md``). :func:`firm_contacts` makes feet
that hold, as a rubber foot on concrete: the model returned keeps the soft ones (the simulators' default; their
``contacts`` option chooses).

The ground's force acts at the contact point MuJoCo finds (half-way into the penetration, about ``r`` below the
foot frame's origin), not at the origin: a point-foot model taking the origin as fixed sees the moment ``r x f``
and the sphere's rolling (the origin moves ``r dtheta`` as the foot turns on the ground) as model error
(:mod:`wbfriction.sim.quadruped_mujoco` measures both).

Conventions that differ between MuJoCo and Pinocchio (joints by name, quaternion order, the free joint's linear
velocity in world axes) are :class:`~wbfriction.sim.mujoco_model.MujocoRobot`'s maps: the model returned is one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, ModelError
from wbfriction.model.mjspec import mujoco_message, urdf_spec
from wbfriction.model.robot import Robot
from wbfriction.sim.common import require_point_feet
from wbfriction.sim.mujoco_model import MujocoRobot, route_mujoco_warnings
from wbfriction.walking.quadruped import foot_sphere

if TYPE_CHECKING:
    import mujoco

FOOT_FRICTION = 0.9
"""The feet's sliding friction coefficient on the ground (rubber on a floor: 0.8-1.0)."""
FIRM_TIMECONST = 0.005
"""[s] The firm contacts' time constant (``solref[0]``, critically damped): a loaded foot sinks 0.7-1.6 mm (a
rubber foot's deflection on concrete) instead of 3-7 mm; ten physics steps of the simulators' 0.5 ms, over MuJoCo's
stability floor of two."""
FIRM_IMPRATIO = 10.0
"""The firm contacts' ratio of the friction's impedance to the normal's (``opt.impratio``, with elliptic cones):
the tangential force resists sliding ten times more stiffly than the normal force resists sinking (MuJoCo's
documentation: values above 1 make friction harder to break, with elliptic cones)."""
SOLVER_TOLERANCE = 1e-10
"""MuJoCo's constraint solver's tolerance (its default 1e-8 stopped once in an 8 s trot before the contact forces
met the step's acceleration: 1.4e-3 N off in the equations of motion; with 1e-10 they meet to 1e-12, no slower)."""


def build_quadruped_model(robot: Robot, timestep: float = 1e-3, foot_radius: float | None = None,
                          foot_friction: float = FOOT_FRICTION) -> MujocoRobot:
    """The MuJoCo model of a walking robot on point feet (module docstring).

    Args:
        robot: a floating-base robot whose contact frames are points (``contact_model = "point"``), from a URDF.
        timestep: the physics step [s].
        foot_radius: the feet's sphere radius [m], > 0; None: where the gait plans a standing foot's frame (the
            robot's ``foot_radius``, else the Go2's: :func:`~wbfriction.walking.quadruped.foot_sphere`).
        foot_friction: their sliding friction coefficient, > 0.

    Returns:
        A :class:`~wbfriction.sim.mujoco_model.MujocoRobot`: its ``sole_geoms`` are the feet's spheres, in
        :attr:`Robot.contact_frames` order; ``imu_index`` the gyro's and accelerometer's ``sensordata`` addresses
        (empty without an IMU); no touch or force-torque sensor.

    Raises:
        InputError: a fixed base, contact frames that are not points, a radius or friction <= 0, an MJCF robot.
        ModelError: a URDF MuJoCo cannot compile, a joint or body it does not have.
    """
    import mujoco
    if not robot.floating_base or not robot.contact_frames:
        raise InputError(f"robot '{robot.name}': a walking quadruped needs a floating base and contact frames")
    require_point_feet(robot, "the quadruped's MuJoCo model")
    foot_radius = foot_sphere(robot) if foot_radius is None else foot_radius
    if not (foot_radius > 0 and foot_friction > 0):
        raise InputError(f"foot radius ({foot_radius}) and friction ({foot_friction}) must be > 0")
    route_mujoco_warnings()
    spec = urdf_spec(robot.require_urdf("the quadruped's MuJoCo model"), free_joint=True)
    spec.option.timestep = timestep
    spec.option.tolerance = SOLVER_TOLERANCE
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 1], condim=3,
                            friction=[foot_friction, 0.0, 0.0])
    for joint in spec.joints:
        joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    model = robot.model
    for frame in robot.contact_frames:
        fr = model.frames[model.getFrameId(frame)]
        _joint_body(spec, model, fr.parentJoint).add_geom(
            name=f"foot_{frame}", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[foot_radius, 0, 0],
            pos=fr.placement.translation, condim=3, friction=[foot_friction, 0.0, 0.0])
    if robot.imu is not None:
        fr = model.frames[robot.imu.frame]
        _joint_body(spec, model, fr.parentJoint).add_site(
            name="imu", pos=fr.placement.translation, quat=pin.Quaternion(fr.placement.rotation).coeffs()[[3, 0, 1, 2]])
        for name, kind in (("imu_gyro", mujoco.mjtSensor.mjSENS_GYRO),
                           ("imu_acc", mujoco.mjtSensor.mjSENS_ACCELEROMETER)):
            spec.add_sensor(name=name, type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname="imu")
    for name in robot.actuated:
        spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT).set_to_motor()
    try:
        mj = spec.compile()
    except Exception as exc:
        raise ModelError(f"{robot.urdf}: MuJoCo cannot compile the model: {mujoco_message(exc)}") from None
    return _addresses(robot, mj)


def firm_contacts(model: mujoco.MjModel) -> None:
    """Make the feet's contacts firm, in place: elliptic friction cones (Coulomb's cone, not MuJoCo's pyramid),
    :data:`FIRM_IMPRATIO` and every geom's time constant :data:`FIRM_TIMECONST` (only the feet and the floor
    collide; MuJoCo averages the pair's), ``solimp`` MuJoCo's default.

    Measured on the go2_walking twin (3 s, 0.5 ms steps, force > 0): a stance foot's median speed on the ground
    0.07-0.10 cm/s (soft: 1.4-1.6), 0.4 % of the base's RMS speed; the mean of the stance feet's velocities from the
    true state 0.9 % (walk) / 3.3 % (trot) off the base's 10 ms away from every touch-down and lift-off (soft: 7.3 % /
    17 %); the simulation as fast. A landing foot still slides (cm/s for a sample or two: the impact), and a foot
    slips wherever its force leaves the friction cone (:data:`FOOT_FRICTION`).
    """
    import mujoco
    model.opt.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    model.opt.impratio = FIRM_IMPRATIO
    model.geom_solref[:, 0] = FIRM_TIMECONST


def _joint_body(spec: mujoco.MjSpec, model: pin.Model, joint: int) -> mujoco.MjsBody:
    """The MuJoCo spec body a Pinocchio joint moves (its child link: the frame the joint's placements are in)."""
    for f in model.frames:
        if f.type == pin.FrameType.BODY and f.parentJoint == joint and f.placement.isIdentity():
            body = spec.body(f.name)
            if body is not None:
                return body
    raise ModelError(f"MuJoCo has no body for joint '{model.names[joint]}'")


def _addresses(robot: Robot, mj: mujoco.MjModel) -> MujocoRobot:
    """The :class:`MujocoRobot` of the compiled model: the joints', feet's and IMU's addresses."""
    import mujoco

    def named(kind: mujoco.mjtObj, name: str) -> int:
        i = mujoco.mj_name2id(mj, kind, name)
        if i < 0:
            raise ModelError(f"{robot.urdf}: MuJoCo's model has no '{name}'")
        return int(i)

    joints = np.array([named(mujoco.mjtObj.mjOBJ_JOINT, j) for j in robot.actuated])
    feet = tuple(named(mujoco.mjtObj.mjOBJ_GEOM, f"foot_{f}") for f in robot.contact_frames)
    imu = (np.r_[[mj.sensor_adr[named(mujoco.mjtObj.mjOBJ_SENSOR, s)] + i for s in ("imu_gyro", "imu_acc")
                  for i in range(3)]].astype(int) if robot.imu is not None else np.zeros(0, dtype=int))
    base = int(mj.jnt_bodyid[np.flatnonzero(mj.jnt_type == mujoco.mjtJoint.mjJNT_FREE)[0]])
    return MujocoRobot(robot, mj, np.array(mj.jnt_qposadr[joints]), np.array(mj.jnt_dofadr[joints]), feet,
                       np.zeros(0, dtype=int), joints, base, np.zeros((0, 6), dtype=int), imu)
