"""What the thesis's studies share: the leg joints in the thesis's numbering, the table rows, the worst
errors, and the fit of the leg joints picked by name."""

from __future__ import annotations

import numpy as np
import pytest

from wbfriction.fit.result import FitResult
from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import FrictionParams
from wbfriction.studies.common import SIMULATOR, fit_legs, leg_joints, leg_params_extra, leg_rows, worst_errors
from wbfriction.studies.filters import FilterStudyResult, FilterStudyRow
from wbfriction.studies.thesis import TABLE_6_1, TABLE_6_2, thesis_number


def test_thesis_numbering():
    """Fig. 4.1 / Table 4.1: 1-6 right leg from the hip roll to the ankle pitch, 7-12 the left leg."""
    assert [thesis_number("right", g) for g in ("hip_roll", "knee", "ankle_pitch")] == [1, 4, 6]
    assert [thesis_number("left", g) for g in ("hip_roll", "ankle_pitch")] == [7, 12]
    assert len(TABLE_6_1) == len(TABLE_6_2) == 12


def test_leg_joints_of_talos_in_thesis_order(talos):
    legs = leg_joints(talos)
    assert [thesis_number(side, g) for _, side, g in legs] == list(range(1, 13))
    assert all(j.startswith("leg_right") for j, side, _ in legs[:6]) and all(side == "left" for _, side, _ in legs[6:])
    assert {j for j, _, _ in legs} == {j for f in talos.contact_frames for j in talos.limb(f)}
    assert SIMULATOR.substeps == 10  # physics at 10 kHz under a 1 kHz controller (the demo's figures)


def test_rows_extra_and_worst_errors(talos):
    legs = leg_joints(talos)[:2]
    target = THESIS_TARGETS["hip_roll"]
    fits = [FitResult(j, 100, params=FrictionParams(F_v=target.F_v * (1 + e), F_c=target.F_c, S=target.S,
                                                    v_s=target.v_s, tau_os=target.tau_os, a=target.a),
                      target=target) for (j, _, _), e in zip(legs, (0.1, -0.3))]
    rows = leg_rows(legs, fits)
    assert [r.number for r in rows] == [1, 2]
    assert rows[0].thesis_6_1 == TABLE_6_1[("right", legs[0][2])]
    worst = worst_errors(rows)
    assert worst["F_v"] == pytest.approx(30.0) and worst["F_c"] == 0.0
    assert worst_errors(rows, ("F_c",)) == {"F_c": 0.0}
    extra = leg_params_extra(rows)
    assert extra[legs[0][0]]["thesis_number"] == 1 and "thesis_error_percent_table_6_2" in extra[legs[1][0]]
    assert "thesis_error_percent_table_6_1" not in leg_params_extra(rows, thesis_errors=False)[legs[0][0]]


def test_fit_legs_picks_the_joints_by_name():
    """The estimate's joints in another order than the legs': each leg's fit recovers its own friction."""
    t = np.arange(6000) * 1e-3
    qd = np.column_stack([np.sin(2 * np.pi * 0.4 * t), 1.5 * np.sin(2 * np.pi * 0.3 * t)])
    knee, ankle = THESIS_TARGETS["knee"], THESIS_TARGETS["ankle_roll"]
    tau_f = np.column_stack([ankle.torque(qd[:, 0]), knee.torque(qd[:, 1])])
    est = FrictionEstimate(joints=("ankle", "knee"), time=t, qd=qd, tau_f=tau_f, valid=np.ones_like(qd, dtype=bool),
                           phase=np.full(len(t), "single"), unique=np.ones(len(t), dtype=bool),
                           contact=np.ones((len(t), 1), dtype=bool), contact_frames=("sole",))
    fits = fit_legs(est, [("knee", "right", "knee"), ("ankle", "right", "ankle_roll")],
                    {"knee": knee, "ankle": ankle})
    assert [f.joint for f in fits] == ["knee", "ankle"]
    for f in fits:
        assert max(f.error_percent()[n] for n in ("F_v", "F_c", "tau_os")) < 0.1


def test_the_best_scheme_of_a_noise_level():
    worst = dict.fromkeys(("F_v", "F_c", "S", "v_s", "tau_os", "a"), 1.0)
    rows = [FilterStudyRow(1e-4, "a", 10, 0.1, {**worst, "F_v": 9.0}), FilterStudyRow(1e-4, "b", 10, 0.2, worst),
            FilterStudyRow(None, "c", 10, 0.0, {**worst, "F_c": 0.5})]
    result = FilterStudyResult(rows)
    assert result.best(1e-4).scheme == "b" and result.best(None).scheme == "c"
    assert rows[0].score == 9.0
