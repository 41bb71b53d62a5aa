"""What the PD drivers' delay holds back, and what follows where a log does not tell (issue 63, item 4).

Set-points held back by ``d`` and the whole law held back differ on steady motion by a viscous torque ``kp d qd``: a
friction fitted under either takes it up in F_v. On the real Aliengo (``tests/real/test_aliengo.py``) the two close
the balance alike and F_v is 0 on ten joints under one, 0.14-0.61 under the other, 0.33 higher where both are
interior (``kp d`` = 0.28). Where the log does not tell, the identified friction carries its distance to the
other's, ``--config-output`` says so (``delayed_known = false``) and the friction fitted afterwards carries ``kp d``
in F_v's standard error.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import wbfriction
from wbfriction.actuator import identify_actuators
from wbfriction.actuator.identification import structure_gain, structure_widened
from wbfriction.exceptions import InputError
from wbfriction.fit.joints import delay_structure_spread
from wbfriction.logs.log import log_from_table
from wbfriction.logs.torque import torque_record
from wbfriction.model import load_robot, robots
from wbfriction.pipeline.actuator_step import actuator_config
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER, HungOptions, SetpointOptions

GO2_TOML = Path(robots.__file__).parent / "go2.toml"


@pytest.fixture(scope="module")
def go2_identified():
    robot = wbfriction.load_robot("go2")
    sim = simulate_hung(robot, HungOptions(duration=4.0, noise=REAL_DRIVER, setpoints=SetpointOptions(amplitude=0.25)))
    return robot, identify_actuators(robot, log_from_table(sim.table, robot, "hung.parquet"))


def test_equal_residuals_do_not_tell_and_clearly_smaller_ones_do(go2_identified):
    _, result = go2_identified
    r = result.residuals
    assert r is not None and np.isfinite(r).any()
    gain, se = structure_gain(result, replace(result, residuals=r.copy()))
    assert gain == 0.0 and not gain > 2 * se
    gain, se = structure_gain(result, replace(result, residuals=2.0 * r))
    assert gain > 2 * se


def test_a_structure_not_told_widens_the_friction_by_its_distance_to_the_others(go2_identified):
    """The friction's standard errors grow by the other structure's distance; the armature, written beside the
    structure it was fitted under, keeps its own."""
    _, result = go2_identified
    other = replace(result, joints=tuple(replace(j, F_v=replace(j.F_v, value=j.F_v.value + 0.3),
                                                 armature=replace(j.armature, value=j.armature.value + 0.01))
                                         for j in result.joints))
    other = replace(other, options=replace(result.options, delayed="torque"))
    widened = structure_widened(result, other)
    assert not widened.delayed_known
    for before, after in zip(result.joints, widened.joints):
        assert after.F_v.se == pytest.approx(math.hypot(before.F_v.se, 0.3))
        assert after.F_c == before.F_c and after.armature == before.armature
        if before.F_v.status == "ok":
            assert after.F_v.status == "weak" and "with the setpoints delayed" in after.F_v.reason \
                and "with the torque" in after.F_v.reason


def test_the_toml_written_says_so_and_the_friction_carries_kp_delay(go2_identified, tmp_path):
    robot, result = go2_identified
    assert result.written is not None and result.written.delay is not None
    # the delay written (here the TOML's is the simulator's truth and is kept: the identified one written instead)
    result = replace(result, written=replace(result.written, delay=replace(result.written.delay, source="identified")))
    toml = tmp_path / "go2.toml"
    written = actuator_config(GO2_TOML.read_text(), GO2_TOML.parent, robot.urdf, toml,
                              replace(result, delayed_known=False))
    assert "delayed_known = false" in written
    toml.write_text(written)
    back = load_robot(None, config=toml)
    assert back.pd is not None and not back.pd.delayed_known
    expected = {j: float(k) * back.pd.delay for j, k in zip(back.pd.joints, back.pd.kp)}
    assert back.pd.viscous_equivalent() == pytest.approx(expected)
    setpoints = SimpleNamespace(kp=None, kd=None)  # the log's: gains from the TOML
    record = torque_record(back, "pd", setpoints)  # type: ignore[arg-type]
    assert record["delayed_known"] is False
    assert delay_structure_spread({"torque_source": record}) == pytest.approx(expected)
    # told: nothing written, nothing carried
    again = actuator_config(written, tmp_path, robot.urdf, toml, result)
    assert "delayed_known" not in again
    assert delay_structure_spread({"torque_source": torque_record(robot, "pd", setpoints)}) == {}  # type: ignore


def test_a_delayed_known_that_is_not_a_boolean_is_refused(tmp_path):
    toml = tmp_path / "go2.toml"
    toml.write_text(GO2_TOML.read_text().replace("[pd]", '[pd]\ndelayed_known = "no"', 1))
    with pytest.raises(InputError, match="delayed_known must be true or false"):
        load_robot(None, config=toml)
