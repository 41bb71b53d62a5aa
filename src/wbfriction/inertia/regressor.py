"""The joint-torque regressor of the robot standing on one sole, or on point feet with its base's motion measured, in
the original bodies' inertial parameters.

The inverse dynamics are linear in each body's ten inertial parameters
``pi_b = (m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz)`` (about the body's joint
frame; ``pin.Inertia.toDynamicParameters`` order). In single support the stance foot is welded
to the ground and the robot is a fixed-base tree rooted at it (:mod:`wbfriction.model.rerooted`);
the joint rows of that tree's regressor (``pin.computeJointTorqueRegressor``) are free of the
contact wrench. :class:`StanceRegressor` maps its columns back to the original bodies.

A robot on point feet gives no such tree (a point foot turns about its contact). With the base's motion measured,
the floating model's own regressor holds every acceleration (:class:`FloatingRegressor`): a joint's row is free of
the contact forces where no foot with an unknown force is down on its limb
(:func:`~wbfriction.model.determination.free_rows`; issue 56).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from wbfriction.model.rerooted import StanceModel, body_frame, stance_model
from wbfriction.model.robot import Robot

PARAMS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
"""The ten inertial parameters of a body, in ``pin.Inertia.toDynamicParameters`` order
[kg, kg·m, kg·m^2]: mass, first moments, rotational inertia about the joint frame."""

def body_parameters(model: pin.Model) -> np.ndarray:
    """The inertial parameters of every body (joint) of ``model``, (n_bodies, 10)."""
    return np.array([model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)])


def with_body_parameters(model: pin.Model, pi: np.ndarray) -> pin.Model:
    """A copy of ``model`` with body ``j``'s inertia from row ``j - 1`` of ``pi`` (n_bodies, 10)."""
    out = pin.Model(model)
    for j in range(1, model.njoints):
        out.inertias[j] = pin.Inertia.FromDynamicParameters(np.asarray(pi[j - 1], dtype=float))
    return out


def act_matrix(placement: pin.SE3) -> np.ndarray:
    """The linear map (10, 10) of ``placement.act`` on dynamic parameters: the parameters
    of a body expressed in a frame whose pose in the current one is ``placement``...
    i.e. ``toDynamicParameters(placement.act(I)) = A @ toDynamicParameters(I)``."""
    ref = np.array([1.0, 0, 0, 0, 1, 0, 1, 0, 0, 1])  # unit mass, unit inertia: the map is affine-free
    base = placement.act(pin.Inertia.FromDynamicParameters(ref)).toDynamicParameters()
    cols = []
    for k in range(10):
        e = ref.copy()
        e[k] += 1.0
        cols.append(placement.act(pin.Inertia.FromDynamicParameters(e)).toDynamicParameters() - base)
    return np.array(cols).T


@dataclass
class StanceRegressor:
    """Joint-torque regressor of the robot standing on one contact frame.

    The regressor of the stance-rooted tree is in the parameters of its own bodies, each
    expressed in the frame of the rooted joint that carries it; :attr:`to_rooted` maps the
    original model's parameters to those (a fixed linear map, so that a least-squares
    system built in rooted parameters is mapped once, not row by row).

    Attributes:
        stance: the stance-rooted model (:mod:`wbfriction.model.rerooted`).
        to_rooted: (10 n_bodies, 10 n_bodies): ``pi_rooted = to_rooted @ pi.ravel()``.
        pattern: (n_act, 10 n_bodies), whether an actuated joint's row of :meth:`joint_rows` can be
            non-zero in a rooted parameter (:func:`structural_pattern`): a joint's torque depends only on
            the bodies beyond it in the rooted tree.
    """

    stance: StanceModel
    to_rooted: np.ndarray
    data: pin.Data = field(init=False, repr=False)
    pattern: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.data = self.stance.model.createData()
        self.pattern = structural_pattern(self.stance.model, self.data, self.stance.v_index)

    def joint_rows(self, frame_pose: np.ndarray, angles: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """``Y`` with ``Y @ to_rooted @ pi.ravel() = S (M qdd + h - J^T lambda)`` (without the
        armature): the generalized forces of the actuated joints, for each sample.

        Args:
            frame_pose: world pose of the stance frame (N, 7) (x, y, z, qx, qy, qz, qw).
            angles, qd, qdd: actuated joints' positions, velocities, accelerations (N, n_act).

        Returns:
            (N, n_act, 10 n_bodies), in the original joints' signs.
        """
        model, st = self.stance.model, self.stance
        q = st.layout.configuration(angles, frame_pose, st.sign)
        n = angles.shape[0]
        Y = np.empty((n, len(st.v_index), 10 * (model.njoints - 1)))
        v = np.zeros((n, model.nv))
        a = np.zeros((n, model.nv))
        v[:, st.v_index] = qd * st.sign
        a[:, st.v_index] = qdd * st.sign
        for k in range(n):  # the actuated rows taken straight into Y (one copy)
            np.take(pin.computeJointTorqueRegressor(model, self.data, q[k], v[k], a[k]), st.v_index, axis=0, out=Y[k])
        Y *= st.sign[None, :, None]
        return Y


def structural_pattern(model: pin.Model, data: pin.Data, v_index: np.ndarray, states: int = 3) -> np.ndarray:
    """Where the rows ``v_index`` (the actuated joints') of ``model``'s regressor can be non-zero
    (len(v_index), 10 n_bodies): the entries non-zero at any of ``states`` random configurations, velocities and
    accelerations (the root's included, so that no gravity direction or motion is special). An entry zero at a
    generic state is zero by the tree's structure (the bodies not beyond the joint, the parameters a joint's axis
    does not see), at every state: a regression may leave such columns out of a joint's rows."""
    rng = np.random.default_rng(0)
    out = np.zeros((len(v_index), 10 * (model.njoints - 1)), dtype=bool)
    for _ in range(states):
        q = pin.integrate(model, pin.neutral(model), rng.standard_normal(model.nv))
        Y = pin.computeJointTorqueRegressor(model, data, q, rng.standard_normal(model.nv),
                                            rng.standard_normal(model.nv))
        out |= Y[v_index] != 0.0
    return out


@dataclass
class FloatingRegressor:
    """Joint-torque regressor of a robot on point feet whose base's motion is measured (module docstring): the
    floating model's, its actuated joints' rows, in the original bodies' parameters.

    Attributes:
        model: the robot's floating model.
        v_index: the actuated joints' velocity indices (n_act,).
        to_rooted: the identity (10 n_bodies, 10 n_bodies): :class:`StanceRegressor`'s map, here none.
        pattern: (n_act, 10 n_bodies), as :attr:`StanceRegressor.pattern`.
    """

    model: pin.Model
    v_index: np.ndarray
    data: pin.Data = field(init=False, repr=False)
    to_rooted: np.ndarray = field(init=False, repr=False)
    pattern: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.data = self.model.createData()
        self.to_rooted = np.eye(10 * (self.model.njoints - 1))
        self.pattern = structural_pattern(self.model, self.data, self.v_index)

    def joint_rows(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """``Y`` with ``Y @ pi.ravel() = S (M a + h)`` (without the armature), for each sample.

        Args:
            q, v, a: the floating model's configurations (N, nq), velocities and accelerations (N, nv), the base's
                in Pinocchio's convention (its twist in its own frame).

        Returns:
            (N, n_act, 10 n_bodies) [N·m per parameter unit].
        """
        Y = np.empty((len(q), len(self.v_index), 10 * (self.model.njoints - 1)))
        for k in range(len(q)):
            np.take(pin.computeJointTorqueRegressor(self.model, self.data, q[k], v[k], a[k]), self.v_index, axis=0,
                    out=Y[k])
        return Y


def stance_regressor(robot: Robot, contact_index: int) -> StanceRegressor:
    """The regressor of ``robot`` standing on contact ``contact_index`` (built once)."""
    key = ("regressor", contact_index)
    if key not in robot.cache:
        stance = stance_model(robot, contact_index)
        nb = robot.model.njoints - 1
        T = np.zeros((10 * nb, 10 * nb))
        for j in range(1, robot.model.njoints):
            f = stance.model.frames[stance.model.getFrameId(body_frame(j))]
            c = f.parentJoint - 1
            T[10 * c:10 * c + 10, 10 * (j - 1):10 * j] = act_matrix(f.placement)
        robot.cache[key] = StanceRegressor(stance, T)
    return robot.cache[key]


def floating_regressor(robot: Robot) -> FloatingRegressor:
    """The floating regressor of ``robot`` on point feet (built once)."""
    if "floating regressor" not in robot.cache:
        robot.cache["floating regressor"] = FloatingRegressor(robot.model, np.asarray(robot.act_v_index))
    return robot.cache["floating regressor"]


def row_groups(robot: Robot) -> range:
    """The groups of rows a regression builds with one regressor each (:func:`regressor_of`): one per contact frame
    on soles (the stance it is rooted at), one on point feet (the floating model)."""
    return range(1) if robot.partial_contacts else range(len(robot.contact_frames))


def regressor_of(robot: Robot, group: int) -> StanceRegressor | FloatingRegressor:
    """The regressor of a group of :func:`row_groups`: the floating one on point feet, else the stance's."""
    return floating_regressor(robot) if robot.partial_contacts else stance_regressor(robot, group)
