"""The thesis's identification results (Tables 6.1 and 6.2), for side-by-side comparison.

TORO walking straight ahead (Table 6.1) and walking straight and sideways (Table 6.2) in
the OpenHRP simulation; thesis joint numbers 1-6 right leg (hip roll, hip pitch, hip yaw,
knee, ankle roll, ankle pitch), 7-12 left leg. Errors in percent of the target, in the
order of :data:`wbfriction.friction.models.PARAM_NAMES` (F_v, F_c, S, v_s, tau_os, a).
"""

from __future__ import annotations

THESIS_LEG_ORDER = ("hip_roll", "hip_pitch", "hip_yaw", "knee", "ankle_roll", "ankle_pitch")
"""Thesis joint numbering within a leg (Fig. 4.1, Table 4.1): 1/7 hip roll ... 6/12 ankle pitch."""

TABLE_6_1: dict[tuple[str, str], tuple[float, ...]] = {
    ("right", "hip_pitch"): (2.50, 0.37, 0.40, 0.60, 0.35, 1.57),
    ("right", "hip_yaw"): (15.40, 1.29, 5.30, 1.65, 0.40, 1.33),
    ("left", "hip_pitch"): (6.40, 1.08, 0.60, 7.55, 0.67, 5.81),
    ("left", "hip_yaw"): (100.00, 9.79, 44.40, 10.05, 0.51, 1.77),
    ("right", "hip_roll"): (971.75, 56.28, 680.15, 0.30, 0.37, 3.44),
    ("right", "knee"): (0.50, 0.17, 0.65, 1.70, 0.03, 2.21),
    ("left", "hip_roll"): (1125.90, 43.73, 392.30, 22.15, 0.46, 3.09),
    ("left", "knee"): (0.80, 0.32, 1.30, 2.30, 0.09, 3.21),
    ("right", "ankle_roll"): (5.95, 3.50, 17.55, 1.70, 0.50, 0.53),
    ("left", "ankle_roll"): (34.50, 22.00, 94.60, 56.80, 0.70, 6.42),
    ("right", "ankle_pitch"): (0.00, 0.10, 0.05, 0.85, 0.25, 1.06),
    ("left", "ankle_pitch"): (0.00, 0.10, 0.10, 0.65, 0.10, 1.51),
}
"""Table 6.1: parameter errors [%], TORO walking straight ahead."""

TABLE_6_2: dict[tuple[str, str], tuple[float, ...]] = {
    ("right", "hip_pitch"): (0.75, 0.16, 1.40, 1.75, 0.20, 1.11),
    ("right", "hip_yaw"): (9.65, 1.32, 6.50, 4.70, 0.32, 0.86),
    ("left", "hip_pitch"): (1.50, 0.37, 0.15, 6.20, 0.13, 2.50),
    ("left", "hip_yaw"): (9.65, 1.13, 7.00, 1.75, 0.24, 0.02),
    ("right", "hip_roll"): (17.25, 1.35, 5.85, 2.15, 0.31, 1.02),
    ("right", "knee"): (0.05, 0.03, 2.45, 1.60, 0.04, 7.91),
    ("left", "hip_roll"): (17.70, 1.83, 11.95, 0.40, 0.41, 0.76),
    ("left", "knee"): (0.10, 0.11, 1.80, 2.15, 0.04, 8.60),
    ("right", "ankle_roll"): (0.45, 0.50, 2.00, 3.05, 0.50, 0.49),
    ("left", "ankle_roll"): (0.50, 0.60, 3.00, 2.70, 0.40, 0.75),
    ("right", "ankle_pitch"): (0.10, 0.15, 1.30, 0.45, 0.25, 1.39),
    ("left", "ankle_pitch"): (0.10, 0.00, 0.50, 1.15, 0.20, 1.19),
}
"""Table 6.2: parameter errors [%], TORO walking straight and sideways."""


def thesis_number(side: str, group: str) -> int:
    """The thesis's joint number (1-6 right leg, 7-12 left leg) of a leg joint group."""
    return THESIS_LEG_ORDER.index(group) + 1 + (6 if side == "left" else 0)
