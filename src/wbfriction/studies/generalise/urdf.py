"""The URDFs of the generalisation benchmark: random serial chains (:func:`chain_urdf`), and a URDF's inertial
parameters perturbed (:func:`perturbed_urdf`): the model the tool is given is not the one simulated.

Frames and units: URDF's (metres, kilograms, kg·m² about the link's centre of mass in the ``<inertial>`` frame).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from lxml import etree as ET

from wbfriction.model.mjspec import read_urdf

CHAIN_LIMIT = 2.6
"""Each random chain's joint range, ``±`` [rad]."""
CHAIN_VELOCITY = 3.0
"""Each random chain's joint velocity limit [rad/s]."""


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random rotation matrix (3, 3) (QR of a Gaussian matrix, signs fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def _fmt(x) -> str:
    return " ".join(f"{float(v):.9g}" for v in np.atleast_1d(x))


def _inertial(link: ET._Element, mass: float, com: np.ndarray, inertia: np.ndarray) -> None:
    node = ET.SubElement(link, "inertial")
    ET.SubElement(node, "origin", xyz=_fmt(com), rpy="0 0 0")
    ET.SubElement(node, "mass", value=f"{mass:.9g}")
    ET.SubElement(node, "inertia", ixx=f"{inertia[0, 0]:.9g}", ixy=f"{inertia[0, 1]:.9g}",
                  ixz=f"{inertia[0, 2]:.9g}", iyy=f"{inertia[1, 1]:.9g}", iyz=f"{inertia[1, 2]:.9g}",
                  izz=f"{inertia[2, 2]:.9g}")


def chain_urdf(rng: np.random.Generator, n_joints: int, name: str = "chain") -> tuple[str, tuple[str, ...]]:
    """A random serial chain of ``n_joints`` revolute joints welded to the world at ``base_link`` (a fixed-base arm).

    Each link ``i`` is a box of length 0.1-0.45 m along a random direction, cross-section 0.04-0.1 m, mass 0.5-4 kg
    (less outward), its centre of mass near the box's middle (within 2 cm), its inertia the box's about its centre
    rotated into the link's frame (so physically valid: positive, triangle inequality); the next joint sits at the
    box's end, its axis a principal axis (60 %) or a random unit vector. Ranges ``±``:data:`CHAIN_LIMIT`, velocity
    limit :data:`CHAIN_VELOCITY`, effort 300 N·m.

    Returns:
        the URDF's text and the joint names in chain order.
    """
    root = ET.Element("robot", name=name)
    base = ET.SubElement(root, "link", name="base_link")
    _inertial(base, 5.0, np.zeros(3), np.eye(3) * 0.05)
    parent, origin, joints = "base_link", np.array([0.0, 0.0, 0.1]), []
    for i in range(n_joints):
        link_name, joint_name = f"link{i + 1}", f"joint{i + 1}"
        axis = np.eye(3)[rng.integers(3)] if rng.uniform() < 0.6 else rng.normal(size=3)
        axis = axis / np.linalg.norm(axis)
        joint = ET.SubElement(root, "joint", name=joint_name, type="revolute")
        ET.SubElement(joint, "parent", link=parent)
        ET.SubElement(joint, "child", link=link_name)
        ET.SubElement(joint, "origin", xyz=_fmt(origin), rpy="0 0 0")
        ET.SubElement(joint, "axis", xyz=_fmt(axis))
        ET.SubElement(joint, "limit", lower=f"{-CHAIN_LIMIT}", upper=f"{CHAIN_LIMIT}", effort="300",
                      velocity=f"{CHAIN_VELOCITY}")
        length = rng.uniform(0.1, 0.45)
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        mass = rng.uniform(0.5, 4.0) * (1.0 - 0.1 * i)
        width, depth = rng.uniform(0.04, 0.1, size=2)
        dims = np.array([length, width, depth])
        box = mass / 12.0 * np.diag([dims[1] ** 2 + dims[2] ** 2, dims[0] ** 2 + dims[2] ** 2,
                                     dims[0] ** 2 + dims[1] ** 2])
        # the box's long axis along ``direction``: a rotation taking x to it, then a random roll about it
        x = direction
        y = np.cross(x, rng.normal(size=3))
        y /= np.linalg.norm(y)
        rot = np.column_stack([x, y, np.cross(x, y)])
        end = direction * length
        com = 0.5 * end + rng.uniform(-0.02, 0.02, size=3)
        link = ET.SubElement(root, "link", name=link_name)
        _inertial(link, mass, com, rot @ box @ rot.T)
        joints.append(joint_name)
        parent, origin = link_name, end
    return ET.tostring(root, pretty_print=True, encoding="unicode"), tuple(joints)


def fixed_joints(text: str, joints: tuple[str, ...]) -> str:
    """A URDF's text with ``joints`` made ``fixed`` at their zero (a Panda's fingers, which the benchmark neither
    simulates nor identifies)."""
    root = ET.fromstring(text.encode())
    for joint in root.findall("joint"):
        if joint.get("name") in joints:
            joint.set("type", "fixed")
            for tag in ("axis", "limit", "dynamics", "mimic"):
                for e in joint.findall(tag):
                    joint.remove(e)
    return ET.tostring(root, pretty_print=True, encoding="unicode")


def perturbed_urdf(text: str, share: float, rng: np.random.Generator) -> tuple[str, dict[str, float]]:
    """The URDF ``text`` with every link's mass, centre of mass and inertia off by ``share`` (0-1): the mass times
    ``1 ± share``, each centre-of-mass coordinate times ``1 ± share``, the inertia tensor times ``1 ± share`` (one
    factor: it stays physically valid), each sign drawn from ``rng``; links of zero mass untouched.

    Returns:
        the perturbed URDF's text and each link's mass factor (given / simulated).
    """
    root = ET.fromstring(text.encode())
    factors = {}
    for link in root.findall("link"):
        inertial = link.find("inertial")
        mass = None if inertial is None else inertial.find("mass")
        if mass is None or float(mass.get("value")) <= 0:
            continue
        f_m, f_i = (1.0 + share * rng.choice([-1.0, 1.0]) for _ in range(2))
        mass.set("value", f"{float(mass.get('value')) * f_m:.12g}")
        factors[link.get("name")] = float(f_m)
        origin = inertial.find("origin")
        if origin is not None and origin.get("xyz"):
            com = np.array([float(v) for v in origin.get("xyz").split()])
            origin.set("xyz", _fmt(com * (1.0 + share * rng.choice([-1.0, 1.0], size=3))))
        inertia = inertial.find("inertia")
        if inertia is not None:
            for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                if inertia.get(key) is not None:
                    inertia.set(key, f"{float(inertia.get(key)) * f_i:.12g}")
    return ET.tostring(root, pretty_print=True, encoding="unicode"), factors


def link_masses(path: str | Path) -> dict[str, float]:
    """Each link's mass [kg] in a URDF file (links without an ``<inertial>`` left out)."""
    out = {}
    for link in read_urdf(path).getroot().findall("link"):
        mass = link.find("inertial/mass")
        if mass is not None:
            out[link.get("name")] = float(mass.get("value"))
    return out
