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


MESH_SUFFIXES = (".stl", ".obj", ".msh")
"""The mesh files MuJoCo reads (its URDF import loads them by suffix; not Collada ``.dae``)."""


def resolve_mesh(filename: str, urdf: str | Path) -> Path | None:
    """A URDF mesh path as a file: ``package://<package>/<path>`` searched in the folders above ``urdf`` (a
    package's tree, example-robot-data's ``robots/<robot>/...``), a relative path from ``urdf``'s folder, an
    absolute one as it is; None where no such file is."""
    if filename.startswith("package://"):
        rel = filename[len("package://"):]
        for parent in Path(urdf).resolve().parents:
            for candidate in (parent / rel, parent / rel.split("/", 1)[-1]):
                if candidate.is_file():
                    return candidate
        return None
    if filename.startswith("file://"):
        filename = filename[len("file://"):]
    path = (Path(urdf).resolve().parent / filename).resolve()
    return path if path.is_file() else None


def keep_collision_geometry(root: ET._Element, urdf: str | Path) -> tuple[str, ...]:
    """Prepare a URDF tree (in place) for MuJoCo's import with geometry: every ``<visual>`` removed, every
    ``<collision>`` kept (boxes, cylinders, spheres; meshes at their absolute path, :func:`resolve_mesh` from
    ``urdf``), but for a mesh MuJoCo cannot read (:data:`MESH_SUFFIXES`) or that is not found.

    Returns:
        the collision elements removed, one ``"<link>: <file> (<why>)"`` each.
    """
    skipped: list[str] = []
    for link in root.findall("link"):
        for e in link.findall("visual"):
            link.remove(e)
        for e in link.findall("collision"):
            mesh = e.find("geometry/mesh")
            if mesh is None:
                continue
            filename = mesh.get("filename") or ""
            path = resolve_mesh(filename, urdf)
            if path is None or path.suffix.lower() not in MESH_SUFFIXES:
                why = "not found" if path is None else f"MuJoCo reads {', '.join(MESH_SUFFIXES)} meshes only"
                skipped.append(f"{link.get('name')}: {filename} ({why})")
                link.remove(e)
            else:
                mesh.set("filename", str(path))
    return tuple(skipped)


def urdf_spec(urdf: str | Path, free_joint: bool = True, *, geometry_from: str | Path | None = None,
              dynamics: bool = False) -> mujoco.MjSpec:
    """The MuJoCo spec of a URDF's kinematic tree and inertias (built by MuJoCo's own URDF import).

    Visual and collision geometry, ``<dynamics>``, Gazebo, transmission and MuJoCo extension tags
    are removed; of an element a joint repeats (a second ``<origin>``), the first is kept, as
    Pinocchio's parser does. MuJoCo compiles it with ``fusestatic`` (links on fixed joints fused
    into their parent body) and ``balanceinertia`` off (inertias as given); with the geometry, ``inertiafromgeom``
    off (the geometry adds no mass: a link's inertia is its ``<inertial>``, none without).

    Args:
        urdf: the URDF file.
        free_joint: add a free joint at the root link (unless it has one): a floating base.
            Otherwise the root link is welded to the world at the origin.
        geometry_from: keep the collision geometry (:func:`keep_collision_geometry`), its meshes found from this
            URDF's place (``urdf`` itself, or the file it was written from); None: no geometry.
        dynamics: keep the joints' ``<dynamics>`` (MuJoCo's import: ``damping``, ``friction`` as ``frictionloss``).

    Raises:
        InputError: an unreadable URDF.
        ModelError: a URDF MuJoCo cannot read.
    """
    return _urdf_spec(urdf, free_joint, geometry_from, dynamics)[0]


def urdf_model_spec(urdf: str | Path, free_joint: bool = True, geometry_from: str | Path | None = None
                    ) -> tuple[mujoco.MjSpec, tuple[str, ...]]:
    """:func:`urdf_spec` with the collision geometry (meshes found from ``geometry_from``, default ``urdf``; the
    joints' ``<dynamics>`` dropped), and the collision elements skipped (:func:`keep_collision_geometry`)."""
    return _urdf_spec(urdf, free_joint, urdf if geometry_from is None else geometry_from, False)


def _urdf_spec(urdf: str | Path, free_joint: bool, geometry_from: str | Path | None,
               dynamics: bool) -> tuple[mujoco.MjSpec, tuple[str, ...]]:
    """:func:`urdf_spec` and the collision elements skipped."""
    import mujoco
    root = read_urdf(urdf).getroot()
    skipped: tuple[str, ...] = ()
    if geometry_from is None:
        for link in root.findall("link"):
            for e in [*link.findall("visual"), *link.findall("collision")]:
                link.remove(e)
    else:
        skipped = keep_collision_geometry(root, geometry_from)
    for joint in root.findall("joint"):
        seen: set[str] = set()
        for e in list(joint):
            if (e.tag == "dynamics" and not dynamics) or e.tag in seen:
                joint.remove(e)
            elif isinstance(e.tag, str):
                seen.add(e.tag)
    for e in [e for tag in DROPPED_TAGS for e in root.findall(tag)]:
        root.remove(e)
    extension = ET.SubElement(root, "mujoco")
    compiler = ET.SubElement(extension, "compiler", discardvisual="true", fusestatic="true", balanceinertia="false")
    if geometry_from is not None:
        compiler.set("inertiafromgeom", "false")
    try:
        spec = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    except Exception as exc:  # mujoco raises ValueError with its parser's message
        raise ModelError(f"{urdf}: MuJoCo cannot read the URDF: {mujoco_message(exc)}") from None
    base = spec.worldbody.first_body()
    if free_joint and base is not None and not any(j.type == mujoco.mjtJoint.mjJNT_FREE for j in base.joints):
        base.add_freejoint()
    return spec, skipped
