"""What to record next (:mod:`wbfriction.excite.next`): after a hung Go2's log whose hips held still (their fits not
``ok``), the motion proposed moves the joints the log left undetermined and holds the others; played with another
noise and identified, it determines them as predicted."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import wbfriction
from wbfriction.actuator import identify_actuators
from wbfriction.excite.next import record_next
from wbfriction.excite.options import PdExciteOptions
from wbfriction.excite.pd_design import held
from wbfriction.fit.params_file import read_params
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import log_from_table
from wbfriction.logs.tables import write_table
from wbfriction.model.loading import RobotSpec
from wbfriction.pipeline.estimate_step import estimate_file
from wbfriction.pipeline.fit_step import fit_file
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER, HungOptions, SetpointOptions

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("excite_next")]  # one module fixture, one worker


@pytest.fixture(scope="module")
def following(tmp_path_factory):
    folder = tmp_path_factory.mktemp("next")
    go2 = wbfriction.load_robot("go2")
    hips = np.array(["_hip_" in j for j in go2.actuated])
    first = HungOptions(duration=20.0, noise=REAL_DRIVER, setpoints=SetpointOptions(kind="ramps", amplitude=0.8))
    log = simulate_hung(go2, first, reference=held(go2, first, hips))
    write_table(log.table, folder / "first.parquet")
    estimate_file(RobotSpec.given("go2"), folder / "first.parquet", folder / "friction.parquet", EstimateOptions(),
                  robot=go2)
    fit_file(folder / "friction.parquet", folder / "params.json")
    fits = read_params(folder / "params.json")
    options = PdExciteOptions(duration=20.0, amplitudes=(0.8, 0.95), reversals=((0.2, 1.5),))
    return go2, fits, record_next(go2, fits, "params.json", options)


def test_only_what_the_log_left_undetermined_moves(following):
    go2, fits, nxt = following
    undetermined = {j for j, f in fits.items() if not f.verdict().ok}
    # the rear hips held still (the front ones swing with their legs: 0.5-0.6 rad/s, their fits ok and right)
    assert {"RL_hip_joint", "RR_hip_joint"} <= undetermined
    assert set(nxt.design.moving) == undetermined and set(nxt.logged) == undetermined
    still = [go2.actuated.index(j) for j in go2.actuated if j not in undetermined]
    assert np.ptp(nxt.design.q_des[:, still], axis=0).max() == 0.0
    assert nxt.design.worst()[2] < 1.0


@pytest.mark.xfail(strict=True, reason="with weak at 10 % of a value (issue 79) the design chosen changes, and on it "
                   "the prediction's noise-free identification reports 1.3-10 times the played log's standard errors "
                   "on the front hips (offset 0.0099 against 0.00095 rad): the predictor's defect, still open")
def test_played_it_determines_them_as_predicted(following):
    go2, _, nxt = following
    design = nxt.design
    options = replace(design.options.hung(design.chosen.amplitude, design.chosen.reversal),
                      noise=replace(REAL_DRIVER, seed=9))
    sim = simulate_hung(go2, options, reference=(design.q_des - go2.offset_vector, design.qd_des))
    result = identify_actuators(go2, log_from_table(sim.table, go2, "next.parquet"))
    ratios = []
    for j in result.joints:
        if j.joint in design.moving:
            for name, p in j.parameters().items():
                assert p.status == "ok", (j.joint, name, p.reason)
                ratios.append(p.se / design.prediction.joints[j.joint][name].se)
    ratios = np.array(ratios)
    assert np.mean((ratios > 1 / 1.5) & (ratios < 1.5)) >= 0.9, np.sort(ratios)
