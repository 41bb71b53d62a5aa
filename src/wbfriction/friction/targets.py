"""Friction parameters per joint: the thesis's targets by joint group, and the user's TOML files.

The simulators inject these (:mod:`wbfriction.sim`); the studies compare the fits with them.
"""

from __future__ import annotations

from pathlib import Path

from wbfriction.config import toml_table
from wbfriction.exceptions import InputError
from wbfriction.friction.models import FrictionParams, ModelParams, target_from_dict

THESIS_TARGETS: dict[str, FrictionParams] = {
    "hip_pitch": FrictionParams(F_v=0.2, F_c=0.8, S=0.2, v_s=0.2, tau_os=0.8, a=40.0),
    "hip_yaw": FrictionParams(F_v=0.2, F_c=0.8, S=0.2, v_s=0.2, tau_os=0.8, a=40.0),
    "hip_roll": FrictionParams(F_v=0.2, F_c=1.0, S=0.2, v_s=0.2, tau_os=1.0, a=40.0),
    "knee": FrictionParams(F_v=0.2, F_c=1.0, S=0.2, v_s=0.2, tau_os=1.0, a=40.0),
    "ankle_roll": FrictionParams(F_v=0.2, F_c=0.1, S=0.2, v_s=0.2, tau_os=0.1, a=40.0),
    "ankle_pitch": FrictionParams(F_v=0.2, F_c=0.2, S=0.2, v_s=0.2, tau_os=0.2, a=40.0),
}
"""The thesis's target friction per joint group (Table 6.1), injected in simulation."""


def friction_by_group(groups: dict[str, tuple[str, ...]],
                      targets: dict[str, FrictionParams] = THESIS_TARGETS) -> dict[str, FrictionParams]:
    """Per-joint friction parameters from per-group ones (joints of groups not in ``targets``: none)."""
    return {joint: targets[g] for g, joints in groups.items() if g in targets for joint in joints}


def load_friction_toml(path: str | Path, groups: dict[str, tuple[str, ...]],
                       joints: tuple[str, ...]) -> dict[str, ModelParams]:
    """Friction parameters per joint from a TOML file.

    Each table under ``[friction]`` is named after a joint group or a joint and gives the
    parameters of (3.5), or of the model its ``model`` key names (``coulomb-viscous``: F_v, F_c, tau_os;
    ``stribeck``: F_v, F_c, F_s, v_s, tau_os); missing ones take the model's defaults. A joint's
    own table overrides its group's::

        [friction.knee]
        F_v = 0.2
        F_c = 1.0
        [friction.leg_right_4_joint]
        model = "coulomb-viscous"
        F_c = 1.5

    Raises:
        InputError: unreadable file, an unknown group, joint, model or parameter.
    """
    table = toml_table(path, "friction")
    out: dict[str, ModelParams] = {}
    for is_group in (True, False):  # groups first, joints override
        for name, values in table.items():
            if (name in groups) != is_group:
                continue
            if not is_group and name not in joints:
                raise InputError(f"{path}: [friction.{name}] names neither a joint group nor a joint")
            try:
                params = target_from_dict(values) if isinstance(values, dict) else FrictionParams.from_dict(values)
            except InputError as exc:
                raise InputError(f"{path}: [friction.{name}]: {exc}") from exc
            for joint in (groups[name] if is_group else (name,)):
                out[joint] = params
    return out
