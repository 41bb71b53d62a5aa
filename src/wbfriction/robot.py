"""Robot model: a URDF with a free-flyer root, its joint groups and contact frames.

The model is Pinocchio's (``pin.buildModelFromUrdf`` with ``pin.JointModelFreeFlyer``):
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

import importlib.metadata
import os
import sys
import tomllib
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property
from importlib import resources
from pathlib import Path

import numpy as np
import pinocchio as pin

from .config import read_toml
from .exceptions import InputError

BUILTIN_ROBOTS = ("talos", "toro")
_ERD_PREFIX = "example-robot-data:"
_GENERATED = "wbfriction:"  # a URDF this package generates: "wbfriction:<name>" (robots/<name>.py)


def example_robot_data_dir() -> Path:
    """Directory of the robots shipped by the installed ``example-robot-data`` package.

    Raises:
        InputError: if the package is not installed.
    """
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError as exc:  # pragma: no cover - install issue
        raise InputError("example-robot-data is not installed: pip install example-robot-data") from exc
    path = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
    if not path.is_dir():  # pragma: no cover - install issue
        raise InputError(f"example-robot-data robots not found at {path}")
    return path


@contextmanager
def _quiet_stderr():
    """Silence what C++ code (urdfdom) writes to file descriptor 2 meanwhile."""
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    try:
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


def _resolve(spec: str, base_dir: Path) -> Path:
    if spec.startswith(_ERD_PREFIX):
        return example_robot_data_dir() / spec[len(_ERD_PREFIX):]
    if spec.startswith(_GENERATED):
        from .robots.toro import toro_urdf_path
        generators = {"toro": toro_urdf_path}
        name = spec[len(_GENERATED):]
        if name not in generators:
            raise InputError(f"no generated URDF '{spec}': known are "
                             + ", ".join(_GENERATED + n for n in generators))
        return generators[name]()
    path = Path(spec).expanduser()
    return path if path.is_absolute() else (base_dir / path)


@dataclass(frozen=True)
class Robot:
    """A floating-base robot model with its joint groups and contact frames.

    Attributes:
        name: robot name.
        model: Pinocchio model with a free-flyer root joint named ``root_joint``.
        urdf: path of the URDF the model was built from.
        actuated: names of all actuated (single-DoF) joints, in model order.
        torque_controlled: names of the torque-controlled joints, in model order.
        position_controlled: names of the position-controlled joints, in model order.
        contact_frames: names of the 6D contact frames (feet soles), as configured.
        groups: named joint groups (e.g. ``knee``), used to set friction per group.
        q_reference: a standing configuration (nq,), e.g. TALOS's ``half_sitting``.
        balance_gains: (K [N·m/rad], D [N·m·s/rad]) of the MuJoCo walking controller's
            base-attitude stabiliser (:func:`wbfriction.sim.control.attitude_ankle_torques`);
            a property of the simulated robot, not used by the estimator.
    """

    name: str
    model: pin.Model
    urdf: Path
    actuated: tuple[str, ...]
    torque_controlled: tuple[str, ...]
    position_controlled: tuple[str, ...]
    contact_frames: tuple[str, ...]
    groups: dict[str, tuple[str, ...]] = field(default_factory=dict)
    q_reference: np.ndarray | None = None
    balance_gains: tuple[float, float] = (0.0, 0.0)
    cache: dict = field(default_factory=dict, repr=False, compare=False)
    """Derived models built on demand (e.g. the stance models of :mod:`wbfriction.stance`)."""

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
        from .exceptions import ModelError

        if len(self.layout.q2_joint):
            raise ModelError(f"robot '{self.name}': continuous joints are not supported here")
        return np.array([self.model.idx_qs[self.model.getJointId(n)] for n in self.actuated], dtype=int)

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
    def layout(self) -> "JointLayout":
        """Configuration layout of :attr:`actuated` in :attr:`model`."""
        return _joint_layout(self.model, self.actuated)

    @cached_property
    def reference_angles(self) -> np.ndarray:
        """Joint positions of :attr:`q_reference` (zeros if there is none), (n_act,)."""
        return np.zeros(self.n_act) if self.q_reference is None else self.angles(self.q_reference)

    @cached_property
    def angle_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper joint position limits (n_act,) [rad]; +-inf for continuous joints."""
        lo, hi = np.full(self.n_act, -np.inf), np.full(self.n_act, np.inf)
        lay = self.layout
        lo[lay.q1_joint] = self.model.lowerPositionLimit[lay.q1_index]
        hi[lay.q1_joint] = self.model.upperPositionLimit[lay.q1_index]
        return lo, hi


@dataclass(frozen=True)
class JointLayout:
    """How joint angles map to a Pinocchio configuration vector of a given model.

    Single-coordinate joints (revolute, prismatic) take the angle itself; continuous
    joints (unbounded revolute, nq = 2) take (cos, sin). ``sign`` flips a joint's
    direction (used for the re-rooted models of :mod:`wbfriction.stance`).
    """

    nq: int
    q1_index: np.ndarray  # configuration index of each single-coordinate joint
    q1_joint: np.ndarray  # its position in the angle vector
    q2_index: np.ndarray  # configuration index (cos) of each continuous joint
    q2_joint: np.ndarray
    root_nq: int

    def configuration(self, angles: np.ndarray, base: np.ndarray | None = None,
                      sign: np.ndarray | None = None) -> np.ndarray:
        a = np.asarray(angles, dtype=float)
        single = a.ndim == 1
        a = np.atleast_2d(a)
        if sign is not None:
            a = a * sign
        q = np.zeros((a.shape[0], self.nq))
        if self.root_nq == 7:
            q[:, 6] = 1.0
            if base is not None:
                q[:, :7] = np.atleast_2d(base)
        q[:, self.q1_index] = a[:, self.q1_joint]
        q[:, self.q2_index] = np.cos(a[:, self.q2_joint])
        q[:, self.q2_index + 1] = np.sin(a[:, self.q2_joint])
        return q[0] if single else q

    def angles(self, q: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`configuration` (without sign): joint positions from configurations."""
        q = np.asarray(q, dtype=float)
        single = q.ndim == 1
        q = np.atleast_2d(q)
        n_joints = len(self.q1_joint) + len(self.q2_joint)
        a = np.empty((q.shape[0], n_joints))
        a[:, self.q1_joint] = q[:, self.q1_index]
        a[:, self.q2_joint] = np.arctan2(q[:, self.q2_index + 1], q[:, self.q2_index])
        return a[0] if single else a


def _joint_layout(model: pin.Model, joints: tuple[str, ...]) -> JointLayout:
    q1_index, q1_joint, q2_index, q2_joint = [], [], [], []
    for k, name in enumerate(joints):
        jid = model.getJointId(name)
        if model.nqs[jid] == 1:
            q1_index.append(model.idx_qs[jid])
            q1_joint.append(k)
        else:
            q2_index.append(model.idx_qs[jid])
            q2_joint.append(k)
    root_nq = model.nqs[1] if model.njoints > 1 else 0
    as_int = lambda x: np.array(x, dtype=int)  # noqa: E731
    return JointLayout(model.nq, as_int(q1_index), as_int(q1_joint), as_int(q2_index), as_int(q2_joint), root_nq)


# --------------------------------------------------------------------- loading
def _check_names(names, known, what: str, source: str) -> None:
    for n in names:
        if n not in known:
            raise InputError(f"{source}: unknown {what} '{n}' (not in the model)")


def build_robot(urdf: Path, config: dict, source: str = "config") -> Robot:
    """Build a :class:`Robot` from a URDF and a configuration mapping.

    Args:
        urdf: URDF file. A free-flyer root joint is added (a URDF-declared floating
            joint is ignored by Pinocchio's parser, so the result is the same).
        config: keys ``name``, ``contact_frames`` (required), ``position_controlled``,
            ``torque_controlled``, ``groups``, ``srdf``/``reference_configuration`` (an SRDF
            posture), ``reference_angles`` (joint name -> angle [rad], set over it),
            ``balance_gains`` (:attr:`Robot.balance_gains`).
        source: file name used in error messages.

    Raises:
        InputError: URDF that does not load, unknown joint or frame names, a joint
            listed both as torque- and position-controlled, a multi-DoF actuated joint.
    """
    urdf = Path(urdf)
    if not urdf.is_file():
        raise InputError(f"{urdf}: URDF file not found")
    try:
        with _quiet_stderr():
            model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    except Exception as exc:  # Pinocchio raises plain RuntimeError/ValueError
        raise InputError(f"{urdf}: URDF does not load: {str(exc).strip().splitlines()[0]}") from exc
    actuated = []
    for jid in range(2, model.njoints):
        if model.nvs[jid] != 1:
            raise InputError(f"{urdf}: joint '{model.names[jid]}' has {model.nvs[jid]} DoF; only 1-DoF joints are supported")
        actuated.append(model.names[jid])
    known = set(actuated)
    pc = list(config.get("position_controlled", []))
    _check_names(pc, known, "position-controlled joint", source)
    tc_cfg = config.get("torque_controlled")
    if tc_cfg is None:
        tc_cfg = [n for n in actuated if n not in pc]
    _check_names(tc_cfg, known, "torque-controlled joint", source)
    both = set(pc) & set(tc_cfg)
    if both:
        raise InputError(f"{source}: joint '{sorted(both)[0]}' is both torque- and position-controlled")
    frames = list(config.get("contact_frames", []))
    if not frames:
        raise InputError(f"{source}: 'contact_frames' is missing or empty")
    for f in frames:
        if not model.existFrame(f):
            raise InputError(f"{source}: unknown contact frame '{f}' (not a frame of {urdf.name})")
    groups = {}
    for gname, joints in dict(config.get("groups", {})).items():
        _check_names(joints, known, f"joint in group '{gname}'", source)
        groups[gname] = tuple(joints)
    in_model_order = lambda names: tuple(n for n in actuated if n in set(names))  # noqa: E731
    q_ref = None
    srdf = config.get("srdf")
    if srdf:
        srdf_path = _resolve(srdf, Path(config.get("_dir", ".")))
        pin.loadReferenceConfigurations(model, str(srdf_path), False)
        ref = config.get("reference_configuration")
        if ref is not None and ref in model.referenceConfigurations:
            q_ref = np.array(model.referenceConfigurations[ref], dtype=float)
    angles = dict(config.get("reference_angles", {}))
    if angles:
        _check_names(list(angles), known, "joint in reference_angles", source)
        q_ref = pin.neutral(model) if q_ref is None else q_ref
        for name, angle in angles.items():
            q_ref[model.idx_qs[model.getJointId(name)]] = float(angle)
    return Robot(
        name=str(config.get("name", urdf.stem)),
        model=model,
        urdf=urdf,
        actuated=tuple(actuated),
        torque_controlled=in_model_order(tc_cfg),
        position_controlled=in_model_order(pc),
        contact_frames=tuple(frames),
        groups=groups,
        q_reference=q_ref,
        balance_gains=_balance_gains(config.get("balance_gains", (0.0, 0.0)), source),
    )


def _balance_gains(value, source: str) -> tuple[float, float]:
    try:
        K, D = (float(x) for x in value)
    except (TypeError, ValueError):
        raise InputError(f"{source}: 'balance_gains' must be two numbers [K, D], got {value!r}") from None
    if K < 0 or D < 0:
        raise InputError(f"{source}: 'balance_gains' must be >= 0, got {value!r}")
    return K, D


def load_robot(name: str | None = "talos", *, urdf: str | Path | None = None,
               config: str | Path | None = None) -> Robot:
    """Load a built-in robot by name, or any robot from ``urdf`` and a ``config`` TOML.

    Examples:
        >>> robot = load_robot("talos")                                  # doctest: +SKIP
        >>> robot = load_robot(urdf="my.urdf", config="my_robot.toml")   # doctest: +SKIP
        >>> robot = load_robot("talos", urdf="talos_identified.urdf")    # doctest: +SKIP

    ``urdf`` without ``config`` gives the built-in robot ``name``'s configuration (contact
    frames, joint roles, groups) on another URDF of the same robot.

    Raises:
        InputError: unknown built-in name, missing files, or a bad configuration.
    """
    if config is not None:
        if urdf is None:
            raise InputError("--config needs the robot's --urdf")
        cfg_path = Path(config)
        cfg = read_toml(cfg_path)
        cfg["_dir"] = str(cfg_path.parent)
        return build_robot(Path(urdf), cfg, source=str(cfg_path))
    if name not in BUILTIN_ROBOTS:
        raise InputError(f"unknown robot '{name}': built-in robots are {', '.join(BUILTIN_ROBOTS)}; "
                         "otherwise give --urdf and --config")
    text = resources.files("wbfriction.robots").joinpath(f"{name}.toml").read_text()
    cfg = tomllib.loads(text)  # the package's own file
    if urdf is not None:  # the built-in robot's configuration on another URDF of it (identified inertias)
        return build_robot(Path(urdf), cfg, source=f"built-in robot '{name}' on {urdf}")
    return build_robot(_resolve(cfg["urdf"], Path(".")), cfg, source=f"built-in robot '{name}'")
