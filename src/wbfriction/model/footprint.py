"""The footprint of a robot's sole, read from its URDF: the rectangle under a contact frame that the bottom of the
foot's collision geometry (a binary STL mesh, from the installed robot package, or a box) covers, in the frame's
axes. MuJoCo's sole boxes are built on it (:mod:`wbfriction.sim.mujoco_model`), and the standing references put the
centre of mass over it (:mod:`wbfriction.walking.single_support`, :mod:`wbfriction.excite.one_foot`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import cast

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import ModelError
from wbfriction.model.mjspec import resolve_mesh
from wbfriction.model.robot import Robot


def _read_stl(path: Path) -> np.ndarray:
    """Vertices (3 n, 3) of a binary STL file."""
    data = path.read_bytes()
    n = int(np.frombuffer(data[80:84], np.uint32)[0])
    tri = np.frombuffer(data[84:84 + 50 * n], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    return tri["v"].reshape(-1, 3).astype(float)


def sole_footprint(robot: Robot, frame: str, urdf_root: ET.Element | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Rectangle under a contact frame: centre (x, y) and half sizes (x, y) [m], in the frame.

    Read from the collision geometry (a binary STL mesh or a box) of the link the frame
    hangs on: the bounding box, in the frame's axes, of the vertices within 1 cm of the
    lowest one.

    Raises:
        ModelError: no collision mesh or box to read.
    """
    root = ET.parse(robot.urdf).getroot() if urdf_root is None else urdf_root
    model = robot.model
    fr = model.frames[model.getFrameId(frame)]
    link = model.frames[fr.parentFrame]
    while link.type != pin.FrameType.BODY and link.parentFrame != 0:  # the link carrying the frame
        link = model.frames[link.parentFrame]
    for node in root.findall("link"):
        if node.get("name") != link.name:
            continue
        for col in node.findall("collision"):
            v = _collision_vertices(col, robot.urdf)
            if v is None:
                continue
            link_to_frame = link.placement.actInv(fr.placement)  # frame pose in the link
            v = (v - link_to_frame.translation) @ link_to_frame.rotation  # in the contact frame
            low = v[v[:, 2] < v[:, 2].min() + 0.01]
            lo, hi = low[:, :2].min(axis=0), low[:, :2].max(axis=0)
            return (lo + hi) / 2, (hi - lo) / 2
    raise ModelError(f"no collision mesh or box on link '{link.name}' to size the sole of '{frame}'")


def _collision_vertices(col: ET.Element, urdf: Path) -> np.ndarray | None:
    """Vertices (n, 3) of a URDF collision element in its link's frame: a binary STL mesh's,
    or a box's corners; None for other shapes."""
    # a mesh's filename and a box's size are required by URDF (cast, not checked: a missing one fails on None)
    mesh, box = col.find("geometry/mesh"), col.find("geometry/box")
    if mesh is not None:
        scale = np.array([float(s) for s in (mesh.get("scale") or "1 1 1").split()])
        v = _read_stl(_resolve_mesh(cast(str, mesh.get("filename")), urdf)) * scale
    elif box is not None:
        half = np.array([float(s) for s in cast(str, box.get("size")).split()]) / 2
        v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    else:
        return None
    origin = col.find("origin")
    xyz = np.array([float(s) for s in ((origin.get("xyz") if origin is not None else None) or "0 0 0").split()])
    rpy = np.array([float(s) for s in ((origin.get("rpy") if origin is not None else None) or "0 0 0").split()])
    return v @ pin.rpy.rpyToMatrix(*rpy).T + xyz


def _resolve_mesh(filename: str, urdf: Path) -> Path:
    """A URDF mesh path as a file (:func:`~wbfriction.model.mjspec.resolve_mesh`); ModelError where none is."""
    path = resolve_mesh(filename, urdf)
    if path is None:
        raise ModelError(f"mesh '{filename}' not found above {urdf}")
    return path
