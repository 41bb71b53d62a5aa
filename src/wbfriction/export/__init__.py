"""Exports of the identified friction and armature to where users simulate: the mapping of model
(3.5) to simulator fields (:mod:`.mapping`), the URDF's ``<dynamics>`` (:mod:`.urdf`), a MuJoCo
model (:mod:`.mjcf`) and an Isaac Lab actuator dictionary as YAML (:mod:`.isaac`)."""

from wbfriction.export.isaac import isaac_actuator_dict, write_isaac_yaml
from wbfriction.export.mapping import JointExport, joint_export, joint_exports
from wbfriction.export.mjcf import mujoco_model, mujoco_spec, urdf_spec, write_mjcf
from wbfriction.export.urdf import write_friction_urdf

__all__ = ["JointExport", "isaac_actuator_dict", "joint_export", "joint_exports", "mujoco_model", "mujoco_spec",
           "urdf_spec", "write_friction_urdf", "write_isaac_yaml", "write_mjcf"]
