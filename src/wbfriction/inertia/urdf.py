"""A URDF with new inertias: the identified model written back in the given one's structure.

Pinocchio merges the links attached by fixed joints into the body of the joint that
carries them (TALOS's arm_left_7_joint carries its wrist sensor and gripper: ten links).
An identified body ``j`` is therefore the sum of several URDF links' inertias. The
corrected URDF keeps every link, joint, mesh and limit; only the ``<inertial>`` of each
joint's child link changes, to the identified body minus the other merged links as the
given URDF has them:

.. math::

    I_{child} = {}^{child}X_j^{*}\\Big(I_j^{id} - \\sum_{l \\ne child} {}^{j}X_l^{*} I_l\\Big)

(inertias as spatial inertias, ``X*`` the force transform of the link's placement in the
joint frame). Reloaded by Pinocchio, the written URDF gives the identified bodies back.
A child link whose share would not be a physical rigid body (the identified body lighter
than the links merged with it) gets the whole body, and the other links' ``<inertial>``
are removed; the table of changes says so.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
from lxml import etree as ET

from wbfriction.exceptions import InputError
from wbfriction.inertia.consistency import is_consistent
from wbfriction.inertia.regressor import body_parameters
from wbfriction.logs.tables import write_atomic
from wbfriction.model.robot import Robot


@dataclass(frozen=True)
class BodyLinks:
    """The URDF links merged into one Pinocchio body.

    Attributes:
        joint: the Pinocchio joint carrying the body.
        child: the joint's child link (for the free flyer, the URDF's root link).
        placements: every merged link's frame in the joint frame (link name -> SE3),
            the child link's included.
    """

    joint: str
    child: str
    placements: dict[str, pin.SE3]


def _parse(path: Path) -> ET.ElementTree:
    try:
        return ET.parse(str(path))
    except (OSError, ET.XMLSyntaxError) as exc:
        raise InputError(f"{path}: not a readable URDF ({exc})") from None


def body_links(robot: Robot, tree: ET.ElementTree | None = None) -> list[BodyLinks]:
    """The links of every body of ``robot`` (joints 1 … njoints-1, model order), from its
    URDF's joints and the model's BODY frames."""
    root = (tree or _parse(robot.urdf)).getroot()
    children = {j.get("name"): j.find("child").get("link") for j in root.findall("joint")}
    child_links = set(children.values())
    roots = [link.get("name") for link in root.findall("link") if link.get("name") not in child_links]
    model = robot.model
    out = []
    for j in range(1, model.njoints):
        name = model.names[j]
        child = children.get(name) or (roots[0] if j == 1 and len(roots) == 1 else None)
        placements = {f.name: f.placement for f in model.frames
                      if f.type == pin.FrameType.BODY and f.parentJoint == j}
        if child is None or child not in placements:
            raise InputError(f"{robot.urdf}: joint '{name}' has no child link in the URDF")
        out.append(BodyLinks(name, child, placements))
    return out


def link_inertia(link: ET.Element) -> pin.Inertia:
    """A URDF ``<link>``'s inertia in the link frame (zero without ``<inertial>``)."""
    el = link.find("inertial")
    if el is None:
        return pin.Inertia.Zero()
    origin = el.find("origin")
    xyz, rpy = ((np.array(origin.get(k, "0 0 0").split(), dtype=float) if origin is not None else np.zeros(3))
                for k in ("xyz", "rpy"))
    mass = float(el.find("mass").get("value"))
    t = {k: float(el.find("inertia").get(k, 0.0)) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    inertia = np.array([[t["ixx"], t["ixy"], t["ixz"]], [t["ixy"], t["iyy"], t["iyz"]], [t["ixz"], t["iyz"], t["izz"]]])
    return pin.SE3(pin.rpy.rpyToMatrix(rpy), xyz).act(pin.Inertia(mass, np.zeros(3), inertia))


def _set_inertial(link: ET.Element, inertia: pin.Inertia | None) -> None:
    """Replace the link's ``<inertial>`` by ``inertia`` (about its centre of mass, axes of the
    link frame), or remove it (None)."""
    old = link.find("inertial")
    index = list(link).index(old) if old is not None else 0
    if old is not None:
        link.remove(old)
    if inertia is None:
        return
    indent = (link.text or "\n    ") + "  "  # one level below the link's children
    el = ET.Element("inertial")
    el.text, el.tail = indent, (old.tail if old is not None else link.text)
    num = lambda x: repr(float(x))  # noqa: E731  (shortest text that reads back to the same float)
    I = inertia.inertia
    for tag, attrs in (("origin", {"xyz": " ".join(num(x) for x in inertia.lever), "rpy": "0 0 0"}),
                       ("mass", {"value": num(inertia.mass)}),
                       ("inertia", {k: num(I[a, b]) for k, (a, b) in (("ixx", (0, 0)), ("ixy", (0, 1)),
                                    ("ixz", (0, 2)), ("iyy", (1, 1)), ("iyz", (1, 2)), ("izz", (2, 2)))})):
        ET.SubElement(el, tag, attrs).tail = indent
    el[-1].tail = indent[:-2]
    link.insert(index, el)


def write_urdf(robot: Robot, pi: np.ndarray, path: str | Path) -> tuple[str, ...]:
    """Write ``robot``'s URDF with body ``j``'s inertia from row ``j - 1`` of ``pi``
    (n_bodies, 10; :func:`wbfriction.inertia.regressor.body_parameters` order, about the joint
    frame), atomically. Everything but the child links' ``<inertial>`` is kept.

    Returns:
        the joints whose whole body went to the child link, the other merged links'
        inertials removed (the module docstring).

    Raises:
        InputError: the URDF cannot be read, or a joint has no child link in it.
    """
    tree = _parse(robot.urdf)
    links = {link.get("name"): link for link in tree.getroot().findall("link")}
    moved = []
    given = body_parameters(robot.model)
    for b, body in enumerate(body_links(robot, tree)):
        if np.array_equal(pi[b], given[b]):
            continue  # unchanged: the URDF's own text kept
        others = [name for name in body.placements if name != body.child]
        rest = np.asarray(pi[b], dtype=float) - sum(
            (body.placements[name].act(link_inertia(links[name])).toDynamicParameters() for name in others),
            np.zeros(10))
        if others and not is_consistent(rest[None], 1e-12)[0]:
            moved.append(body.joint)
            for name in others:
                _set_inertial(links[name], None)
            rest = np.asarray(pi[b], dtype=float)
        X = body.placements[body.child].inverse()
        _set_inertial(links[body.child], X.act(pin.Inertia.FromDynamicParameters(rest)))
    root = tree.getroot()
    siblings = reversed(list(root.itersiblings(preceding=True)))
    prolog = [ET.tostring(node, encoding="unicode").strip() for node in siblings]
    text = "\n".join(['<?xml version="1.0" encoding="utf-8"?>', *prolog, ET.tostring(root, encoding="unicode")]) + "\n"
    write_atomic(Path(path), lambda tmp: tmp.write_text(text, encoding="utf-8"))
    return tuple(moved)


@dataclass(frozen=True)
class BodyChange:
    """How one body changed (:func:`inertia_changes`).

    Attributes:
        body: joint carrying the body.
        mass_given, mass: [kg].
        com_shift: displacement of the centre of mass [m].
        moments_given, moments: principal moments of inertia about the centre of mass,
            ascending [kg·m^2] (3,).
    """

    body: str
    mass_given: float
    mass: float
    com_shift: float
    moments_given: np.ndarray
    moments: np.ndarray

    @property
    def mass_change(self) -> float:
        """Relative change of the mass (nan for a massless given body)."""
        return self.mass / self.mass_given - 1.0 if self.mass_given > 0 else float("nan")

    @property
    def moments_change(self) -> np.ndarray:
        """Relative change of each principal moment (3,)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return self.moments / self.moments_given - 1.0


def _com_and_moments(p: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """A body's mass [kg], centre of mass [m] and principal moments about it [kg·m^2] (ascending) from its dynamic
    parameters ``p`` (10,) (Pinocchio's order: ``m, m c, I`` about the body frame's origin). A massless body (a URDF
    may give one) has its centre of mass at the origin and its moments about it (issue 53: ``LinAlgError`` after
    the identification's work)."""
    if p[0] > 0:
        inertia = pin.Inertia.FromDynamicParameters(p)
        return float(inertia.mass), np.asarray(inertia.lever), np.linalg.eigvalsh(inertia.inertia)
    I = np.array([[p[4], p[5], p[7]], [p[5], p[6], p[8]], [p[7], p[8], p[9]]])
    return float(p[0]), np.zeros(3), np.linalg.eigvalsh(I)


def inertia_changes(bodies: tuple[str, ...] | list[str], pi_given: np.ndarray, pi: np.ndarray) -> list[BodyChange]:
    """Per body, the given and identified mass, centre-of-mass shift and principal moments
    (``pi_given``, ``pi``: (n_bodies, 10) as in :func:`write_urdf`; a massless body's centre of mass at its frame's
    origin)."""
    out = []
    for name, p0, p1 in zip(bodies, pi_given, pi):
        (m0, c0, I0), (m1, c1, I1) = _com_and_moments(np.asarray(p0)), _com_and_moments(np.asarray(p1))
        out.append(BodyChange(name, m0, m1, float(np.linalg.norm(c1 - c0)), I0, I1))
    return out
