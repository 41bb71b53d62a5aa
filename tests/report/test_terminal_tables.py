"""The terminal's tables (issue 67): within a 100-column terminal and using it, a unit in every parameter column's
header, the joints by their names, and the joints that carry no information (not excited) folded into one line
that names every one of them, their rows back with ``--wide``."""

from __future__ import annotations

import re

import numpy as np
import pytest
from rich.console import Console

from wbfriction.fit.selection import fit_friction
from wbfriction.friction.models import CoulombViscousParams, FrictionParams
from wbfriction.report.terminal import compact_names, fit_notes, fit_tables

TRUE = CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.3)
MOVED = ("leg_left_2_joint", "leg_left_3_joint", "leg_right_4_joint")
STILL = ("torso_1_joint", "torso_2_joint", "arm_left_1_joint", "arm_left_2_joint", "arm_left_3_joint",
         "arm_left_5_joint", "gripper_left_joint")
UNITS = {"F_c": "[N·m]", "F_v": "[N·m·s/rad]", "tau_os": "[N·m]", "S": "[-]", "v_s": "[rad/s]", "a": "[s/rad]"}


def _fit(joint: str, amplitude: float, seed: int):
    rng = np.random.default_rng(seed)
    qd = amplitude * np.sin(np.linspace(0, 12 * np.pi, 1500))
    return fit_friction(qd, TRUE.torque(qd) + 0.005 * rng.normal(size=qd.size), joint=joint,
                        model="coulomb-viscous")


@pytest.fixture(scope="module")
def fits():
    """Three joints swept at 1 rad/s (ok) and seven at 1 mrad/s (not excited: below 0.02 rad/s)."""
    out = [_fit(j, 1.0, k) for k, j in enumerate(MOVED)] + [_fit(j, 1e-3, 10 + k) for k, j in enumerate(STILL)]
    assert [f.verdict().status for f in out] == ["ok"] * len(MOVED) + ["not excited"] * len(STILL)
    return out


def _printed(renderables, width: int = 100) -> list[str]:
    console = Console(width=width, record=True, file=open("/dev/null", "w"), color_system=None)
    for r in renderables:
        console.print(r, highlight=False)
    return console.export_text().splitlines()


def _expand(name: str) -> list[str]:
    """Bash's brace expansion of one name (``a_{1..3,5}_b``), written apart from the code under test."""
    m = re.fullmatch(r"(.*)\{(.*)\}(.*)", name)
    if m is None:
        return [name]
    numbers = []
    for part in m.group(2).split(","):
        low, _, high = part.partition("..")
        numbers += list(range(int(low), int(high or low) + 1))
    return [f"{m.group(1)}{n}{m.group(3)}" for n in numbers]


def test_compact_names_expand_back_to_the_names():
    names = ["leg_left_1_joint", "torso_1_joint", "torso_2_joint", *[f"arm_left_{k}_joint" for k in (1, 2, 3, 5)],
             "panda_joint7", "lwr_6", "FR_calf_joint"]
    shown = compact_names(names)
    assert shown == ["leg_left_1_joint", "torso_{1,2}_joint", "arm_left_{1..3,5}_joint", "panda_joint7", "lwr_6",
                     "FR_calf_joint"]
    assert sorted(n for s in shown for n in _expand(s)) == sorted(names)


def test_the_joints_not_excited_are_one_line_that_names_them_all(fits):
    lines = _printed([*fit_tables(fits), *fit_notes(fits)])
    assert all(len(line) <= 100 for line in lines), [line for line in lines if len(line) > 100]
    rows = [line.split()[0] for line in lines if line.split() and line.split()[0] in (*MOVED, *STILL)]
    assert sorted(set(rows)) == sorted(MOVED)  # a row per joint that moved, none of the others
    text = " ".join(lines)
    folded = re.search(r"(\d+) joints not excited \([^)]*\): (.*?)(?: model chosen|$)", " ".join(text.split()))
    assert folded is not None, text
    named = [n for s in folded.group(2).split(", ") for n in _expand(s.strip())]
    assert int(folded.group(1)) == len(STILL) and sorted(named) == sorted(STILL)
    wide = _printed(fit_tables(fits, wide=True), width=300)
    assert {line.split()[0] for line in wide if line.split()} >= {*MOVED, *STILL}  # --wide: every joint's row


def test_every_parameter_column_has_its_unit(fits):
    thesis = fit_friction(*_sweep(), model="thesis", joint="knee")
    for table in fit_tables([*fits, thesis]):
        if "error [%]" in str(table.title) or table.title == "Terms beyond velocity":
            continue  # percentages, said in the title; the terms' values carry their units in the cell
        for column in table.columns:
            name = str(column.header).split(" [")[0]
            if name in UNITS:
                assert str(column.header) == f"{name} {UNITS[name]}", column.header


def _sweep():
    qd = np.sin(np.linspace(0, 12 * np.pi, 3000))
    truth = FrictionParams(F_v=0.2, F_c=1.0, S=0.2, v_s=0.2, tau_os=0.3, a=40.0)
    return qd, truth.torque(qd) + 0.005 * np.random.default_rng(1).normal(size=qd.size)


def test_the_demos_table_fits_and_says_what_the_thesis_errors_over_100_percent_are():
    """The demo's table beside the thesis's Tables 6.1/6.2: within 100 columns, a unit under every parameter, the
    thesis's errors to the digits that mean something (its hip rolls' F_v 971.75 % and 1125.90 % as 972 and 1126),
    and the caption naming each one over 100 %: nothing left to a lone footnote."""
    import dataclasses

    from wbfriction.studies.common import LegRow
    from wbfriction.studies.tables import study_table
    from wbfriction.studies.thesis import TABLE_6_1, TABLE_6_2

    qd, tau_f = _sweep()
    truth = FrictionParams(F_v=0.2, F_c=1.0, S=0.2, v_s=0.2, tau_os=0.3, a=40.0)
    fit = dataclasses.replace(fit_friction(qd, tau_f, model="thesis"), target=truth)
    rows = [LegRow(joint, side, group, number, dataclasses.replace(fit, joint=joint), TABLE_6_1[(side, group)],
                   TABLE_6_2[(side, group)])
            for joint, side, group, number in (("leg_right_2_joint", "right", "hip_roll", 1),
                                               ("leg_right_4_joint", "right", "knee", 4),
                                               ("leg_left_2_joint", "left", "hip_roll", 7))]
    lines = _printed([study_table(rows, "Identified friction (3.5)")])
    assert all(len(line) <= 100 for line in lines), [line for line in lines if len(line) > 100]
    header = " ".join(lines[1:3])
    assert all(unit in header for unit in UNITS.values())
    thesis = [line.split() for line in lines if line.strip().startswith("T6.1 [%]")]
    assert [r[2] for r in thesis] == ["972", "0.50", "1126"]  # F_v of Table 6.1, hip rolls and the right knee
    caption = " ".join(" ".join(lines).split())
    over = re.search(r"T6\.1 over 100 % \(([^)]*)\)", caption)
    assert over is not None, caption
    assert over.group(1) == "#1 F_v 972, #1 S 680, #7 F_v 1126, #7 S 392"  # every value of Table 6.1 above 100
    assert "at most 18 %" in caption  # the same entries of Table 6.2: 17.25, 5.85, 17.70, 11.95


def test_identifys_tables_show_their_units_and_a_magnitude_at_zero_as_zero(fits):
    """``identify``'s tables: the units of the bodies' table that Rich took for tags ([kg], [mm]) shown, a unit
    under each friction parameter, and an acceleration-route F_v the solver left at 2.18e-67 N·m·s/rad (its floor
    of zero: below :data:`~wbfriction.fit.status.ZERO`) printed 0; within 100 columns."""
    import dataclasses

    from wbfriction.inertia.document import BodyWritten, HeldOutRms, Identification, JointIdentified
    from wbfriction.report.terminal import identification_tables

    moved = fits[0]
    at_zero = dataclasses.replace(moved, params=dataclasses.replace(moved.params, F_v=2.18e-67))
    joints = {joint: JointIdentified(identified={"F_v": value, "F_c": 0.409, "tau_os": 0.824, "F_s-F_c": 0.0},
                                     acceleration_route=route, acceleration_route_given_model=route,
                                     holdout_rms=HeldOutRms(1.41, 0.342, 0.266, 0.265), generating_share=0.5,
                                     generating_share_given_model=0.5)
              for joint, value, route in (("lwr_0_joint", 1.49, moved), ("lwr_6_joint", 5.52e-30, at_zero))}
    bodies = (BodyWritten("lwr_1_link", 2.7, 2.967, 0.0989, 0.0515, (0.01, 0.02, 0.02), (0.006, 0.01, 0.011),
                          (-0.361, -0.501, -0.452), kept=True),)
    result = Identification(passes=(), bodies=bodies, joints=joints, holdout_samples=2010)
    tables, _ = identification_tables(result)
    lines = _printed(tables)
    assert all(len(line) <= 100 for line in lines), [line for line in lines if len(line) > 100]
    text = "\n".join(lines)
    assert "mass [kg]" in text and "COM [mm]" in text and "COM: shift [mm]" in " ".join(text.split())
    assert "[N·m·s/rad]" in text and "[N·m]" in text
    assert "e-30" not in text and "e-67" not in text
    row = next(line.split() for line in lines if line.startswith(" lwr_6_joint") or line.startswith("lwr_6_joint"))
    assert row[2] == "0" and row[6] == "0", row  # F_v of this route and of the acceleration route


def test_a_p_value_below_the_floating_points_digits_is_said_so():
    from wbfriction.report.numbers import p_value_text

    assert [p_value_text(p) for p in (1.37e-67, 0.0, 1e-12, 0.0123)] == ["< 1e-12", "< 1e-12", "1e-12", "0.012"]
