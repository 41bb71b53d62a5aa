"""Issue 81, class 3: a hung robot's design aborted on one bad candidate, blaming the units. ``excite --robot go2
--duration 10`` at the default seed stopped with "wrong units (degrees for radians)?": one candidate's simulated motion
passed a joint limit by more than a log may, and the log check raised before the search could drop it. A candidate
is now scored, never raised (:func:`~wbfriction.excite.pd_design.design_pd`): dropped, its reason kept and counted,
and only a search with no candidate left fails, in one line saying why."""

from __future__ import annotations

import dataclasses

import numpy as np
import pyarrow as pa
import pytest

import wbfriction
import wbfriction.excite.pd_design as pd_design
import wbfriction.excite.predict as predict
from helpers import run_cli_printed, said
from wbfriction.exceptions import InputError
from wbfriction.excite.document import pd_document
from wbfriction.excite.options import PdExciteOptions
from wbfriction.logs.options import LIMIT_MARGIN
from wbfriction.sim.hung import simulate_hung

BAD = (0.1, 0.8)
"""The reversal range of the candidate whose motion is made to pass a limit."""
JOINT = "FL_hip_joint"


@pytest.fixture(scope="module")
def go2():
    return wbfriction.load_robot("go2")


@pytest.fixture
def overshooting(go2, monkeypatch):
    """The hung simulator, but a candidate reversing every ``BAD`` seconds has its front left hip pass its upper limit
    by twice what a log may from sample 50 on (its true angle and its logged one): infeasible by construction."""
    upper = go2.angle_limits[1][go2.actuated.index(JOINT)]
    offset = go2.encoder_offset.get(JOINT, 0.0)

    def simulated(robot, options, *args, **kwargs):
        sim = simulate_hung(robot, options, *args, **kwargs)
        if options.setpoints.reversal != BAD:
            return sim
        i = robot.actuated.index(JOINT)
        q = sim.trajectory.q.copy()
        q[50:, i] = upper + 2 * LIMIT_MARGIN
        column = sim.table.column_names.index(f"q.{JOINT}")
        logged = sim.table.column(column).to_numpy().copy()
        logged[50:] = upper + offset + 2 * LIMIT_MARGIN
        return dataclasses.replace(sim, trajectory=dataclasses.replace(sim.trajectory, q=q),
                                   table=sim.table.set_column(column, f"q.{JOINT}", pa.array(logged)))

    monkeypatch.setattr(pd_design, "simulate_hung", simulated, raising=False)  # the search's own simulation
    monkeypatch.setattr(predict, "simulate_hung", simulated)  # the prediction's


def test_a_candidate_past_a_limit_is_dropped_and_the_search_goes_on(go2, overshooting):
    options = PdExciteOptions(duration=2.0, amplitudes=(0.5,), reversals=((0.2, 1.5), BAD))
    design = pd_design.design_pd(go2, options)
    assert design.chosen.reversal == (0.2, 1.5) and design.chosen.dropped is None
    (dropped,) = design.dropped()
    assert dropped.reversal == BAD and not dropped.within and dropped.worst[2] == np.inf
    assert f"joint '{JOINT}'" in dropped.dropped and "by 0.4 rad" in dropped.dropped
    assert "units" not in dropped.dropped
    doc = pd_document(design)
    assert [c.get("dropped") is not None for c in doc["candidates"]] == [False, True]


def test_no_candidate_left_is_one_line_saying_why(go2, overshooting, monkeypatch):
    def never(*args, **kwargs):
        raise AssertionError("a dropped candidate's identification predicted")

    monkeypatch.setattr(pd_design, "predict_pd", never)
    with pytest.raises(InputError) as err:
        pd_design.design_pd(go2, PdExciteOptions(duration=2.0, amplitudes=(0.5, 0.8), reversals=(BAD,)))
    message = str(err.value)
    assert "\n" not in message and "units" not in message
    assert message.startswith("robot 'go2': no candidate motion can be scored: 2 of 2 dropped")
    assert f"joint '{JOINT}'" in message and "--amplitude" in message


@pytest.mark.slow
def test_the_hung_go2s_10_s_design_at_the_default_seed(capsys, tmp_path):
    """The case of the issue, as a user runs it (about a minute): one candidate of six dropped, the design written."""
    code, out, err = run_cli_printed(capsys, "excite", "--robot", "go2", "--duration", "10", "-o",
                                     tmp_path / "d.parquet")
    assert code == 0, said(err)
    assert "1 of 6 candidates dropped unscored" in " ".join(out.split()) and (tmp_path / "d.parquet").exists()
