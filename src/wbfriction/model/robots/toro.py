"""A TORO-like humanoid, generated from documented numbers (thesis ch. 4, Table 4.1, eq. 5.3).

DLR's TORO has no public model. This module writes a URDF of a robot of its shape and
joint numbering, to rerun the thesis's scenario on a robot of that shape. It is TORO-*like*:
every number below has a source, and where TORO's own number is not public it is a stated
approximation.

**Robot** (thesis 4.1): 79.2 kg, 1.74 m tall, 25 torque-controlled revolute joints (6 per
limb and a waist joint) and 2 position-controlled neck joints.

**Joints** (thesis Fig. 4.1 and Table 4.1). Letters, names, order, velocity limits, torque
limits and ranges come from the table, as :data:`TABLE_4_1`. Per limb the order from the
trunk outwards is the table's:

* leg: A hip roll, B hip pitch, C hip yaw, D knee, E ankle roll, F ankle pitch;
* G waist;
* arm: H-J shoulder 1-3, K elbow, L-M wrist 1-2;
* neck: N yaw, O pitch.

Two ranges are read from a garbled copy of the table:

* hip roll: read "±45 ±90", taken as -45°..+90° (abduction, outwards, positive);
* knee: read "± 105", taken as given.

Joints are addressed by name (the model's own order is Pinocchio's tree traversal, which
takes sibling branches in name order). The thesis's numbers, 1-6 for the right leg's A-F
and 7-12 for the left leg's, come from the joint groups of the built-in robot ``toro``.

**Axes**: at q = 0 the robot stands straight, every frame aligned with the base frame
(x forward, y left, z up).

* Pitch joints turn about +y: hip pitch flexion is negative (range -115°..90°), knee
  flexion positive.
* The elbow turns about -y, so its range 0°..148° is flexion.
* Roll and yaw axes are mirrored on the right side (about -x and -z), so a range means the
  same motion on both sides. For example, shoulder 2 from -15° to 180° is abduction.

**Dimensions and masses: stated approximations.** The overview paper (Englsberger et al.,
"Overview of the torque-controlled humanoid robot TORO", Humanoids 2014) was not available
to this project, so no link length or mass of it is used. Instead, the adult human
proportions of Winter (*Biomechanics and Motor Control of Human Movement*, 4th ed., 2009,
Table 4.1 and Fig. 4.1), scaled to TORO's height ``H`` = 1.74 m and mass ``M`` = 79.2 kg:

* Lengths:
  * ankle height 0.039 H;
  * shank 0.246 H;
  * thigh 0.245 H (hip joints at 0.530 H);
  * shoulder joints at 0.818 H, 0.259 H apart;
  * upper arm 0.186 H, forearm 0.146 H, hand 0.108 H;
  * foot 0.152 H long, 0.055 H wide.
* Masses: foot 0.0145 M, shank 0.0465 M, thigh 0.100 M, upper arm 0.028 M, forearm 0.016 M,
  hand 0.006 M, head and neck 0.081 M, trunk 0.497 M. The trunk is split into pelvis
  0.142 M and thorax-abdomen 0.355 M.
* Centres of mass along each segment (from the proximal joint): thigh and shank 0.433,
  upper arm 0.436, forearm 0.430, hand 0.506 of the length.

Choices of this project (not Winter's, not TORO's):

* hip joints 0.10 H apart (the human pelvis's 0.191 H is its outer width);
* the waist joint 0.10 m above the hip joints;
* the neck joints 0.05 m above the shoulder joints; the head reaches the full height H;
* the sole centred under the ankle, as on most bipeds;
* the links between two joints of a limb (hip roll and pitch, ankle roll, shoulders 1-2,
  wrist 1, neck yaw) are drive units of 0.5 kg (0.3 kg in the neck, 0.2 kg at the wrist),
  taken from the segment they belong to, so the total stays M;
* every segment is a uniform box of the listed size (its inertia, and its collision shape).
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

MASS = 79.2
"""Total mass [kg] (thesis 4.1)."""
HEIGHT = 1.74
"""Height [m], sole to the top of the head, standing straight (thesis 4.1)."""


@dataclass(frozen=True)
class JointSpec:
    """One row of thesis Table 4.1.

    Attributes:
        letter: the joint's letter in Fig. 4.1 (A-O).
        name: joint type (``hip_roll`` ... ``neck_pitch``).
        motor, gear_ratio: drive unit (documentation only).
        velocity: maximum velocity [deg/s].
        torque: maximum torque [N·m].
        lower, upper: range [deg].
    """

    letter: str
    name: str
    motor: str
    gear_ratio: int
    velocity: float
    torque: float
    lower: float
    upper: float


TABLE_4_1: tuple[JointSpec, ...] = (
    JointSpec("A", "hip_roll", "ILM85", 160, 110.0, 176.0, -45.0, 90.0),
    JointSpec("B", "hip_pitch", "ILM70", 160, 157.0, 100.0, -115.0, 90.0),
    JointSpec("C", "hip_yaw", "ILM70", 160, 157.0, 100.0, -120.0, 120.0),
    JointSpec("D", "knee", "ILM85", 100, 176.0, 130.0, -105.0, 105.0),
    JointSpec("E", "ankle_roll", "ILM50", 160, 120.0, 40.0, -19.5, 19.5),
    JointSpec("F", "ankle_pitch", "ILM85", 100, 176.0, 130.0, -45.0, 45.0),
    JointSpec("G", "waist", "ILM70", 160, 157.0, 100.0, -120.0, 120.0),
    JointSpec("H", "shoulder_1", "ILM70", 160, 157.0, 100.0, -120.0, 120.0),
    JointSpec("I", "shoulder_2", "ILM70", 160, 157.0, 100.0, -15.0, 180.0),
    JointSpec("J", "shoulder_3", "ILM50", 160, 120.0, 40.0, -105.0, 105.0),
    JointSpec("K", "elbow", "ILM50", 160, 120.0, 40.0, 0.0, 148.0),
    JointSpec("L", "wrist_1", "ILM50", 160, 120.0, 40.0, -145.0, 118.0),
    JointSpec("M", "wrist_2", "ILM50", 160, 120.0, 40.0, -105.0, 105.0),
    JointSpec("N", "neck_yaw", "MS106T", 225, 270.0, 8.4, -90.0, 90.0),
    JointSpec("O", "neck_pitch", "MS106T", 225, 270.0, 8.4, -30.0, 90.0),
)
"""Thesis Table 4.1, rows A-O (hip roll and knee ranges: module docstring)."""

# Winter (2009) proportions, module docstring
ANKLE_HEIGHT, SHANK, THIGH = 0.039 * HEIGHT, 0.246 * HEIGHT, 0.245 * HEIGHT
HIP_SPACING, SHOULDER_HEIGHT, SHOULDER_SPACING = 0.10 * HEIGHT, 0.818 * HEIGHT, 0.259 * HEIGHT
UPPER_ARM, FOREARM, HAND = 0.186 * HEIGHT, 0.146 * HEIGHT, 0.108 * HEIGHT
FOOT_LENGTH, FOOT_WIDTH = 0.152 * HEIGHT, 0.055 * HEIGHT
HIP_HEIGHT = ANKLE_HEIGHT + SHANK + THIGH
WAIST_ABOVE_HIP, NECK_ABOVE_SHOULDER = 0.10, 0.05
SEGMENT_MASS = {"foot": 0.0145, "shank": 0.0465, "thigh": 0.100, "upper_arm": 0.028, "forearm": 0.016,
                "hand": 0.006, "head": 0.081, "pelvis": 0.142, "torso": 0.355}
"""Winter's segment masses as shares of the total mass (they sum to 1 over both sides)."""
DRIVE = 0.5  # [kg] a drive-unit link between two joints of a limb
RIGHT, LEFT = -1.0, 1.0  # the side's sign of y


@dataclass(frozen=True)
class _Link:
    name: str
    mass: float
    com: tuple[float, float, float]  # [m] in the link frame
    size: tuple[float, float, float]  # [m] box (x, y, z), centred on the centre of mass


@dataclass(frozen=True)
class _Joint:
    name: str
    spec: JointSpec
    parent: str
    child: _Link
    origin: tuple[float, float, float]  # [m] in the parent link frame
    axis: tuple[float, float, float]


def _box_inertia(mass: float, size: tuple[float, float, float]) -> np.ndarray:
    """Principal moments [kg m²] of a uniform box."""
    x, y, z = size
    return mass / 12.0 * np.array([y * y + z * z, x * x + z * z, x * x + y * y])


_SPEC = {s.name: s for s in TABLE_4_1}


def _leg(side: str, s: float, M: float) -> list[_Joint]:
    thigh = SEGMENT_MASS["thigh"] * M - 2 * DRIVE
    shank = SEGMENT_MASS["shank"] * M - DRIVE
    p = f"{side}_"
    drive = (0.08, 0.08, 0.08)
    return [
        _Joint(p + "hip_roll", _SPEC["hip_roll"], "pelvis", _Link(p + "hip_roll_link", DRIVE, (0, 0, 0), drive),
               (0.0, s * HIP_SPACING / 2, 0.0), (s, 0, 0)),
        _Joint(p + "hip_pitch", _SPEC["hip_pitch"], p + "hip_roll_link",
               _Link(p + "hip_pitch_link", DRIVE, (0, 0, 0), drive), (0, 0, 0), (0, 1, 0)),
        _Joint(p + "hip_yaw", _SPEC["hip_yaw"], p + "hip_pitch_link",
               _Link(p + "thigh", thigh, (0, 0, -0.433 * THIGH), (0.12, 0.12, THIGH)), (0, 0, 0), (0, 0, s)),
        _Joint(p + "knee", _SPEC["knee"], p + "thigh",
               _Link(p + "shank", shank, (0, 0, -0.433 * SHANK), (0.10, 0.10, SHANK)), (0, 0, -THIGH), (0, 1, 0)),
        _Joint(p + "ankle_roll", _SPEC["ankle_roll"], p + "shank",
               _Link(p + "ankle_roll_link", DRIVE, (0, 0, 0), (0.06, 0.06, 0.06)), (0, 0, -SHANK), (s, 0, 0)),
        _Joint(p + "ankle_pitch", _SPEC["ankle_pitch"], p + "ankle_roll_link",
               _Link(p + "foot", SEGMENT_MASS["foot"] * M, (0, 0, -ANKLE_HEIGHT / 2),
                     (FOOT_LENGTH, FOOT_WIDTH, ANKLE_HEIGHT)), (0, 0, 0), (0, 1, 0)),
    ]


def _arm(side: str, s: float, M: float) -> list[_Joint]:
    upper = SEGMENT_MASS["upper_arm"] * M - 2 * DRIVE
    fore = SEGMENT_MASS["forearm"] * M - 0.2
    p = f"{side}_"
    drive = (0.07, 0.07, 0.07)
    return [
        _Joint(p + "shoulder_1", _SPEC["shoulder_1"], "torso", _Link(p + "shoulder_1_link", DRIVE, (0, 0, 0), drive),
               (0.0, s * SHOULDER_SPACING / 2, SHOULDER_HEIGHT - HIP_HEIGHT - WAIST_ABOVE_HIP), (0, 1, 0)),
        _Joint(p + "shoulder_2", _SPEC["shoulder_2"], p + "shoulder_1_link",
               _Link(p + "shoulder_2_link", DRIVE, (0, 0, 0), drive), (0, 0, 0), (s, 0, 0)),
        _Joint(p + "shoulder_3", _SPEC["shoulder_3"], p + "shoulder_2_link",
               _Link(p + "upper_arm", upper, (0, 0, -0.436 * UPPER_ARM), (0.08, 0.08, UPPER_ARM)), (0, 0, 0),
               (0, 0, s)),
        _Joint(p + "elbow", _SPEC["elbow"], p + "upper_arm",
               _Link(p + "forearm", fore, (0, 0, -0.430 * FOREARM), (0.07, 0.07, FOREARM)), (0, 0, -UPPER_ARM),
               (0, -1, 0)),
        _Joint(p + "wrist_1", _SPEC["wrist_1"], p + "forearm",
               _Link(p + "wrist_1_link", 0.2, (0, 0, 0), (0.05, 0.05, 0.05)), (0, 0, -FOREARM), (0, 0, s)),
        _Joint(p + "wrist_2", _SPEC["wrist_2"], p + "wrist_1_link",
               _Link(p + "hand", SEGMENT_MASS["hand"] * M, (0, 0, -0.506 * HAND), (0.08, 0.03, HAND)), (0, 0, 0),
               (0, 1, 0)),
    ]


def _tree(M: float = MASS) -> tuple[_Link, list[_Joint]]:
    pelvis = _Link("pelvis", SEGMENT_MASS["pelvis"] * M, (0, 0, 0.03), (0.18, HIP_SPACING + 0.10, 0.16))
    torso_len = SHOULDER_HEIGHT - HIP_HEIGHT - WAIST_ABOVE_HIP + NECK_ABOVE_SHOULDER
    head_len = HEIGHT - SHOULDER_HEIGHT - NECK_ABOVE_SHOULDER
    torso = _Link("torso", SEGMENT_MASS["torso"] * M, (0, 0, torso_len / 2), (0.22, SHOULDER_SPACING - 0.08, torso_len))
    head = SEGMENT_MASS["head"] * M - 0.3
    joints = _leg("right", RIGHT, M) + _leg("left", LEFT, M)
    joints.append(_Joint("waist", _SPEC["waist"], "pelvis", torso, (0, 0, WAIST_ABOVE_HIP), (0, 0, 1)))
    joints += _arm("right", RIGHT, M) + _arm("left", LEFT, M)
    joints += [
        _Joint("neck_yaw", _SPEC["neck_yaw"], "torso", _Link("neck_link", 0.3, (0, 0, 0), (0.06, 0.06, 0.06)),
               (0, 0, torso_len), (0, 0, 1)),
        _Joint("neck_pitch", _SPEC["neck_pitch"], "neck_link",
               _Link("head", head, (0, 0, head_len / 2), (0.20, 0.18, head_len)), (0, 0, 0), (0, 1, 0)),
    ]
    return pelvis, joints


def _fmt(values) -> str:
    return " ".join(f"{float(v):.9g}" for v in values)


def _link_xml(root: ET.Element, link: _Link) -> None:
    node = ET.SubElement(root, "link", name=link.name)
    inertial = ET.SubElement(node, "inertial")
    ET.SubElement(inertial, "origin", xyz=_fmt(link.com), rpy="0 0 0")
    ET.SubElement(inertial, "mass", value=f"{link.mass:.9g}")
    ixx, iyy, izz = _box_inertia(link.mass, link.size)
    ET.SubElement(inertial, "inertia", ixx=f"{ixx:.9g}", ixy="0", ixz="0", iyy=f"{iyy:.9g}", iyz="0", izz=f"{izz:.9g}")
    for tag in ("visual", "collision"):
        geom = ET.SubElement(node, tag)
        ET.SubElement(geom, "origin", xyz=_fmt(link.com), rpy="0 0 0")
        ET.SubElement(ET.SubElement(geom, "geometry"), "box", size=_fmt(link.size))


def toro_urdf() -> str:
    """The TORO-like robot's URDF (module docstring), as text.

    Links: ``pelvis`` (the floating base), the limbs, ``torso`` and ``head``. Joints:
    ``{right,left}_{hip_roll,...,ankle_pitch}``, ``waist``,
    ``{right,left}_{shoulder_1,...,wrist_2}``, ``neck_yaw``, ``neck_pitch``.

    Frames:
    * ``right_sole`` and ``left_sole``: fixed frames on the bottom face of the foot boxes,
      under the ankles (z up);
    * ``head_top``: the highest point of the head.

    Limits are Table 4.1's, in radians.
    """
    pelvis, joints = _tree()
    root = ET.Element("robot", name="toro_like")
    root.append(ET.Comment(" TORO-like humanoid generated by wbfriction.model.robots.toro from documented numbers "
                           "(thesis Table 4.1; Winter 2009 proportions). Not DLR's TORO model. "))
    _link_xml(root, pelvis)
    for j in joints:
        _link_xml(root, j.child)
        node = ET.SubElement(root, "joint", name=j.name, type="revolute")
        ET.SubElement(node, "origin", xyz=_fmt(j.origin), rpy="0 0 0")
        ET.SubElement(node, "parent", link=j.parent)
        ET.SubElement(node, "child", link=j.child.name)
        ET.SubElement(node, "axis", xyz=_fmt(j.axis))
        ET.SubElement(node, "limit", lower=f"{np.radians(j.spec.lower):.9g}", upper=f"{np.radians(j.spec.upper):.9g}",
                      effort=f"{j.spec.torque:.9g}", velocity=f"{np.radians(j.spec.velocity):.9g}")
    for side in ("right", "left"):
        _fixed_frame(root, f"{side}_sole", f"{side}_foot", (0.0, 0.0, -ANKLE_HEIGHT))
    _fixed_frame(root, "head_top", "head", (0.0, 0.0, HEIGHT - SHOULDER_HEIGHT - NECK_ABOVE_SHOULDER))
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"


def _fixed_frame(root: ET.Element, name: str, parent: str, xyz: tuple[float, float, float]) -> None:
    ET.SubElement(root, "link", name=name)
    node = ET.SubElement(root, "joint", name=f"{name}_fixed", type="fixed")
    ET.SubElement(node, "origin", xyz=_fmt(xyz), rpy="0 0 0")
    ET.SubElement(node, "parent", link=parent)
    ET.SubElement(node, "child", link=name)


def toro_urdf_path() -> Path:
    """A file holding :func:`toro_urdf`, written once per content into the user's cache
    (``$XDG_CACHE_HOME/wbfriction``, else ``~/.cache/wbfriction``, else the temporary
    directory), atomically: the same text always has the same path."""
    text = toro_urdf()
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    for base in (os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache", tempfile.gettempdir()):
        folder = Path(base) / "wbfriction"
        path = folder / f"toro_like-{digest}.urdf"
        if path.is_file():
            return path
        try:
            folder.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
            with os.fdopen(fd, "w") as f:
                f.write(text)
            os.replace(tmp, path)
            return path
        except OSError:
            continue
    raise OSError("no writable cache or temporary directory for the TORO-like URDF")
