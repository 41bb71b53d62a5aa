"""Robot model: a URDF (or an MJCF) with a free-flyer root, its joint groups and contact frames.

A fixed-base robot (an arm) has the same free-flyer root, welded to the world at the
identity through one permanent contact at its root link (:attr:`Robot.floating_base`).

The model is Pinocchio's (``pin.buildModelFromUrdf`` with ``pin.JointModelFreeFlyer``, or
``pin.buildModelFromMJCFAndRootJoint``: :func:`wbfriction.model.loading.build_model`):
configuration ``q`` (size ``nq``: base position [m], base orientation as a unit
quaternion (x, y, z, w), then the joint coordinates) and velocity ``v`` (size ``nv``:
base twist in the base frame [m/s, rad/s], then joint velocities [rad/s]).

Joints are split as in the thesis (eq. 5.3) into

* torque-controlled joints (``tc``): their torque ``tau`` is logged and their friction
  ``tau_f`` is estimated;
* position-controlled joints (``pc``, TORO's neck, TALOS's head): their acceleration is
  constrained to the measured one (eq. 5.4c), their torque is an unknown multiplier.

Joints are always addressed by name, never by order: a log's columns, a TOML file's
groups and the model are matched name by name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, ModelError
from wbfriction.model.contacts import ContactKind, ContactModel, contact_model_of
from wbfriction.model.force_torque import ForceTorqueSensor
from wbfriction.model.imu import Imu
from wbfriction.model.labels import default_label
from wbfriction.model.layout import JointLayout, joint_layout
from wbfriction.model.pd import PdDriver

ModelFormat = Literal["urdf", "mjcf"]
"""The robot description formats a model is built from (:func:`wbfriction.model.loading.build_model`)."""


@dataclass(frozen=True)
class Robot:
    """A floating-base robot model with its joint groups and contact frames.

    Attributes:
        name: robot name.
        model: Pinocchio model with a free-flyer root joint named ``root_joint``.
        urdf: path of the robot description the model was built from: a URDF, or an MJCF where
            :attr:`model_format` is ``"mjcf"`` (what needs a URDF asks :meth:`require_urdf`).
        actuated: names of all actuated (single-DoF) joints, in model order.
        torque_controlled: names of the torque-controlled joints, in model order.
        position_controlled: names of the position-controlled joints, in model order.
        contact_frames: names of the contact frames (feet soles, point feet), as configured.
        contact_kinds: the name of each contact frame's registered contact model (``contact_model`` in the TOML,
            :mod:`wbfriction.model.contacts`): ``"sole"`` (six constraints: the frame does not move, a contact
            wrench), ``"point"`` (three: the frame's origin does not move, a contact force; a quadruped's foot) built
            in; empty: every frame a sole.
        foot_radius: the radius of a point foot's sphere [m] (``foot_radius`` in the TOML): its contact point, where
            the ground's force acts, is that far below the contact frame's origin (the sphere's centre), along the
            world's vertical (flat ground); 0: at the origin.
        groups: named joint groups (e.g. ``knee``), used to set friction per group.
        q_reference: a standing configuration (nq,), e.g. TALOS's ``half_sitting``.
        balance_gains: (K [N·m/rad], D [N·m·s/rad]) of the MuJoCo walking controller's
            base-attitude stabiliser (:func:`wbfriction.sim.control.attitude_ankle_torques`);
            a property of the simulated robot, not used by the estimator.
        floating_base: False for a robot whose root link is welded to the world (an arm, a
            humanoid hanging in its gantry). The model keeps its free-flyer root and
            :attr:`contact_frames` is the root link's frame, always in contact: a fixed base
            is a permanent single support with the weld at the root (thesis 5.13 with the base
            welded: ``tau_f = M qdd + h - tau``, every sample unique). Logs need no
            ``contact.*`` columns.
        locked_joints: joints removed from the model at a fixed position [rad or m]
            (Pinocchio's reduced model): not in :attr:`actuated`, not needed in a log.
        torque_constants: joint -> torque constant [N·m/A] at the joint (gear ratio
            included), for logs that record motor currents ``current.<joint>`` [A].
        torque_scale_sd: joint -> how well the scale of its logged torque is known, one relative standard deviation
            (0.02: 2 %; a torque constant's, a torque sensor's calibration), carried into the friction's standard
            errors (:mod:`wbfriction.fit.torque_scale`); a joint not in it: not stated, none carried.
        ft_sensors: six-axis force-torque sensors, one per contact at most
            (:mod:`wbfriction.model.force_torque`; ``[force_torque.<name>]`` in the TOML).
        imu: the inertial measurement unit (:mod:`wbfriction.model.imu`; ``[imu]`` in the TOML), or None.
        labels: joint -> the label a person reads ("right knee"; ``[labels]`` in the TOML,
            :mod:`wbfriction.model.labels`); :meth:`label` falls back to the joint's name.
        model_format: ``"urdf"`` or ``"mjcf"``: the format of :attr:`urdf`.
        contact_force: ``(on, off)`` [N]: the normal forces above which a sensed sole comes into
            contact and below which it leaves it, for logs without ``contact.*`` columns
            (:mod:`wbfriction.logs.contacts`); None: shares of the robot's weight.
        pd: the motor drivers of the PD-driven joints (``[pd]`` in the TOML, :mod:`wbfriction.model.pd`): logs
            with ``q_des.<joint>`` columns take their torque from the PD law; None: no PD-driven joint.
        encoder_offset: joint -> the logged angle minus the model's angle [rad] (``[encoder_offset]`` in the
            TOML): the dynamics are evaluated at the logged angle minus it.
        angle_bounds: joint -> (lower, upper) position limits [rad], the model's angle (``[angle_limits]`` in the
            TOML): where the URDF gives none (a continuous joint that has stops) or other ones; they replace the
            URDF's in :attr:`angle_limits`.
    """

    name: str
    model: pin.Model
    urdf: Path
    actuated: tuple[str, ...]
    torque_controlled: tuple[str, ...]
    position_controlled: tuple[str, ...]
    contact_frames: tuple[str, ...]
    groups: dict[str, tuple[str, ...]] = field(default_factory=dict)
    model_format: ModelFormat = "urdf"
    q_reference: np.ndarray | None = None
    balance_gains: tuple[float, float] = (0.0, 0.0)
    floating_base: bool = True
    locked_joints: dict[str, float] = field(default_factory=dict)
    torque_constants: dict[str, float] = field(default_factory=dict)
    torque_scale_sd: dict[str, float] = field(default_factory=dict)
    ft_sensors: tuple[ForceTorqueSensor, ...] = ()
    contact_force: tuple[float, float] | None = None
    imu: Imu | None = None
    labels: dict[str, str] = field(default_factory=dict)
    pd: PdDriver | None = None
    encoder_offset: dict[str, float] = field(default_factory=dict)
    contact_kinds: tuple[ContactKind, ...] = ()
    foot_radius: float = 0.0
    angle_bounds: dict[str, tuple[float, float]] = field(default_factory=dict)
    cache: dict[Any, Any] = field(default_factory=dict, repr=False, compare=False)
    """Derived models built on demand (e.g. the stance models of :mod:`wbfriction.model.rerooted`)."""

    def require_urdf(self, purpose: str) -> Path:
        """The robot's URDF, for ``purpose`` (rewriting it, a simulator built from its geometry).

        Raises:
            InputError: a robot loaded from an MJCF.
        """
        if self.model_format != "urdf":
            raise InputError(f"{self.urdf}: {purpose} needs the robot's URDF (give --urdf): this robot was loaded "
                             "from an MJCF")
        return self.urdf

    # ----------------------------------------------------------------- indices
    @cached_property
    def n_act(self) -> int:
        """Number of actuated joints."""
        return len(self.actuated)

    @cached_property
    def tc_index(self) -> np.ndarray:
        """Positions of the torque-controlled joints within :attr:`actuated` (n_tc,)."""
        pos = {name: i for i, name in enumerate(self.actuated)}
        return np.array([pos[n] for n in self.torque_controlled], dtype=int)

    @cached_property
    def pc_index(self) -> np.ndarray:
        """Positions of the position-controlled joints within :attr:`actuated` (n_pc,)."""
        pos = {name: i for i, name in enumerate(self.actuated)}
        return np.array([pos[n] for n in self.position_controlled], dtype=int)

    @cached_property
    def act_v_index(self) -> np.ndarray:
        """Velocity indices (into ``v``) of the actuated joints (n_act,)."""
        return np.array([self.model.idx_vs[self.model.getJointId(n)] for n in self.actuated], dtype=int)

    @cached_property
    def act_q_index(self) -> np.ndarray:
        """Configuration indices (into ``q``) of the actuated joints (n_act,), for robots whose
        actuated joints all have one coordinate (revolute or prismatic).

        Raises:
            ModelError: an actuated joint with more coordinates (a continuous joint).
        """
        if len(self.layout.q2_joint):
            raise ModelError(f"robot '{self.name}': continuous joints are not supported here")
        return np.array([self.model.idx_qs[self.model.getJointId(n)] for n in self.actuated], dtype=int)

    @cached_property
    def contact_models(self) -> tuple[ContactModel, ...]:
        """The registered contact model of each contact frame (n_contacts,) (:mod:`wbfriction.model.contacts`; every
        frame a sole where :attr:`contact_kinds` is empty).

        Raises:
            InputError: a kind no model is registered under (unregistered since the robot was loaded).
        """
        kinds = self.contact_kinds or ("sole",) * len(self.contact_frames)
        return tuple(contact_model_of(k) for k in kinds)

    @cached_property
    def contact_dims(self) -> tuple[int, ...]:
        """The constraints (contact force components) of each contact frame (n_contacts,): 6 for a sole, 3 for a
        point (:attr:`ContactModel.dims <wbfriction.model.contacts.ContactModel.dims>`)."""
        return tuple(m.dims for m in self.contact_models)

    @cached_property
    def partial_contacts(self) -> bool:
        """Some contact frame's model does not fix the floating base alone (a quadruped's point feet,
        :attr:`ContactModel.fixes_base <wbfriction.model.contacts.ContactModel.fixes_base>`): there is no single
        support, friction is estimated where the contacts leave it determined, sample by sample
        (:mod:`wbfriction.model.determination`), from the base's measured motion."""
        return any(not m.fixes_base for m in self.contact_models)

    @cached_property
    def stands_on(self) -> str:
        """What the robot stands on, for messages: the :attr:`~wbfriction.model.contacts.ContactModel.plural` of its
        contact models that do not fix the base (``"point feet"``), else of its contacts (``"soles"``)."""
        models = [m for m in self.contact_models if not m.fixes_base] or list(self.contact_models)
        return " and ".join(dict.fromkeys(m.plural for m in models))

    @cached_property
    def contact_frame_ids(self) -> tuple[int, ...]:
        """Pinocchio frame ids of :attr:`contact_frames`."""
        return tuple(int(self.model.getFrameId(f)) for f in self.contact_frames)

    def limb(self, frame: str) -> tuple[str, ...]:
        """Actuated joints on the kinematic path from the root to contact frame ``frame``.

        For a sole frame this is the leg: the joints that a stance foot's contact wrench
        acts on directly, and that the thesis's "swing only" mask excludes while that
        foot is on the ground (section 6.2.1).
        """
        joint_id = self.model.frames[self.model.getFrameId(frame)].parentJoint
        path = set(self.model.supports[joint_id])
        return tuple(n for n in self.actuated if self.model.getJointId(n) in path)

    def contact_of(self, joint: str) -> int | None:
        """Index of the contact frame whose :meth:`limb` holds ``joint`` (a leg joint's
        foot), or None."""
        return next((c for c, f in enumerate(self.contact_frames) if joint in self.limb(f)), None)

    @cached_property
    def limb_mask(self) -> np.ndarray:
        """Boolean (n_contacts, n_tc): torque-controlled joint ``j`` lies on contact ``c``'s limb."""
        mask = np.zeros((len(self.contact_frames), len(self.torque_controlled)), dtype=bool)
        for c, frame in enumerate(self.contact_frames):
            limb = set(self.limb(frame))
            mask[c] = [n in limb for n in self.torque_controlled]
        return mask

    def group_of(self, joint: str) -> str | None:
        """Name of the first group that contains ``joint``, or None."""
        for group, joints in self.groups.items():
            if joint in joints:
                return group
        return None

    def label(self, joint: str) -> str:
        """The label a person reads for ``joint`` (:attr:`labels`, else its name, :func:`~.labels.default_label`)."""
        return self.labels.get(joint) or default_label(joint)

    # ----------------------------------------------------------- configuration
    def configuration(self, angles: np.ndarray, base: np.ndarray | None = None) -> np.ndarray:
        """Pinocchio configurations from joint angles.

        Args:
            angles: joint positions [rad or m] in :attr:`actuated` order, shape (n_act,) or (N, n_act).
            base: base poses (x, y, z, qx, qy, qz, qw), shape (7,) or (N, 7); identity if None.

        Returns:
            q of shape (nq,) or (N, nq). Continuous joints get (cos, sin) coordinates.
        """
        return self.layout.configuration(angles, base)

    def angles(self, q: np.ndarray) -> np.ndarray:
        """Joint positions in :attr:`actuated` order from configurations (N, nq) or (nq,)."""
        return self.layout.angles(q)

    @cached_property
    def layout(self) -> JointLayout:
        """Configuration layout of :attr:`actuated` in :attr:`model`."""
        return joint_layout(self.model, self.actuated)

    @cached_property
    def reference_angles(self) -> np.ndarray:
        """Joint positions of :attr:`q_reference` (zeros if there is none), (n_act,)."""
        return np.zeros(self.n_act) if self.q_reference is None else self.angles(self.q_reference)

    @cached_property
    def offset_vector(self) -> np.ndarray:
        """The encoders' offsets (n_act,) in :attr:`actuated` order [rad]: the logged angle minus the model's
        (:attr:`encoder_offset`, 0 where not given)."""
        return np.array([self.encoder_offset.get(n, 0.0) for n in self.actuated])

    @cached_property
    def angle_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper joint position limits (n_act,) [rad]: the URDF's, those of :attr:`angle_bounds` in their
        place; +-inf for a continuous joint without bounds."""
        lo, hi = np.full(self.n_act, -np.inf), np.full(self.n_act, np.inf)
        lay = self.layout
        lo[lay.q1_joint] = self.model.lowerPositionLimit[lay.q1_index]
        hi[lay.q1_joint] = self.model.upperPositionLimit[lay.q1_index]
        for joint, (lower, upper) in self.angle_bounds.items():
            k = self.actuated.index(joint)
            lo[k], hi[k] = lower, upper
        return lo, hi
