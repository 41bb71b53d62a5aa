"""Names of :mod:`wbfriction.export`, imported on first use (:func:`lazy_loader.attach_stub`)."""

from .isaac import IsaacTarget as IsaacTarget
from .isaac import isaac_actuator_dict as isaac_actuator_dict
from .isaac import write_isaac_yaml as write_isaac_yaml
from .mapping import FitSelection as FitSelection
from .mapping import JointExport as JointExport
from .mapping import check_include as check_include
from .mapping import joint_export as joint_export
from .mapping import joint_exports as joint_exports
from .mapping import select_fits as select_fits
from .mapping import status_note as status_note
from .mjcf import MjcfTarget as MjcfTarget
from .mjcf import mujoco_model as mujoco_model
from .mjcf import mujoco_spec as mujoco_spec
from .mjcf import urdf_spec as urdf_spec
from .mjcf import write_mjcf as write_mjcf
from .registry import UnknownExportFormat as UnknownExportFormat
from .registry import register_target as register_target
from .registry import target_for as target_for
from .target import ExportReport as ExportReport
from .target import ExportTarget as ExportTarget
from .urdf import UrdfTarget as UrdfTarget
from .urdf import write_friction_urdf as write_friction_urdf
