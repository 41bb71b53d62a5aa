"""The report's parameter table: each column shows its own parameter's value, the target row the target's,
and the error row the relative error computed here, joint by joint (parsed from the rendered HTML)."""

from __future__ import annotations

from html.parser import HTMLParser

import numpy as np
import pytest

from wbfriction.fit.energy import energy_consistency
from wbfriction.fit.result import FitResult, fitted_offsets
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import CoulombViscousParams, FrictionParams
from wbfriction.report.build import Report
from wbfriction.report.html import render_html

THESIS = FrictionParams(F_v=0.21, F_c=1.3, S=0.37, v_s=0.055, tau_os=-0.48, a=41.5)
TARGET = FrictionParams(F_v=0.2, F_c=1.2, S=0.4, v_s=0.05, tau_os=-0.5, a=40.0)
SIMPLE = CoulombViscousParams(F_v=0.73, F_c=2.6, tau_os=0.09)


class _Table(HTMLParser):
    """The rows of cells (text) of the table with id ``parameters``."""

    def __init__(self) -> None:
        super().__init__()
        self.rows: list[list[str]] = []
        self._in_table = self._in_cell = False

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self._in_table = dict(attrs).get("id") == "parameters"
        elif self._in_table and tag == "tr":
            self.rows.append([])
        elif self._in_table and tag in ("td", "th"):
            self._in_cell = True
            self.rows[-1].append("")

    def handle_endtag(self, tag):
        if tag == "table":
            self._in_table = False
        elif tag in ("td", "th"):
            self._in_cell = False

    def handle_data(self, data):
        if self._in_table and self._in_cell:
            self.rows[-1][-1] += data


@pytest.fixture(scope="module")
def table() -> list[list[str]]:
    t = np.arange(2000) * 1e-3
    qd = np.column_stack([np.sin(2 * np.pi * t), 0.5 * np.sin(2 * np.pi * 0.7 * t)])
    tau_f = np.column_stack([THESIS.torque(qd[:, 0]), SIMPLE.torque(qd[:, 1])])
    est = FrictionEstimate(joints=("knee", "ankle"), time=t, qd=qd, tau_f=tau_f, valid=np.ones_like(qd, dtype=bool),
                           phase=np.full(len(t), "single"), unique=np.ones(len(t), dtype=bool),
                           contact=np.ones((len(t), 1), dtype=bool), contact_frames=("sole",))
    stderr = {"F_v": 0.0011, "F_c": 0.0022, "S": 0.0033, "v_s": 0.00044, "tau_os": 0.0055, "a": 0.66}
    fits: dict[str, FitResult] = {
        "knee": FitResult("knee", 2000, params=THESIS, stderr=stderr, rms_residual=0.0123, target=TARGET,
                          success=True, speed=1.0),
        "ankle": FitResult("ankle", 1999, params=SIMPLE, stderr={"F_v": 0.01, "F_c": 0.02, "tau_os": 0.03},
                           rms_residual=0.0456, success=True, speed=0.01)}
    energy = {e.joint: e for e in energy_consistency(est, fitted_offsets(fits.values()))}
    parser = _Table()
    parser.feed(render_html(Report(est, fits, energy, [("robot", "test")], 0.05)))
    return parser.rows


def _value(cell: str) -> float:
    return float(cell.split("±")[0].replace("(bound)", ""))


def test_each_column_shows_its_own_parameter(table):
    head = table[0]
    names = head[4:-1]
    assert head[:4] == ["joint", "model", "status", "N"] and set(names) == {"F_v", "F_c", "S", "v_s", "tau_os", "a"}
    rows = {r[0].strip(): r for r in table[1:]}
    knee, ankle = rows["knee"], rows["ankle"]
    for i, n in enumerate(names, start=4):
        assert _value(knee[i]) == pytest.approx(getattr(THESIS, n), rel=1e-3), n
        if n in SIMPLE.names:
            assert _value(ankle[i]) == pytest.approx(getattr(SIMPLE, n), rel=1e-3), n
        else:  # not a parameter of the Coulomb-viscous model: blank
            assert ankle[i].strip() == "", n
    assert (knee[1], knee[3], ankle[1], ankle[3]) == ("thesis", "2000", "coulomb-viscous", "1999")
    # the ankle moved at most 0.01 rad/s: its numbers are shown greyed, with the reason
    assert knee[2] == "ok" and ankle[2].startswith("not excited: it hardly moved")
    assert _value(knee[-1]) == pytest.approx(0.0123, rel=1e-3) and _value(ankle[-1]) == pytest.approx(0.0456, rel=1e-3)


def test_target_and_error_rows_are_the_joints_own(table):
    names = table[0][4:-1]
    target = next(r for r in table if r[0].strip() == "target")
    error = next(r for r in table if r[0].strip() == "error [%]")
    for i, n in enumerate(names, start=4):
        t, p = getattr(TARGET, n), getattr(THESIS, n)
        assert _value(target[i]) == pytest.approx(t, rel=1e-3), n
        assert _value(error[i]) == pytest.approx(100 * abs(p - t) / abs(t), abs=0.006), n
    assert sum(r[0].strip() == "target" for r in table) == 1  # the ankle has no target: no target row
