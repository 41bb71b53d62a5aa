"""The text of a MuJoCo model (MJCF) at full precision, as :func:`~wbfriction.export.mjcf.write_mjcf` writes it.

The written MJCF (:func:`~wbfriction.export.mjcf.write_mjcf`) is MuJoCo's own ``MjSpec.to_xml``, whose numbers have 6
significant digits, with every number of the bodies, inertials, joints and sites rewritten from the
compiled model at full precision (and the frames MuJoCo writes for fused links folded into the
bodies' placements), and its sibling bodies in the robot model's joint order: it reloads to the same
model, and Pinocchio reads it (``wbfriction ... --mjcf``) with the joints in the URDF model's order and
the same mass matrix and gravity to rounding.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from lxml import etree as ET

from wbfriction.exceptions import ModelError

if TYPE_CHECKING:
    import mujoco


def _num(values) -> str:
    """Numbers as the shortest text that reads back to the same doubles."""
    return " ".join(repr(float(x)) for x in np.atleast_1d(values))


def _vector(element: ET._Element, key: str, default: Sequence[float]) -> np.ndarray:
    text = element.get(key)
    return np.array(default if text is None else [float(x) for x in text.split()], dtype=float)


def _unwrap_frames(root: ET._Element) -> None:
    """Replace every ``<frame>`` by its children (deepest first), the frame's placement composed into each child
    ``<geom>``'s and ``<site>``'s: the bodies' placements (and sites') are then set from the compiled model,
    relative to their parent body."""
    import mujoco
    for frame in reversed(list(root.iter("frame"))):
        parent = frame.getparent()
        index = parent.index(frame)
        pos, quat = _vector(frame, "pos", (0, 0, 0)), _vector(frame, "quat", (1, 0, 0, 0))
        turn = np.zeros(9)
        mujoco.mju_quat2Mat(turn, quat / np.linalg.norm(quat))
        for child in reversed(list(frame)):
            if child.tag in ("geom", "site"):
                q = np.zeros(4)
                mujoco.mju_mulQuat(q, quat / np.linalg.norm(quat), _vector(child, "quat", (1, 0, 0, 0)))
                child.set("pos", _num(pos + turn.reshape(3, 3) @ _vector(child, "pos", (0, 0, 0))))
                child.set("quat", _num(q))
            parent.insert(index, child)
        parent.remove(frame)


def _order_bodies(root: ET._Element, joints: Sequence[str]) -> bool:
    """Put the sibling ``<body>`` elements in the order of ``joints`` (each ranked by the first of its
    subtree's joints; bodies after the other children), so that a depth-first reader (MuJoCo, Pinocchio)
    meets the joints in that order. Returns whether anything moved."""
    rank = {name: i for i, name in enumerate(joints)}

    def key(body: ET._Element) -> int:
        return min((rank.get(j.get("name") or "", len(rank)) for j in body.iter("joint")), default=len(rank))

    moved = False
    for parent in [*root.iter("worldbody"), *root.iter("body")]:
        children = [c for c in parent if c.tag == "body"]
        ordered = sorted(children, key=key)
        if ordered != children:
            moved = True
            for child in children:
                parent.remove(child)
            parent.extend(ordered)
    return moved


def mjcf_xml(spec: mujoco.MjSpec, model: mujoco.MjModel, joints: Sequence[str] = (),
             notes: Mapping[str, str] | None = None, actuators: Sequence[str] = (),
             actuator_note: str | None = None) -> str:
    """The MJCF text of ``spec`` (compiled as ``model``) at full precision (module docstring): the
    bodies' ``pos``, ``quat`` and ``<inertial>``, the joints' ``pos``, ``axis``, ``range``,
    ``actuatorfrcrange``, ``damping``, ``frictionloss`` and ``armature``, the sites' ``pos`` and ``quat``
    from ``model``; sibling bodies in the order of the joint names ``joints`` (:func:`_order_bodies`);
    ``notes`` (joint -> one line) as a comment before each joint named; the ``gainprm``, ``biasprm``,
    ``forcerange`` and ``delay`` of the actuators named in ``actuators`` from ``model``, ``actuator_note`` as a
    comment at the top of ``<actuator>``.

    Raises:
        ModelError: a body or joint of the text that ``model`` does not have by name.
    """
    import mujoco
    root = ET.fromstring(spec.to_xml().encode())
    _unwrap_frames(root)

    def ident(kind: mujoco.mjtObj, name: str | None) -> int:
        i = mujoco.mj_name2id(model, kind, name or "")
        if i < 0:
            raise ModelError(f"the MJCF's {kind.name} '{name}' is not in the compiled model")
        return i

    for body in root.iter("body"):
        b = ident(mujoco.mjtObj.mjOBJ_BODY, body.get("name"))
        body.set("pos", _num(model.body_pos[b]))
        body.set("quat", _num(model.body_quat[b]))
        inertial = body.find("inertial")
        if inertial is not None:
            for key in ("fullinertia", "diaginertia"):
                inertial.attrib.pop(key, None)
            inertial.set("pos", _num(model.body_ipos[b]))
            inertial.set("quat", _num(model.body_iquat[b]))
            inertial.set("mass", _num(model.body_mass[b]))
            inertial.set("diaginertia", _num(model.body_inertia[b]))
        for joint in body.findall("joint"):
            if joint.get("type") == "free":
                continue
            j = ident(mujoco.mjtObj.mjOBJ_JOINT, joint.get("name"))
            dof = model.jnt_dofadr[j]
            joint.set("pos", _num(model.jnt_pos[j]))
            joint.set("axis", _num(model.jnt_axis[j]))
            if "range" in joint.attrib:
                joint.set("range", _num(model.jnt_range[j]))
            if "actuatorfrcrange" in joint.attrib:
                joint.set("actuatorfrcrange", _num(model.jnt_actfrcrange[j]))
            poly = model.dof_dampingpoly[dof]
            joint.set("damping", _num([model.dof_damping[dof], *poly] if np.any(poly) else model.dof_damping[dof]))
            joint.set("frictionloss", _num(model.dof_frictionloss[dof]))
            joint.set("armature", _num(model.dof_armature[dof]))
            note = (notes or {}).get(joint.get("name") or "")
            if note is not None:
                joint.addprevious(ET.Comment(f" {note} "))
        for site in body.findall("site"):
            if site.get("name"):
                s = ident(mujoco.mjtObj.mjOBJ_SITE, site.get("name"))
                site.set("pos", _num(model.site_pos[s]))
                site.set("quat", _num(model.site_quat[s]))
    _order_bodies(root, joints)
    _actuators_in_full(root, model, actuators, actuator_note)
    _keys_in_full(root, model)
    ET.indent(root, "  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def _trimmed(values: np.ndarray) -> np.ndarray:
    """``values`` without their trailing zeros (at least one kept), as MuJoCo's writer spells a parameter array."""
    nonzero = np.flatnonzero(values)
    return values[: max(1, nonzero[-1] + 1 if nonzero.size else 1)]


def _actuators_in_full(root: ET._Element, model: mujoco.MjModel, names: Sequence[str], note: str | None) -> None:
    """Rewrite the numbers of the actuators ``names`` (``gainprm``, ``biasprm``, ``delay``) and every actuator's
    ``ctrlrange`` and ``forcerange`` from ``model`` at full precision, and put ``note`` at the top of ``<actuator>``
    (:func:`mjcf_xml`)."""
    import mujoco
    section = root.find("actuator")
    if section is None:
        return
    for element in section:
        name = element.get("name")
        if element.tag is ET.Comment or not name:
            continue
        a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        for key, values in (("ctrlrange", model.actuator_ctrlrange), ("forcerange", model.actuator_forcerange)):
            if key in element.attrib:
                element.set(key, _num(values[a]))
        if name not in names:
            continue
        element.set("gainprm", _num(_trimmed(model.actuator_gainprm[a])))
        element.set("biasprm", _num(_trimmed(model.actuator_biasprm[a])))
        if "delay" in element.attrib:
            element.set("delay", _num(model.actuator_delay[a]))
    if note is not None and names:
        section.insert(0, ET.Comment(note))


def _keys_in_full(root: ET._Element, model: mujoco.MjModel) -> None:
    """Rewrite each keyframe's ``qpos`` and ``ctrl`` from ``model`` at full precision, ``qpos`` in the order of the
    text's joints (its bodies may be reordered: :func:`_order_bodies`) (:func:`mjcf_xml`)."""
    import mujoco
    sizes = {int(mujoco.mjtJoint.mjJNT_FREE): 7, int(mujoco.mjtJoint.mjJNT_BALL): 4}
    free = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
    order = []
    for element in root.find("worldbody").iter("joint", "freejoint"):
        name = element.get("name")
        order.append(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) if name else free.pop(0))
    for key in root.iter("key"):
        k = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, key.get("name") or "")
        if k >= 0:
            qpos = [model.key_qpos[k, model.jnt_qposadr[j]:model.jnt_qposadr[j] + sizes.get(int(model.jnt_type[j]), 1)]
                    for j in order]
            key.set("qpos", _num(np.concatenate(qpos) if qpos else model.key_qpos[k]))
            if model.nu:
                key.set("ctrl", _num(model.key_ctrl[k]))
