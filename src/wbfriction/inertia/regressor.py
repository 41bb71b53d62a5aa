"""The joint-torque regressor of the robot standing on one sole, in the original bodies' inertial parameters.

The inverse dynamics are linear in each body's ten inertial parameters
``pi_b = (m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz)`` (about the body's joint
frame; ``pin.Inertia.toDynamicParameters`` order). In single support the stance foot is welded
to the ground and the robot is a fixed-base tree rooted at it (:mod:`wbfriction.model.stance`);
the joint rows of that tree's regressor (``pin.computeJointTorqueRegressor``) are free of the
contact wrench. :class:`StanceRegressor` maps its columns back to the original bodies.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from wbfriction.model.robot import Robot
from wbfriction.model.stance import StanceModel, body_frame, stance_model

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
        stance: the stance-rooted model (:mod:`wbfriction.model.stance`).
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
        self.pattern = structural_pattern(self.stance, self.data)

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


def structural_pattern(stance: StanceModel, data: pin.Data, states: int = 3) -> np.ndarray:
    """Where the actuated joints' rows of the stance tree's regressor can be non-zero (n_act, 10 n_bodies):
    the entries non-zero at any of ``states`` random configurations, velocities and accelerations (the
    root's included, so that no gravity direction or motion is special). An entry zero at a generic state is
    zero by the tree's structure (the bodies not beyond the joint, the parameters a joint's axis does not
    see), at every state: a regression may leave such columns out of a joint's rows."""
    model = stance.model
    rng = np.random.default_rng(0)
    out = np.zeros((len(stance.v_index), 10 * (model.njoints - 1)), dtype=bool)
    for _ in range(states):
        q = pin.integrate(model, pin.neutral(model), rng.standard_normal(model.nv))
        Y = pin.computeJointTorqueRegressor(model, data, q, rng.standard_normal(model.nv),
                                            rng.standard_normal(model.nv))
        out |= Y[stance.v_index] != 0.0
    return out


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
