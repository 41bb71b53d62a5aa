"""The identified friction and armature as an Isaac Lab actuator dictionary (YAML).

Isaac Lab's ``ActuatorBaseCfg`` (``isaaclab.actuators``) takes per joint, by name, the fields

* ``armature`` [kg·m^2]: added to the joint-space inertia (the reflected rotor inertia);
* ``friction`` [N·m]: the static friction effort, the most that holds a joint at rest;
* ``dynamic_friction`` [N·m]: the dynamic (kinetic) friction effort, opposing a moving joint;
* ``viscous_friction`` [N·m·s/rad]: ``-viscous_friction * qd`` on a moving joint,

which PhysX applies as ``PxJointFrictionParams`` (static, dynamic effort, viscous coefficient;
dynamic <= static). These meanings hold from Isaac Sim 5.0 (Isaac Lab 2.2 on); in Isaac Sim 4.5
``friction`` was a unitless coefficient and the other two were not applied. Not Isaac Lab's
``damping``: that is the drive's PD gain, not friction.

From model (3.5) (:mod:`wbfriction.export.mapping`): ``friction = (1 + S) F_c`` (the static level
F_s; the ``stribeck`` model's F_s, the ``coulomb-viscous`` model's F_c), ``dynamic_friction = F_c``,
``viscous_friction = F_v``; the Stribeck velocity v_s, the tanh slope a and the offset tau_os are
dropped. A joint with F_s < F_c (S < 0: static below Coulomb friction, which PhysX does not allow)
is refused.

The document: ``joint_names_expr`` (the joints, each with friction from a fit followed by a comment of
its status, :func:`~wbfriction.export.mapping.status_note`), then one mapping per field, joint -> value,
the fields without any value left out (Isaac Lab then keeps the USD's). Isaac Lab reads the names as
regular expressions matched in full: they are written ``re.escape``-d (unchanged for names of
letters, digits and underscores). Use::

    cfg = ImplicitActuatorCfg(stiffness=..., damping=..., **yaml.safe_load(open("actuators.yaml")))

The YAML is written by hand (:func:`isaac_yaml`): names as double-quoted strings, numbers with a
dot in the mantissa and a signed exponent (``1.0e-05``), so that YAML 1.1 readers (PyYAML, what
Isaac Lab uses) and YAML 1.2 ones read the same floats back, exactly.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from wbfriction.exceptions import InputError
from wbfriction.export.mapping import FrictionLike, JointExport, joint_exports, status_note
from wbfriction.export.target import ExportReport, ExportTarget
from wbfriction.logs.tables import write_atomic
from wbfriction.model.robot import Robot

ISAAC_FIELDS = ("armature", "friction", "dynamic_friction", "viscous_friction")
"""The per-joint fields of Isaac Lab's ``ActuatorBaseCfg`` this export fills, in the order written."""


def isaac_actuator_dict(friction: Mapping[str, FrictionLike], armature: Mapping[str, float] | None = None,
                        robot: Robot | None = None) -> dict[str, Any]:
    """The Isaac Lab actuator dictionary (module docstring): ``joint_names_expr`` and, per field of
    :data:`ISAAC_FIELDS` that has values, ``{re.escape(joint): value}``.

    Args:
        friction: joint -> fitted friction of model (3.5) (:func:`wbfriction.fit.params_file.read_params`).
        armature: joint -> reflected rotor inertia [kg·m^2], or None.
        robot: if given, the joints must be its actuated joints (and are written in its order).

    Raises:
        InputError: friction that is not dissipative, F_s < F_c (PhysX needs ``dynamic_friction <=
            friction``), a negative armature, a joint ``robot`` does not actuate.
    """
    return _actuator_dict(joint_exports(friction, armature, robot))


def _actuator_dict(joints: Mapping[str, JointExport]) -> dict[str, Any]:
    """:func:`isaac_actuator_dict` of the joints' simulator parameters (:func:`joint_exports`)."""
    for exp in joints.values():
        if exp.static is not None and exp.coulomb is not None and exp.static < exp.coulomb:
            raise InputError(f"joint '{exp.joint}': static friction F_s = {exp.static:g} N·m below the Coulomb "
                             f"friction F_c = {exp.coulomb:g} N·m (S < 0), which Isaac Lab (PhysX) does not allow")
    key = re.escape
    values = {
        "armature": {key(n): e.armature for n, e in joints.items() if e.armature is not None},
        "friction": {key(n): e.static for n, e in joints.items() if e.static is not None},
        "dynamic_friction": {key(n): e.coulomb for n, e in joints.items() if e.coulomb is not None},
        "viscous_friction": {key(n): e.viscous for n, e in joints.items() if e.viscous is not None},
    }
    return {"joint_names_expr": [key(n) for n in joints], **{f: values[f] for f in ISAAC_FIELDS if values[f]}}


def yaml_float(x: float) -> str:
    """A finite float as YAML 1.1 and 1.2 both read back exactly: ``repr`` with ``.0`` added to a
    mantissa without a dot (``1e-05`` -> ``1.0e-05``; ``repr``'s exponents are signed)."""
    text = repr(float(x))
    mantissa, e, exponent = text.partition("e")
    return text if "." in mantissa or not e else f"{mantissa}.0e{exponent}"


def isaac_yaml(doc: Mapping[str, Any], header: str = "", notes: Mapping[str, str] | None = None) -> str:
    """The YAML text of :func:`isaac_actuator_dict`'s document (``header``: comment lines first; ``notes``:
    a one-line comment after each of the ``joint_names_expr`` entries it names)."""
    notes = notes or {}
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    for field, value in doc.items():
        lines.append(f"{field}:")
        if isinstance(value, Mapping):
            lines += [f"  {json.dumps(k)}: {yaml_float(v)}" for k, v in value.items()]
        else:
            lines += [f"  - {json.dumps(k)}" + (f"  # {notes[k]}" if k in notes else "") for k in value]
    return "\n".join(lines) + "\n"


HEADER = """Isaac Lab actuator parameters (isaaclab.actuators.ActuatorBaseCfg, Isaac Sim >= 5.0) written by wbfriction
from model (3.5): friction = (1 + S) F_c (static), dynamic_friction = F_c, viscous_friction = F_v [N·m·s/rad],
armature [kg·m^2]; the Stribeck velocity, the tanh slope and the torque offset are dropped.
Use: ImplicitActuatorCfg(stiffness=..., damping=..., **yaml.safe_load(open(this_file)))"""


def write_isaac_yaml(path: str | Path, friction: Mapping[str, FrictionLike],
                     armature: Mapping[str, float] | None = None, robot: Robot | None = None) -> None:
    """Write :func:`isaac_actuator_dict` as YAML (:func:`isaac_yaml`, with a header that says the
    mapping and each joint's fit status after its name), atomically.

    Raises:
        what :func:`isaac_actuator_dict` raises; InputError: an output folder that does not exist.
    """
    write_actuators(path, joint_exports(friction, armature, robot))


def write_actuators(path: str | Path, joints: Mapping[str, JointExport]) -> None:
    """:func:`write_isaac_yaml` of the joints' simulator parameters (joint -> :class:`JointExport`,
    :func:`~wbfriction.export.mapping.joint_exports`, in the order written): same errors."""
    notes = {re.escape(name): note for name, exp in joints.items() if (note := status_note(exp)) is not None}
    text = isaac_yaml(_actuator_dict(joints), HEADER, notes)
    write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


class IsaacTarget(ExportTarget):
    """``.yaml``, ``.yml``: an Isaac Lab actuator dictionary (module docstring)."""

    name = "isaac"
    suffixes = (".yaml", ".yml")
    description = "Isaac Lab actuators"

    def write(self, path: Path, robot: Robot, joints: Mapping[str, JointExport]) -> ExportReport:
        """:func:`write_actuators` (``robot`` unused: ``joints`` are already its actuated joints)."""
        write_actuators(path, joints)
        return self.report(path, joints)
