"""Re-rooted models: the robot re-rooted at a contact frame (its stance foot), for single-support inverse dynamics.

In single support the stance foot is welded to the ground, so the floating-base robot
is a fixed-base tree rooted at that foot. With every joint acceleration measured, the
constrained dynamics (thesis 5.4-5.13) then reduce to one recursive Newton-Euler pass
on the re-rooted tree:

.. math::

    \\mathrm{RNEA}_F(q, \\dot q, \\ddot q_{msr}) =
    \\begin{bmatrix} \\lambda_F \\\\ S^T(\\tau + \\tau_f) \\end{bmatrix},

where the root rows are the contact wrench :math:`\\lambda_F` at the contact frame F
(expressed in F) and the joint rows the generalized joint forces. For a
position-controlled joint the row is its (unknown) torque; for a torque-controlled
joint ``tau_f = row - tau``. This is (5.13) with no matrix inverse: the unique
solution of (5.12) when ``qdd_msr`` is used for every joint and the base acceleration
is the one the contact constraint implies (tests check both routes agree to 1e-9).

The re-rooted model comes from Pinocchio's model graph (``pin.graph``). A joint on the
path from the old root to the foot is reversed; its coordinate keeps its value with a
sign (``sign = -1``), so its generalized force changes sign too (the power
``qd * tau`` is the same in both trees).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import ModelError
from wbfriction.model.layout import JointLayout, joint_layout
from wbfriction.model.momentum import tree_momentum_and_drift
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress

_G = pin.graph
_GRAPH_JOINTS = {
    **dict.fromkeys(("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"),
                    (_G.JointRevolute, slice(3, 6))),
    **dict.fromkeys(("JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned"),
                    (_G.JointRevoluteUnbounded, slice(3, 6))),
    **dict.fromkeys(("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"),
                    (_G.JointPrismatic, slice(0, 3))),
}
"""Pinocchio's 1-DoF joint models by name: the graph joint that stands for each, and where its axis lies in
the joint's motion subspace (angular part for a revolute joint, linear part for a prismatic one)."""


LOCKED_ARMATURE = 1e30
"""Armature [kg·m² or kg] that locks a joint in the articulated-body algorithm: its share ``U U^T / D`` of the
articulated inertia (``D`` = the joint's inertia + armature) is then below the last bit of any body's inertia,
and its acceleration ``u / D`` zero to machine precision (tests/model/test_rerooted.py: the crba route to 1e-12)."""


def _graph_joint(joint: pin.JointModel):
    """Graph joint equivalent to a Pinocchio 1-DoF joint model, its axis read off the joint's motion
    subspace (the bindings give no axis for an unbounded unaligned joint: a URDF continuous joint whose
    axis is not x, y or z)."""
    short = joint.shortname()
    if short not in _GRAPH_JOINTS:
        raise ModelError(f"joint type {short} is not supported by the stance models")
    kind, part = _GRAPH_JOINTS[short]
    data = joint.createData()
    joint.calc(data, np.r_[1.0, np.zeros(joint.nq - 1)])  # any q: a 1-DoF joint's subspace is constant
    return kind(np.asarray(data.S).reshape(6)[part].copy())


def body_frame(j: int) -> str:
    """Name of the frame that marks body ``j`` of the original model in a stance-rooted model."""
    return f"__wbf_body_{j}"


@dataclass
class StanceModel:
    """The robot rooted at one contact frame, with a free-flyer root.

    Attributes:
        frame: name of the contact frame the tree is rooted at.
        model: the re-rooted Pinocchio model; its root configuration is the world
            pose of the contact frame and its root velocity the frame's twist (zero
            for a stance foot).
        v_index: velocity index in ``model`` of each actuated joint (n_act,).
        sign: +1 or -1 per actuated joint: rooted coordinate = sign * original.
        layout: configuration layout of the rooted model.
    """

    frame: str
    model: pin.Model
    v_index: np.ndarray
    sign: np.ndarray
    layout: JointLayout
    pool: pin.ModelPool = field(init=False, repr=False)
    _locked: tuple[pin.Model, np.ndarray] | None = field(init=False, repr=False, default=None)
    _held_pools: dict[tuple[int, ...], pin.ModelPool] = field(init=False, repr=False, default_factory=dict)

    def __post_init__(self) -> None:
        self.pool = pin.ModelPool(self.model, 1)  # one thread: rneaInParallel as a C++ batch loop

    def inverse_dynamics(self, frame_pose: np.ndarray, angles: np.ndarray, qd: np.ndarray,
                         qdd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Joint forces and contact wrench of a stance on this frame, batched over samples.

        Args:
            frame_pose: world pose of the contact frame (x, y, z, qx, qy, qz, qw), (N, 7).
                With a flat foot its orientation is the identity (or a yaw, which does
                not change the result).
            angles, qd, qdd: joint positions [rad], velocities [rad/s] and accelerations
                [rad/s^2] of the actuated joints, in :attr:`Robot.actuated` order, (N, n_act).

        Returns:
            ``(tau_joint, wrench)``: the generalized forces of the actuated joints in the
            original model's sign, (N, n_act) [N·m], i.e. ``S (M qdd + h - J^T lambda)``,
            and the contact wrench lambda on the foot, (N, 6) [N, N·m], expressed in the
            contact frame (linear part first).
        """
        n = angles.shape[0]
        q = self.layout.configuration(angles, frame_pose, self.sign).T
        v = np.zeros((self.model.nv, n))
        a = np.zeros((self.model.nv, n))
        v[self.v_index] = (qd * self.sign).T
        a[self.v_index] = (qdd * self.sign).T
        tau = pin.rneaInParallel(1, self.pool, np.asfortranarray(q), np.asfortranarray(v), np.asfortranarray(a))
        tau = np.asarray(tau).reshape(self.model.nv, n)
        return (tau[self.v_index].T * self.sign), tau[:6].T.copy()

    def acceleration_difference(self, angles: np.ndarray, tau_f: np.ndarray, joints: np.ndarray) -> np.ndarray:
        """``Delta qdd = M_mod^{-1} tau_f`` (5.12) in single support, batched over samples.

        ``M_mod`` is the block of ``joints`` in the mass matrix of the tree rooted at the welded
        contact frame, the other actuated joints held to their measured accelerations
        (:meth:`joint_mass_matrix`). With the velocity and gravity zero, the forward dynamics of that
        tree with the held joints locked gives exactly ``M_mod^{-1} tau_f``: one articulated-body pass
        per sample (``pin.abaInParallel``, a C++ loop; :meth:`_held_pool`). The held joints are locked
        where each sample has them (their angles move: a head turns), by an armature so large
        (:data:`LOCKED_ARMATURE`) that the articulated-body algorithm passes their child's inertia on
        whole and gives them no acceleration, to machine precision.

        Args:
            angles: joint positions of the actuated joints (N, n_act) [rad].
            tau_f: forces on ``joints`` (N, m) [N·m], original joint signs.
            joints: indices into :attr:`Robot.actuated` of the free joints (m,); every other
                actuated joint is held.

        Returns:
            (N, m) [rad/s^2], original joint signs.
        """
        model, v_index = self._locked_root()
        pool = self._held_pool(joints)
        n = angles.shape[0]
        q = self.layout.configuration(angles, None, self.sign)[:, self.layout.root_nq:]
        tau = np.zeros((model.nv, n), order="F")
        tau[v_index[joints]] = (tau_f * self.sign[joints]).T
        qdd = pin.abaInParallel(1, pool, np.asfortranarray(q.T), np.zeros((model.nv, n), order="F"), tau)
        return np.asarray(qdd).reshape(model.nv, n)[v_index[joints]].T * self.sign[joints]

    def _held_pool(self, joints: np.ndarray) -> pin.ModelPool:
        """A one-thread pool of the locked-root tree (:meth:`_locked_root`) without gravity, every actuated
        joint not in ``joints`` (indices into :attr:`Robot.actuated`) held by :data:`LOCKED_ARMATURE`; built
        once per set of free joints."""
        key = tuple(int(j) for j in np.sort(joints))
        if key not in self._held_pools:
            locked, v_index = self._locked_root()
            model = pin.Model(locked)
            model.gravity = pin.Motion.Zero()
            held = np.setdiff1d(np.arange(len(self.v_index)), key)
            model.armature[v_index[held]] = LOCKED_ARMATURE
            self._held_pools[key] = pin.ModelPool(model, 1)
        return self._held_pools[key]

    def momentum(self, angles: np.ndarray, qd: np.ndarray, frame_pose: np.ndarray | None = None,
                 progress: Progress | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The generalized momentum ``p = M qd`` and its rate without friction ``b = C^T qd - g`` of the
        actuated joints on the tree rooted at the welded contact frame, all samples at once
        (:func:`~wbfriction.model.momentum.tree_momentum_and_drift`): ``dp/dt = tau + tau_f + b`` row by row.

        Args:
            angles, qd: joint positions [rad] and velocities [rad/s] of the actuated joints (N, n_act).
            frame_pose: the contact frame's world pose (N, 7) (:func:`stance_frame_pose`): gravity seen by a
                foot that is not flat; None: flat.
            progress: optional callable receiving numbers of samples done.

        Returns:
            ``(p, b)``, (N, n_act) each [N·m·s], [N·m], in the original joints' signs.
        """
        model, v_index = self._locked_root()
        q = self.layout.configuration(angles, None, self.sign)[:, self.layout.root_nq:]
        v = np.zeros((len(angles), model.nv))
        v[:, v_index] = qd * self.sign
        gravity = None
        if frame_pose is not None:  # R^T g: world gravity in the foot's frame, R the unit quaternion's rotation
            axis, w = frame_pose[:, 3:6], frame_pose[:, 6:]
            g = np.broadcast_to(self.model.gravity.linear, axis.shape)
            turn = np.cross(axis, g)
            gravity = g - 2.0 * w * turn + 2.0 * np.cross(axis, turn)
        p, b = tree_momentum_and_drift(model, q, v, gravity)
        if progress is not None:
            progress(len(angles))
        return p[:, v_index] * self.sign, b[:, v_index] * self.sign

    def _locked_root(self) -> tuple[pin.Model, np.ndarray]:
        """The tree with its root joint locked (the contact frame welded) and the velocity index in it of each
        actuated joint (n_act,); built once."""
        if self._locked is None:
            locked = pin.buildReducedModel(self.model, [1], pin.neutral(self.model))
            name_of_v = {int(self.model.idx_vs[j]): self.model.names[j] for j in range(2, self.model.njoints)}
            v_index = [locked.idx_vs[locked.getJointId(name_of_v[int(v)])] for v in self.v_index]
            self._locked = (locked, np.array(v_index, dtype=int))
        return self._locked

    def joint_mass_matrix(self, angles: np.ndarray, joints: np.ndarray) -> np.ndarray:
        """Joint-space mass matrix of the tree rooted at the (welded) contact frame.

        With the stance foot fixed, and the accelerations of the other actuated joints
        prescribed, the block of the chosen joints is ``M_mod`` of (5.12)-(5.13): the
        operator that maps their acceleration difference to friction,
        ``tau_f = M_mod Delta qdd``. It does not depend on the root's pose.

        Args:
            angles: joint positions of the actuated joints (N, n_act) [rad].
            joints: indices into :attr:`Robot.actuated` of the block's joints (m,).

        Returns:
            (N, m, m) [kg·m^2], symmetric positive definite, in the original model's
            joint signs.
        """
        q = self.layout.configuration(angles, None, self.sign)
        data = self.model.createData()
        cols = self.v_index[joints]
        block = np.ix_(cols, cols)
        out = np.empty((angles.shape[0], len(cols), len(cols)))
        for k in range(angles.shape[0]):
            out[k] = pin.crba(self.model, data, q[k])[block]  # Pinocchio 4: the whole symmetric matrix
        out *= np.outer(self.sign[joints], self.sign[joints])
        return out


def build_stance_model(robot: Robot, frame: str) -> StanceModel:
    """Re-root ``robot.model`` at contact frame ``frame`` (see module docstring).

    Raises:
        ModelError: a joint type the graph conversion does not support, or a
            re-rooted model whose kinematics disagree with the original one.
    """
    model = robot.model
    graph = _G.ModelGraph()
    for j in range(1, model.njoints):
        graph.addBody(body_frame(j), model.inertias[j])
    for j in range(2, model.njoints):
        graph.addJoint(model.names[j], _graph_joint(model.joints[j]), body_frame(model.parents[j]),
                       model.jointPlacements[j], body_frame(j), pin.SE3.Identity())
    fr = model.frames[model.getFrameId(frame)]
    rooted = _G.buildModel(graph, body_frame(fr.parentJoint), fr.placement.inverse(), _G.JointFreeFlyer())
    # pin.graph places the root joint at the foot body, the contact frame's offset in the
    # root joint's placement, i.e. on the universe side of the root's motion: the root
    # configuration would then not be the contact frame's pose (rotations compose in the
    # wrong order) and the root wrench would act at the body origin. Move the offset to the
    # child side, so that the root joint frame *is* the contact frame.
    offset = rooted.jointPlacements[1].copy()
    rooted.jointPlacements[1] = pin.SE3.Identity()
    for j in range(2, rooted.njoints):
        if rooted.parents[j] == 1:
            rooted.jointPlacements[j] = offset * rooted.jointPlacements[j]
    for f in rooted.frames:
        if f.parentJoint == 1 and f.name != "root_joint":
            f.placement = offset * f.placement
    # Body inertias: set each one from the original body, re-expressed in the frame of the
    # joint that carries it in the rooted tree. (pin.graph 4.1 leaves the inertia of a body
    # reached through a reversed joint with an offset placement in the wrong frame.)
    carriers = set()
    for j in range(1, model.njoints):
        body = rooted.frames[rooted.getFrameId(body_frame(j))]
        if body.parentJoint in carriers:  # pragma: no cover - would break the one-body-per-joint invariant
            raise ModelError("re-rooted model merges two bodies into one joint")
        carriers.add(body.parentJoint)
        rooted.inertias[body.parentJoint] = body.placement.act(model.inertias[j])
    rooted.gravity = model.gravity
    v_index = np.array([rooted.idx_vs[rooted.getJointId(n)] for n in robot.actuated], dtype=int)
    rooted.armature[v_index] = model.armature[robot.act_v_index]
    reversed_joints = set(model.supports[fr.parentJoint])
    sign = np.array([-1.0 if model.getJointId(n) in reversed_joints else 1.0 for n in robot.actuated])
    stance = StanceModel(frame, rooted, v_index, sign, joint_layout(rooted, robot.actuated))
    check_kinematics(robot, stance)
    return stance


def stance_model(robot: Robot, contact_index: int) -> StanceModel:
    """The model of ``robot`` rooted at contact frame number ``contact_index`` (built once)."""
    key = ("stance", contact_index)
    if key not in robot.cache:
        robot.cache[key] = build_stance_model(robot, robot.contact_frames[contact_index])
    return robot.cache[key]


def check_kinematics(robot: Robot, stance: StanceModel, seed: int = 0) -> None:
    """Check that ``stance`` (the tree re-rooted at its contact frame, :func:`stance_model`) places every
    body of ``robot`` where the original tree does, relative to the contact frame, at joint angles drawn
    uniformly in [-1, 1] rad with ``seed`` (homogeneous transforms equal to 1e-9).

    Raises:
        ModelError: a body placed elsewhere, named with the contact frame.
    """
    rng = np.random.default_rng(seed)
    angles = rng.uniform(-1.0, 1.0, robot.n_act)
    m, r = robot.model, stance.model
    dm, dr = m.createData(), r.createData()
    pin.framesForwardKinematics(m, dm, robot.configuration(angles))
    pin.framesForwardKinematics(r, dr, stance.layout.configuration(angles, None, stance.sign))
    f_m = dm.oMf[m.getFrameId(stance.frame)]
    for j in range(1, m.njoints):
        rel_m = f_m.actInv(dm.oMi[j])
        rel_r = dr.oMf[r.getFrameId(body_frame(j))]  # root frame is the contact frame at identity
        if not np.allclose(rel_m.homogeneous, rel_r.homogeneous, atol=1e-9):
            raise ModelError(f"re-rooted model at '{stance.frame}' disagrees with the original at body of "
                             f"'{m.names[j]}'")


def stance_frame_pose(robot: Robot, stance: StanceModel, angles: np.ndarray, base: np.ndarray | None) -> np.ndarray:
    """World pose of the stance frame (x, y, z, qx, qy, qz, qw), (N, 7): the identity (the sole
    flat at the origin, as the estimator reconstructs it without a logged base) or, with the
    logged base poses ``base`` (N, 7), the frame's pose by forward kinematics.

    Args:
        robot: the robot; stance: its model rooted at the stance frame (:func:`stance_model`).
        angles: joint positions of the actuated joints (N, n_act) [rad].
        base: logged base poses (N, 7) or None.
    """
    n = angles.shape[0]
    pose = np.zeros((n, 7))
    pose[:, 6] = 1.0
    if base is None:
        return pose
    model, columns, fid = foot_chain(robot, stance.frame)
    data = model.createData()
    q = robot.configuration(angles, base)[:, columns]
    for k in range(n):
        pin.forwardKinematics(model, data, q[k])
        pose[k] = pin.SE3ToXYZQUAT(pin.updateFramePlacement(model, data, fid))
    return pose


def foot_chain(robot: Robot, frame: str) -> tuple[pin.Model, np.ndarray, int]:
    """The chain of ``robot.model`` from its root to contact frame ``frame``: every joint off it locked
    (``pin.buildReducedModel``; the chain's placements are the model's own, so forward kinematics places the frame
    to the same bits in a fifth of the time on a humanoid), the columns of a configuration of ``robot`` (nq,) that
    make one of the chain (its nq,), and the frame's id in it; built once per frame."""
    key = ("foot chain", frame)
    if key not in robot.cache:
        model = robot.model
        chain = set(model.supports[model.frames[model.getFrameId(frame)].parentJoint])
        locked = [j for j in range(1, model.njoints) if j not in chain]
        reduced = pin.buildReducedModel(model, locked, pin.neutral(model))
        columns = np.concatenate([np.arange(model.idx_qs[j], model.idx_qs[j] + model.nqs[j])
                                  for j in (model.getJointId(reduced.names[i]) for i in range(1, reduced.njoints))])
        robot.cache[key] = (reduced, columns, reduced.getFrameId(frame))
    return robot.cache[key]
