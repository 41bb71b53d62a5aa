"""Six-axis force-torque sensors between a link and the part of it below the sensor (a foot's sole plate).

A sensor named in the robot TOML (``[force_torque.<name>]``) is fixed to a body frame of the URDF
(``link``) at a placement (``xyz`` [m], ``rpy`` [rad]); the part of that link below the sensor (the
sole plate, between the sensor and the ground: ``mass_below`` [kg], ``com_below`` [m] and
``inertia_below`` [kg·m^2] about its centre of mass, both in the sensor frame) is part of the URDF's
link. ``contact`` names the contact frame whose wrench passes through the sensor.

**Measured wrench.** ``f_s = (force [N], torque [N·m])`` is the wrench the part below the sensor exerts
on the part above it, at the sensor frame's origin, in the sensor frame's axes: a robot standing on
one foot reads ``fz`` of about ``+m g`` there (the ground's push as the sensor sees it). Newton-Euler
of the part below, whose spatial inertia is ``Y_b``, moving with the link's twist ``v`` and spatial
acceleration ``a`` (link frame, Pinocchio's ``data.v``/``data.a``), pushed by the ground's wrench
``f_c`` and pulled by gravity ``g`` (the link frame's axes):

.. math:: f_s = f_c + Y_b a_g - (Y_b a + v \\times^* Y_b v), \\qquad a_g = (R^T g, 0)

(:func:`sensor_readings`, what a simulator logs). The estimator models the robot above the sensors:
each link's inertia less its part below (:func:`above_sensors_model`), with ``f_s`` as an external
wrench on the link (:func:`external_wrenches`); then the equations of motion hold without any
contact wrench: ``M_a qdd + h_a = S^T (tau + tau_f) + sum_s J_s^T f_s``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError

WRENCH_AXES = ("fx", "fy", "fz", "tx", "ty", "tz")
"""The six components of a measured wrench, in the sensor frame: force [N], then torque [N·m]."""


@dataclass(frozen=True)
class ForceTorqueSensor:
    """A six-axis force-torque sensor of the robot (module docstring).

    Attributes:
        name: the sensor's name, that of its log columns ``wrench.<name>.fx`` ... ``.tz``.
        joint: the Pinocchio joint id its link moves with.
        placement: the sensor frame in that joint's frame (``jMs``).
        contact: the contact frame whose wrench it measures (a frame below it on the same joint).
        below: spatial inertia of the part of the link below the sensor, in the sensor frame.
    """

    name: str
    joint: int
    placement: pin.SE3
    contact: str
    below: pin.Inertia

    def columns(self) -> list[str]:
        """The sensor's log columns, ``wrench.<name>.fx`` ... ``wrench.<name>.tz``."""
        return [f"wrench.{self.name}.{axis}" for axis in WRENCH_AXES]

    @property
    def below_in_joint(self) -> pin.Inertia:
        """:attr:`below` in the joint's frame."""
        return self.placement.act(self.below)


def parse_sensors(model: pin.Model, table: object, contact_frames: list[str], source: str
                  ) -> tuple[ForceTorqueSensor, ...]:
    """The ``[force_torque.<name>]`` tables of a robot TOML as sensors of ``model``.

    Each table has ``link`` (a frame of the model), ``contact`` (one of ``contact_frames``, on the
    same joint), and optional ``xyz`` [m], ``rpy`` [rad] (default zeros), ``mass_below`` [kg],
    ``com_below`` [m], ``inertia_below`` ``[ixx, iyy, izz, ixy, ixz, iyz]`` [kg·m^2] (default zeros).

    Raises:
        InputError: naming the file and the key at fault: an unknown link or contact, a contact on
            another joint, a vector of the wrong length, a negative mass, an inertia that is not
            positive semi-definite, two sensors on one contact.
    """
    if not table:
        return ()
    if not isinstance(table, dict):
        raise InputError(f"{source}: '[force_torque]' must hold one table per sensor, [force_torque.<name>]")
    sensors: list[ForceTorqueSensor] = []
    seen: dict[str, str] = {}
    for name, spec in table.items():
        key = f"[force_torque.{name}]"
        if not isinstance(spec, dict):
            raise InputError(f"{source}: {key} must be a table (link, contact, xyz, rpy, mass_below, ...)")
        unknown = set(spec) - {"link", "contact", "xyz", "rpy", "mass_below", "com_below", "inertia_below"}
        if unknown:
            raise InputError(f"{source}: {key} has an unknown key '{sorted(unknown)[0]}'")
        link, contact = spec.get("link"), spec.get("contact")
        if not isinstance(link, str) or not model.existFrame(link):
            raise InputError(f"{source}: {key} link = {link!r} is not a frame of the model")
        if contact not in contact_frames:
            raise InputError(f"{source}: {key} contact = {contact!r} is not one of the contact frames "
                             f"{', '.join(contact_frames)}")
        joint = model.frames[model.getFrameId(link)].parentJoint
        if model.frames[model.getFrameId(contact)].parentJoint != joint:
            raise InputError(f"{source}: {key} contact '{contact}' is not on the link of '{link}': the sensor "
                             "would not carry its wrench")
        if contact in seen:
            raise InputError(f"{source}: {key} measures contact '{contact}' as [force_torque.{seen[contact]}] does")
        seen[contact] = name
        xyz, rpy = _vector(spec, "xyz", 3, key, source), _vector(spec, "rpy", 3, key, source)
        frame_in_joint = model.frames[model.getFrameId(link)].placement
        placement = frame_in_joint * pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)
        mass = float(spec.get("mass_below", 0.0))
        if not np.isfinite(mass) or mass < 0:
            raise InputError(f"{source}: {key} mass_below must be >= 0 [kg], got {spec.get('mass_below')!r}")
        ixx, iyy, izz, ixy, ixz, iyz = _vector(spec, "inertia_below", 6, key, source)
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        if np.linalg.eigvalsh(inertia).min() < -1e-12:
            raise InputError(f"{source}: {key} inertia_below is not positive semi-definite")
        below = pin.Inertia(mass, _vector(spec, "com_below", 3, key, source), inertia)
        sensors.append(ForceTorqueSensor(str(name), int(joint), placement, contact, below))
    return tuple(sensors)


def _vector(spec: dict, key: str, n: int, where: str, source: str) -> np.ndarray:
    value = spec.get(key, [0.0] * n)
    try:
        out = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        out = np.empty(0)
    if out.shape != (n,) or not np.all(np.isfinite(out)):
        raise InputError(f"{source}: {where} {key} must be {n} numbers, got {value!r}")
    return out


def above_sensors_model(model: pin.Model, sensors: tuple[ForceTorqueSensor, ...]) -> pin.Model:
    """A copy of ``model`` whose links carrying a sensor have lost their part below it: the robot
    the measured wrenches act on (module docstring). Inertias are subtracted as their ten dynamic
    parameters (linear in mass, first and second moments), exactly."""
    above = pin.Model(model)
    for s in sensors:
        params = model.inertias[s.joint].toDynamicParameters() - s.below_in_joint.toDynamicParameters()
        above.inertias[s.joint] = pin.Inertia.FromDynamicParameters(params)
    return above


def external_wrenches(model: pin.Model, sensors: tuple[ForceTorqueSensor, ...], wrench: np.ndarray) -> list:
    """The measured wrenches of one sample as Pinocchio's external forces per joint (joint frames),
    for ``pin.rnea(..., fext)``.

    Args:
        wrench: (n_sensors, 6) ``f_s`` of each sensor in its own frame [N, N·m] (module docstring).
    """
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    for s, w in zip(sensors, wrench):
        fext[s.joint] = fext[s.joint] + s.placement.act(pin.Force(w))
    return fext


def sensor_readings(model: pin.Model, sensors: tuple[ForceTorqueSensor, ...], contact_frames: tuple[str, ...],
                    q: np.ndarray, v: np.ndarray, a: np.ndarray, contact_wrench: np.ndarray) -> np.ndarray:
    """What the sensors measure, from the full motion and the contact wrenches (Newton-Euler of the
    part below each sensor, module docstring): the simulators' ground truth.

    Args:
        model: the whole robot's model (the part below each sensor included).
        q, v, a: configurations (N, nq), velocities and accelerations (N, nv).
        contact_wrench: (N, n_contacts, 6) the ground's wrench on each contact frame, in that
            frame (Pinocchio's LOCAL contact forces, ``lambda``) [N, N·m]; zero off contact.

    Returns:
        (N, n_sensors, 6) ``f_s`` in each sensor's frame [N, N·m].
    """
    data = model.createData()
    out = np.empty((len(q), len(sensors), 6))
    contact_placement = [model.frames[model.getFrameId(s.contact)].placement for s in sensors]
    contact_index = [contact_frames.index(s.contact) for s in sensors]
    below = [s.below_in_joint for s in sensors]
    gravity = model.gravity.linear
    for k in range(len(q)):
        pin.forwardKinematics(model, data, q[k], v[k], a[k])
        for i, s in enumerate(sensors):
            vj, aj, R = data.v[s.joint], data.a[s.joint], data.oMi[s.joint].rotation
            f_c = contact_placement[i].act(pin.Force(contact_wrench[k, contact_index[i]]))
            f_g = below[i] * pin.Motion(R.T @ gravity, np.zeros(3))
            f_in = below[i] * aj + vj.cross(below[i] * vj)
            out[k, i] = s.placement.actInv(f_c + f_g - f_in).vector
    return out
