"""From the fitted friction models to the joint parameters of simulators: what each one holds, what is dropped.

The identified friction is, per joint, one of the models of :mod:`wbfriction.friction.models`,
most fully the thesis's (3.5),

.. math:: f(\\dot q) = F_v \\dot q + F_c \\tanh(a \\dot q)\\,(1 + S e^{-|\\dot q / v_s|^{\\delta_s}}) + \\tau_{os},
          \\qquad \\tau_f = -f(\\dot q),

(the ``stribeck`` model writes the static level F_s itself and ``sgn`` for ``tanh``; the
``coulomb-viscous`` model has no static level apart from F_c), and the armature (reflected rotor
inertia) a number per joint [kg·m^2]. Simulators hold less:

===================  ======================  =====================  ===================================
model (3.5)          URDF ``<dynamics>``     MJCF ``<joint>``       Isaac Lab actuator (``ActuatorBaseCfg``)
===================  ======================  =====================  ===================================
F_v [N·m·s/rad]      ``damping``             ``damping``            ``viscous_friction``
F_c [N·m]            ``friction``            ``frictionloss``       ``dynamic_friction``
F_s = (1 + S) F_c    --                      --                     ``friction`` (static)
S, v_s (Stribeck)    dropped                 dropped                shape dropped (only the level F_s)
a (tanh slope)       dropped                 dropped                dropped
tau_os (offset)      dropped                 dropped                dropped
armature [kg·m^2]    -- (no URDF field)      ``armature``           ``armature``
===================  ======================  =====================  ===================================

(F_s is the ``stribeck`` model's own F_s, and F_c for the ``coulomb-viscous`` model.)

* Viscous friction is exact everywhere: every simulator has a linear damping ``-F_v qd``.
* The Coulomb level F_c is what the joint sees in motion (``tanh(a qd) -> sgn(qd)`` for
  ``|qd| >> 1/a``, the Stribeck bump gone for ``|qd| >> v_s``): URDF's ``friction`` (used as one
  dry-friction level by Gazebo, by Pinocchio's dry friction limits, and by MuJoCo's URDF import as
  ``frictionloss``) and MuJoCo's ``frictionloss`` (dry friction as a soft constraint: no tanh, its
  smoothing set by the constraint's ``solref``/``solimp``; see :mod:`wbfriction.export.mjcf`) get F_c.
* Only PhysX (Isaac Sim >= 5.0, so Isaac Lab >= 2.2) has a separate static level: ``friction`` is
  the static friction effort F_s that holds a joint at rest, ``dynamic_friction`` the one in
  motion, F_c (PhysX needs ``dynamic_friction <= friction``, i.e. F_s >= F_c, S >= 0). How fast the
  friction falls from F_s to F_c (v_s, the Stribeck velocity) has no field anywhere.
* ``tau_os`` is not friction (a torque sensor's offset, removed before the energy check, thesis
  7.9): it is not exported. Nor is ``a``, a smoothing of the model's sign function.

Friction that is not dissipative (F_c < 0, F_v < 0, or a static level F_s < 0, i.e. S < -1) and
a negative armature are refused (:class:`~wbfriction.exceptions.InputError`), never exported.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.fit import FitResult
from wbfriction.model.robot import Robot


class FrictionModelParams(Protocol):
    """The parameters of any friction model of :mod:`wbfriction.friction.models` (:class:`FrictionParams`
    of (3.5), ``StribeckParams``, ``CoulombViscousParams``): what the export reads of them."""

    @property
    def F_v(self) -> float: ...

    @property
    def F_c(self) -> float: ...


FrictionLike = FitResult | FrictionModelParams
"""Fitted friction of one joint as the project stores it: a :class:`FitResult` (what
:func:`wbfriction.friction.io.read_params` returns; one without parameters exports no friction)
or bare parameters of a model (e.g. :class:`FrictionParams`)."""


def static_level(params: FrictionModelParams) -> float:
    """The static friction F_s [N·m], the level at rest: ``(1 + S) F_c`` of model (3.5), the
    ``stribeck`` model's ``F_s``, ``F_c`` of the ``coulomb-viscous`` model."""
    F_s, S = getattr(params, "F_s", None), getattr(params, "S", None)
    if F_s is not None:
        return float(F_s)
    return float((1.0 + S) * params.F_c) if S is not None else float(params.F_c)


@dataclass(frozen=True)
class JointExport:
    """The simulator parameters of one joint (module docstring for the mapping).

    Attributes:
        joint: joint name.
        viscous: viscous friction F_v [N·m·s/rad] (URDF/MJCF ``damping``, Isaac ``viscous_friction``),
            None without identified friction.
        coulomb: Coulomb friction F_c [N·m] (URDF ``friction``, MJCF ``frictionloss``, Isaac
            ``dynamic_friction``), None without identified friction.
        static: static friction F_s [N·m] (:func:`static_level`; Isaac ``friction``), None without
            identified friction.
        armature: reflected rotor inertia [kg·m^2] (MJCF and Isaac ``armature``), None when not given.
        params: the model parameters the friction comes from (what is dropped: tau_os, and S, v_s, a of (3.5)).

    Raises:
        InputError: a value that is negative (not dissipative) or not finite, or friction given in part.
    """

    joint: str
    viscous: float | None = None
    coulomb: float | None = None
    static: float | None = None
    armature: float | None = None
    params: FrictionModelParams | None = None

    def __post_init__(self) -> None:
        given = [x is not None for x in (self.viscous, self.coulomb, self.static)]
        if any(given) and not all(given):
            raise InputError(f"joint '{self.joint}': viscous, Coulomb and static friction go together")
        for name, value, unit in (("F_v", self.viscous, "N·m·s/rad"), ("F_c", self.coulomb, "N·m"),
                                  ("F_s", self.static, "N·m"), ("armature", self.armature, "kg·m^2")):
            if value is None:
                continue
            if not np.isfinite(value):
                raise InputError(f"joint '{self.joint}': {name} = {value} is not a finite number")
            if value < 0:
                what = "a negative armature" if name == "armature" else "friction that is not dissipative"
                raise InputError(f"joint '{self.joint}': {name} = {value:g} {unit} < 0: {what} is not exported")

    @property
    def has_friction(self) -> bool:
        """Whether the joint has identified friction (then :attr:`viscous`, :attr:`coulomb`, :attr:`static` are set)."""
        return self.coulomb is not None


def joint_export(joint: str, friction: FrictionLike | None = None, armature: float | None = None) -> JointExport:
    """The simulator parameters of one joint from its fitted friction and armature (module docstring).

    Args:
        joint: joint name.
        friction: the joint's fitted friction; None, or a fit without parameters: no friction.
        armature: [kg·m^2], or None.

    Raises:
        InputError: F_c < 0, F_v < 0, F_s < 0 (S < -1 in (3.5)), a negative armature or
            a value that is not finite: not dissipative, not exported (the message names the joint).
    """
    params = friction.params if isinstance(friction, FitResult) else friction
    if params is None:
        return JointExport(joint, armature=None if armature is None else float(armature))
    return JointExport(joint, viscous=float(params.F_v), coulomb=float(params.F_c),
                       static=static_level(params),
                       armature=None if armature is None else float(armature), params=params)


def joint_exports(friction: Mapping[str, FrictionLike], armature: Mapping[str, float] | None = None,
                  robot: Robot | None = None) -> dict[str, JointExport]:
    """The simulator parameters of every joint with friction or armature, by name.

    Args:
        friction: joint -> fitted friction (e.g. :func:`wbfriction.friction.io.read_params`).
        armature: joint -> reflected rotor inertia [kg·m^2], or None.
        robot: if given, every joint must be one of its actuated joints; the result is then
            in :attr:`Robot.actuated` order (otherwise: the friction's, then the armature's).

    Returns:
        joint -> :class:`JointExport`; joints whose fit has no parameters and no armature are left out.

    Raises:
        InputError: a value :func:`joint_export` refuses, or (with ``robot``) a joint the robot does not actuate.
    """
    armature = armature or {}
    names = list(dict.fromkeys([*friction, *armature]))
    if robot is not None:
        unknown = [n for n in names if n not in robot.actuated]
        if unknown:
            raise InputError(f"joint '{unknown[0]}' is not an actuated joint of robot '{robot.name}'")
        names = [n for n in robot.actuated if n in names]
    out = {}
    for name in names:
        exp = joint_export(name, friction.get(name), armature.get(name))
        if exp.has_friction or exp.armature is not None:
            out[name] = exp
    return out
