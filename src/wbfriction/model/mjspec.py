"""A URDF as MuJoCo reads it: the XML tree (:func:`read_urdf`) and the MuJoCo spec of its kinematic tree and
inertias (:func:`urdf_spec`), what the MuJoCo simulator (:mod:`wbfriction.sim.mujoco_model`) and the MJCF export
(:mod:`wbfriction.export.mjcf`) both build on."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from lxml import etree as ET

from wbfriction.exceptions import InputError, ModelError

if TYPE_CHECKING:
    import mujoco


def read_urdf(path: str | Path) -> ET._ElementTree:
    """The URDF's XML tree (lxml: comments kept).

    Raises:
        InputError: a file that cannot be read or is not XML.
    """
    try:
        return ET.parse(str(path))
    except (OSError, ET.XMLSyntaxError) as exc:
        raise InputError(f"{path}: not a readable URDF ({exc})") from None


DROPPED_TAGS = ("gazebo", "transmission", "mujoco")
"""Top-level URDF elements :func:`urdf_spec` removes (simulator extensions; its own ``<mujoco>`` block replaces any)."""


def mujoco_message(exc: Exception) -> str:
    """MuJoCo's message on one line (its parser and compiler add lines such as "Element name '', id 0")."""
    return " ".join(str(exc).split())


def urdf_spec(urdf: str | Path, free_joint: bool = True) -> mujoco.MjSpec:
    """The MuJoCo spec of a URDF's kinematic tree and inertias (built by MuJoCo's own URDF import).

    Visual and collision geometry, ``<dynamics>``, Gazebo, transmission and MuJoCo extension tags
    are removed; of an element a joint repeats (a second ``<origin>``), the first is kept, as
    Pinocchio's parser does. MuJoCo compiles it with ``fusestatic`` (links on fixed joints fused
    into their parent body) and ``balanceinertia`` off (inertias as given).

    Args:
        urdf: the URDF file.
        free_joint: add a free joint at the root link (unless it has one): a floating base.
            Otherwise the root link is welded to the world at the origin.

    Raises:
        InputError: an unreadable URDF.
        ModelError: a URDF MuJoCo cannot read.
    """
    import mujoco
    root = read_urdf(urdf).getroot()
    for link in root.findall("link"):
        for e in [*link.findall("visual"), *link.findall("collision")]:
            link.remove(e)
    for joint in root.findall("joint"):
        seen: set[str] = set()
        for e in list(joint):
            if e.tag == "dynamics" or e.tag in seen:
                joint.remove(e)
            elif isinstance(e.tag, str):
                seen.add(e.tag)
    for e in [e for tag in DROPPED_TAGS for e in root.findall(tag)]:
        root.remove(e)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", discardvisual="true", fusestatic="true", balanceinertia="false")
    try:
        spec = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    except Exception as exc:  # mujoco raises ValueError with its parser's message
        raise ModelError(f"{urdf}: MuJoCo cannot read the URDF: {mujoco_message(exc)}") from None
    base = spec.worldbody.first_body()
    if free_joint and base is not None and not any(j.type == mujoco.mjtJoint.mjJNT_FREE for j in base.joints):
        base.add_freejoint()
    return spec
