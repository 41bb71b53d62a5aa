"""How a contact frame touches the ground: the contact models the package knows, in a registry new ones join with one
call, and the one each contact frame of a robot is (``contact_model`` in its TOML, :attr:`Robot.contact_kinds
<wbfriction.model.robot.Robot.contact_kinds>`).

A contact model is the constraint the contact puts on the robot's motion, ``J_c v = 0`` (thesis 4.4), and so the
contact force it takes, ``J_c^T lambda`` in the equations of motion (thesis 5.10): its Jacobian's rows are the force's
components. Two are built in:

* ``sole``: a humanoid's foot sole, six constraints (the frame does not move, thesis 4.4), a contact wrench in the
  frame's own axes. One sole on the ground fixes the floating base: the thesis's single-support route (5.13).
* ``point``: a quadruped's foot, three constraints (its contact point does not move; the foot may turn about it), a
  force in world axes, which foot sensors measure (:mod:`wbfriction.logs.foot_forces`). No single point fixes the
  base: which joints' friction a sample determines is the rank question of :mod:`wbfriction.model.determination`,
  asked sample by sample (:mod:`wbfriction.friction.point_contacts`).

Another is one call away::

    import pinocchio as pin

    from wbfriction.model.contacts import ContactModel, register_contact_model

    class LocalPoint(ContactModel):
        name, what, plural, dims = "local-point", "a point in the frame's axes (three constraints)", "points", 3
        def jacobian(self, robot, data, frame_id):
            return pin.getFrameJacobian(robot.model, data, frame_id, pin.LOCAL)[:3]

    register_contact_model(LocalPoint())

after which a robot TOML's ``contact_model = "local-point"`` loads, and every function and command that takes the
robot estimates its friction with it.
"""

from __future__ import annotations

from typing import ClassVar, Protocol

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.registry import Registry

ContactKind = str
"""How a contact frame touches the ground: the name of a registered :class:`ContactModel` (``"sole"``, ``"point"``
built in; :attr:`Robot.contact_kinds <wbfriction.model.robot.Robot.contact_kinds>`)."""


class ContactFrames(Protocol):
    """What a contact model's Jacobian reads of the robot (a :class:`~wbfriction.model.robot.Robot`)."""

    @property
    def model(self) -> pin.Model:
        """The Pinocchio model."""

    @property
    def foot_radius(self) -> float:
        """A point foot's sphere [m] (:attr:`Robot.foot_radius <wbfriction.model.robot.Robot.foot_radius>`)."""


class ContactModel:
    """A contact model: the constraints a contact frame on the ground puts on the robot, and the force it takes.

    A subclass names itself (:attr:`name`, what a robot TOML's ``contact_model`` says; :attr:`what` and
    :attr:`plural`, what messages say), gives its constraints' number (:attr:`dims`: the contact force's components)
    and their Jacobian (:meth:`jacobian`), and says what follows for the estimation: whether one such contact alone
    fixes the floating base (:attr:`fixes_base`) and whether foot sensors measure its force's components
    (:attr:`world_force`).
    """

    name: ClassVar[str]
    """The model's name, as a robot TOML's ``contact_model`` gives it."""
    what: ClassVar[str]
    """What one such contact is, for messages ("a sole (six constraints: the frame does not move)")."""
    plural: ClassVar[str]
    """What a robot on such contacts stands on, for messages ("soles", "point feet")."""
    dims: ClassVar[int]
    """The constraints: the rows of :meth:`jacobian`, the contact force's components."""
    fixes_base: ClassVar[bool] = False
    """Whether one such contact alone fixes the floating base (its Jacobian's base columns of full rank 6): single
    support determines every joint's friction, the thesis's route (5.13, :mod:`wbfriction.friction.estimate`). If
    not, a robot with such a contact has its friction estimated where the contacts leave it determined, sample by
    sample (:attr:`Robot.partial_contacts <wbfriction.model.robot.Robot.partial_contacts>`,
    :mod:`wbfriction.model.determination`), which needs the base's measured motion."""
    world_force: ClassVar[bool] = False
    """Whether its force's components are the world-axes force foot sensors measure (``force.<frame>.x|y|z``,
    :mod:`wbfriction.logs.foot_forces`): the rows of :meth:`jacobian` are then x, y, z in world axes, and measured
    components are known forces (:func:`~wbfriction.model.determination.joint_torques`); otherwise a foot's force
    columns are not used."""

    def jacobian(self, robot: ContactFrames, data: pin.Data, frame_id: int) -> np.ndarray:
        """The constraint Jacobian ``J_c`` (dims, nv) of the contact at Pinocchio frame ``frame_id``, after
        ``pin.computeJointJacobians`` and ``pin.updateFramePlacements`` on ``data``: ``J_c v`` is the motion the
        contact forbids (thesis 4.4), ``J_c^T lambda`` its force's generalized torque (thesis 5.10)."""
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"


class Sole(ContactModel):
    """A foot sole: six constraints, the frame does not move (thesis 4.4), a contact wrench in its own axes."""

    name, plural, dims, fixes_base = "sole", "soles", 6, True
    what = "a sole (six constraints: the frame does not move)"

    def jacobian(self, robot: ContactFrames, data: pin.Data, frame_id: int) -> np.ndarray:
        """The frame's six LOCAL rows (6, nv)."""
        return pin.getFrameJacobian(robot.model, data, frame_id, pin.LOCAL)


class Point(ContactModel):
    """A point foot: three constraints, its contact point does not move (the foot may turn about it), a force in
    world axes."""

    name, plural, dims, world_force = "point", "point feet", 3, True
    what = "a point foot (three constraints: its contact point does not move)"

    def jacobian(self, robot: ContactFrames, data: pin.Data, frame_id: int) -> np.ndarray:
        """The velocity of its contact point in world axes (3, nv): the frame's origin, or with the robot's
        :attr:`~wbfriction.model.robot.Robot.foot_radius` ``r`` the sphere's lowest point ``d = -r e_z`` from it,
        ``J_lin - [d]x J_ang`` (LOCAL_WORLD_ALIGNED)."""
        J = pin.getFrameJacobian(robot.model, data, frame_id, pin.LOCAL_WORLD_ALIGNED)
        r = robot.foot_radius
        if not r:
            return J[:3]
        # v_p = v_o + w x d, d = (0, 0, -r): w x d = (-r w_y, r w_x, 0)
        return J[:3] + np.array([[0.0, -r, 0.0], [r, 0.0, 0.0], [0.0, 0.0, 0.0]]) @ J[3:]


def check_contact_model(kind: ContactModel) -> None:
    """Refuse a contact model whose :attr:`~ContactModel.dims` is not 1-6, or one of
    :attr:`~ContactModel.world_force` whose force is not three components (what :func:`register_contact_model` checks
    first).

    Raises:
        ValueError: naming the model and what is wrong.
    """
    if not 1 <= kind.dims <= 6:
        raise ValueError(f"contact model '{kind.name}' has {kind.dims} constraints: a contact has 1 to 6")
    if kind.world_force and kind.dims != 3:
        raise ValueError(f"contact model '{kind.name}' takes foot sensors' world-axes forces (world_force) but has "
                         f"{kind.dims} constraints, not their 3 components")


ENTRY_POINT_GROUP = "wbfriction.contact_models"
"""The entry-point group under which an installed package advertises its contact models: each entry's name is the
model's (what a robot TOML's ``contact_model`` names) and its object a :class:`ContactModel` (an instance, or a class
called without arguments)."""

MODELS: Registry[ContactModel] = Registry("contact model", unknown=InputError, check=check_contact_model,
                                          entry_points=ENTRY_POINT_GROUP)
"""The registered contact models, in the order they were registered, then those installed packages advertise (each
loaded when a robot TOML first names it: one that does not load is its one line,
:class:`~wbfriction.registry.EntryPointError`)."""


register_contact_model = MODELS.register
"""Add a contact model (a :class:`ContactModel`) to those a robot TOML's ``contact_model`` may name; returns it.
ValueError: a model of that name registered already (naming it), one whose :attr:`~ContactModel.dims` is not 1-6, or
one of :attr:`~ContactModel.world_force` whose force is not three components."""
unregister_contact_model = MODELS.unregister
"""Remove the contact model of a name; returns it (ValueError: none of that name)."""
contact_models = MODELS.kinds
"""The registered contact models, in the order they were registered."""
contact_model_of = MODELS.get
"""The registered contact model of a name (:class:`~wbfriction.exceptions.InputError`: none, listing those
registered)."""


for _builtin in (Sole(), Point()):
    register_contact_model(_builtin)
