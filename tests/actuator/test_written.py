"""What ``identify --actuator pd --config-output`` writes (:mod:`wbfriction.actuator.written`), against the truth of
the hung Go2 in MuJoCo (:mod:`wbfriction.sim.hung`, a real driver's noise, 4 s): each value written is closer to the
simulator's truth than the robot TOML's it replaces, whatever the TOML holds (the truth, nothing, gains off by two)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import wbfriction
from wbfriction.actuator import identify_actuators
from wbfriction.actuator.written import held_out_blocks
from wbfriction.fit.regression import HELD_OUT_BLOCKS
from wbfriction.logs.log import log_from_table
from wbfriction.pipeline.actuator_step import written_values
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER, HungOptions, SetpointOptions


@pytest.fixture(scope="module")
def go2():
    return wbfriction.load_robot("go2")


@pytest.fixture(scope="module")
def sim(go2):
    return simulate_hung(go2, HungOptions(duration=4.0, noise=REAL_DRIVER, setpoints=SetpointOptions(amplitude=0.25)))


def identified(robot, table):
    return identify_actuators(robot, log_from_table(table, robot, "hung.parquet"))


def truth_of(sim, result, kind: str, joint: str) -> float:
    i = [j.joint for j in result.joints].index(joint)
    return float(sim.armature[i] if kind == "armature" else sim.encoder_offset[i])


def written_against_truth(sim, result) -> tuple[list[str], list[str]]:
    """The values written closer to the truth than the TOML's, and those written farther (joint and kind)."""
    closer, farther = [], []
    assert result.written is not None
    for v in result.written.values:
        if v.source != "identified":
            continue
        t = truth_of(sim, result, v.kind, v.joint)
        (closer if abs(v.written - t) <= abs(v.given - t) else farther).append(f"{v.joint} {v.kind}")
    return closer, farther


@given(st.integers(min_value=2, max_value=400))
def test_the_blocks_are_contiguous_and_cover_every_window(count):
    blocks = held_out_blocks(count)
    assert 2 <= len(blocks) <= HELD_OUT_BLOCKS
    assert np.array_equal(np.concatenate(blocks), np.arange(count))
    assert all(len(b) >= 1 and np.all(np.diff(b) == 1) for b in blocks)


def test_a_toml_without_delay_gets_the_one_the_log_shows_and_keeps_its_offsets(go2, sim):
    """The TOML's delay 0 and offsets 0 against the drivers' 12 ms and offsets of 10-40 mrad: the delay written is the
    drivers' (within a physics step); the TOML's armature is the truth, and none of it is replaced; the offsets that
    predict the held-out blocks better are named in the JSON and not written: an offset and the URDF's gravity model
    close the balance alike (:data:`~wbfriction.actuator.written.CONFOUNDED`)."""
    blind = replace(go2, encoder_offset={}, pd=replace(go2.pd, delay=0.0))
    result = identified(blind, sim.table)
    armature, offsets, delay = written_values(result)
    assert delay is not None and abs(delay - sim.driver.delay) < sim.physics_step
    assert armature == {} and offsets == {}
    assert result.written is not None
    assert sum(v.kind == "offset" and "cannot tell them apart" in v.reason for v in result.written.values) >= 3
    assert written_against_truth(sim, result)[1] == []


def test_a_toml_that_holds_the_truth_is_kept(go2, sim):
    """The TOML holds the simulator's armature, offsets and delay: values fitted within their noise of them predict
    the held-out blocks a hair better or worse by chance; none replaces them."""
    result = identified(go2, sim.table)
    assert written_values(result) == ({}, {}, None)


def test_an_armature_the_toml_does_not_state_is_written_where_it_predicts_better(go2, sim):
    """No [armature] in the TOML (0: known to be wrong, a rotor always has one): the identified armatures that
    predict the held-out blocks better are written, each closer to the truth than 0."""
    model = go2.model.copy()
    model.armature[:] = 0.0
    bare = replace(go2, model=model)
    result = identified(bare, sim.table)
    armature, _, _ = written_values(result)
    assert len(armature) >= 10
    closer, farther = written_against_truth(sim, result)
    assert farther == []


def test_gains_off_by_two_write_nothing_farther_from_the_truth(go2, sim):
    """The TOML's kp 50 against the drivers' 25: the offsets that absorb the law's error predict the held-out blocks
    better (up to 11 standard errors), yet lie at the search's bound, 0.3 rad from the truth; their standard errors
    carry the law's disagreement (:mod:`wbfriction.actuator.law_check`), the TOML's 0 lies within them, and
    nothing farther from the truth than the TOML's is written."""
    result = identified(replace(go2, encoder_offset={}, pd=replace(go2.pd, kp=np.full(12, 50.0))), sim.table)
    _, farther = written_against_truth(sim, result)
    assert farther == []
