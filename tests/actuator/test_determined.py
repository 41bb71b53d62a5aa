"""Issue 63: ``identify --actuator pd`` says ``ok`` only for what the log determines, and checks the robot TOML's
PD law against the log. The hung Go2 in MuJoCo (:mod:`wbfriction.sim.hung`, a real driver's noise, 4 s), whose log
carries its truth, in the issue's cases: set-points that hold still, drivers later than the delay searched, a TOML
whose gains or delay are not the drivers', jittered time stamps. Each asserts against the simulator's truth: no
value ``ok`` that is more than three standard errors off it, and the mismatch named in one line."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pyarrow as pa
import pytest

import wbfriction
from wbfriction.actuator import identify_actuators
from wbfriction.actuator.excitation import JointMotion
from wbfriction.actuator.solve import sandwich
from wbfriction.fit.status import MIN_SPEED
from wbfriction.logs.log import log_from_table
from wbfriction.pipeline.actuator_step import written_values
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER, HungOptions, SetpointOptions

DURATION = 4.0


@pytest.fixture(scope="module")
def go2():
    return wbfriction.load_robot("go2")


def simulated(robot, **options):
    setpoints = SetpointOptions(amplitude=options.pop("amplitude", 0.25))
    return simulate_hung(robot, HungOptions(duration=DURATION, noise=REAL_DRIVER, setpoints=setpoints, **options))


def identified(robot, table: pa.Table, **pd):
    """Identified from no offset, with the TOML's [pd] changed by ``pd`` (kp, delay)."""
    blind = replace(robot, encoder_offset={}, pd=replace(robot.pd, **pd))
    return identify_actuators(blind, log_from_table(table, blind, "hung.parquet"))


def off_truth(sim, result) -> list[tuple[str, str, float]]:
    """The ``ok`` values more than three standard errors off the simulator's truth: (joint, kind, errors)."""
    out = []
    for i, joint in enumerate(result.joints):
        f = sim.friction[joint.joint]
        truth = {"armature": sim.armature[i], "F_v": f.F_v, "F_c": f.F_c, "offset": sim.encoder_offset[i]}
        for kind, p in joint.parameters().items():
            z = abs(p.value - truth[kind]) / p.se
            if p.status == "ok" and z > 3:
                out.append((joint.joint, kind, z))
    return out


def ok_values(result) -> list[str]:
    return [f"{j.joint} {k}" for j in result.joints for k, p in j.parameters().items() if p.status == "ok"]


def test_still_setpoints_determine_nothing(go2):
    """Set-points that hold still: no velocity, so no friction and no armature; the offset of a joint held still is
    one with the friction holding it (the issue: 12 values ``ok`` and wrong, the offsets written)."""
    sim = simulated(go2, amplitude=0.0)
    result = identified(go2, sim.table)
    assert ok_values(result) == []
    assert all(j.F_v.status == "not excited" and "hardly moved" in j.F_v.reason for j in result.joints)
    assert all(p.status in ("not excited", "at bound") for j in result.joints for p in j.parameters().values())
    assert result.delay.status != "ok"
    assert written_values(result) == ({}, {}, None)


def test_a_tiny_amplitude_is_not_excited(go2):
    """At 0.005 of the range the joints stick within their friction (the issue: a thigh's F_v 31.0 ± 4.5 ``ok``
    against 0.27): nothing ``ok`` beyond three standard errors of the truth, no friction ``ok``."""
    sim = simulated(go2, amplitude=0.005)
    result = identified(go2, sim.table)
    assert off_truth(sim, result) == []
    assert not any(j.F_v.status == "ok" or j.F_c.status == "ok" for j in result.joints)


def test_drivers_later_than_the_search_leave_every_value_at_bound(go2):
    """Drivers 80 ms late, the search to 50 ms: the delay at its bound, every value fitted under it ``at bound``,
    none written (the issue: 24 values ``ok``, armature and F_v 3x, the old delay kept beside them)."""
    sim = simulated(go2, delay=0.08)
    result = identified(go2, sim.table)
    assert result.delay.status == "at bound" and result.delay.value < sim.driver.delay
    assert ok_values(result) == []
    assert all(p.status not in ("ok", "weak") for j in result.joints for p in j.parameters().values())
    assert any("delay at the search's bound" in p.reason for j in result.joints for p in j.parameters().values())
    assert written_values(result) == ({}, {}, None)
    assert len(result.warnings) == 1 and "--max-delay" in result.warnings[0]


def test_a_toml_whose_gains_are_twice_the_drivers_is_named_and_its_error_measured(go2):
    """The TOML's kp 50 against the drivers' 25: the law's scale the log shows is the truth's (25/50, the damping's
    share aside), named in one line with the causes the log cannot tell apart (gains, masses); no factor decides
    anything: how far the values move with the scale freed is in their standard errors, so no value is ``ok`` more
    than three standard errors off the truth (before: every value demoted at a factor 1.6 chosen between two
    robots)."""
    sim = simulated(go2)
    result = identified(go2, sim.table, kp=np.full(12, 50.0))
    assert result.law is not None
    assert np.all(np.abs(result.law.gain - 0.5) < 0.1)  # the truth: half the TOML's stiffness
    assert np.all(result.law.moved[:12] > 0)  # every joint's scale off: its armature's move measured
    assert off_truth(sim, result) == []
    lines = [w for w in result.warnings if "gains" in w]
    assert len(lines) == 1 and "cannot tell which" in lines[0] and "masses" in lines[0] and "\n" not in lines[0]


def test_a_toml_whose_delay_is_not_the_drivers_is_named(go2):
    """The TOML's delay 0 against the drivers' 12 ms: the delay found is the drivers' (within a physics step), the
    TOML's named in one line; the gains agree (none off 1 beyond its tolerance and three standard errors), so
    nothing else is."""
    sim = simulated(go2)
    result = identified(go2, sim.table, delay=0.0)
    assert abs(result.delay.value - sim.driver.delay) < sim.physics_step and result.delay.status == "ok"
    assert result.law is not None and result.law.gains_off == ()
    assert len(result.warnings) == 1 and "[pd] delay (0 ms)" in result.warnings[0]
    right = identified(go2, sim.table)
    assert right.warnings == ()
    assert ok_values(right) == ok_values(result)
    assert off_truth(sim, result) == []


def test_the_ok_values_of_a_ramped_log_lie_within_three_standard_errors(go2):
    """The TOML's own law, ramps and chirps: most values ``ok`` (the test can fail by saying nothing) and none more
    than three standard errors off the truth; the thighs' F_v, 3-4 % off (the friction's true transition is not the
    nuisance model's), were 7-10 plain standard errors off before the nuisance model's sensitivity was counted."""
    sim = simulated(go2)
    result = identified(go2, sim.table)
    assert len(ok_values(result)) >= 40
    assert off_truth(sim, result) == []


def test_jittered_stamps_are_regularised_before_the_delay_is_searched(go2):
    """Stamps jittered by ±1.5 ms around the 200 Hz clock (the issue: the delay 19.8 ms ``ok`` against 12): the
    delay within a physics step of the truth, as on the exact stamps, and the output says which clock was taken."""
    sim = simulated(go2)
    t = sim.table["time"].to_numpy() + np.random.default_rng(1).uniform(-0.0015, 0.0015, len(sim.table))
    table = sim.table.set_column(sim.table.column_names.index("time"), "time", pa.array(t))
    result = identified(go2, table)
    assert abs(result.delay.value - sim.driver.delay) < sim.physics_step
    assert "regularised" in result.clock


def test_standard_errors_are_never_below_the_bound(go2):
    sim = simulated(go2)
    result = identified(go2, sim.table)
    for p in [result.delay] + [p for j in result.joints for p in j.parameters().values()]:
        assert p.se >= p.crb or not np.isfinite(p.crb)


def test_the_sandwich_covers_autocorrelated_residuals():
    """A slope fitted on a slowly varying regressor with AR(1) residuals (rho 0.9): the plain standard error is
    about a fourth of the slope's spread over 400 draws; the sandwich's within 25 % of it."""
    rng = np.random.default_rng(0)
    n, rho = 400, 0.9

    def ar1(size):
        e = np.empty(size)
        e[0] = rng.normal()
        for k in range(1, size):
            e[k] = rho * e[k - 1] + np.sqrt(1 - rho**2) * rng.normal()
        return e

    x = ar1(n)[:, None]
    slopes, plain, hac = [], [], []
    for _ in range(400):
        e = ar1(n)
        b = float(np.linalg.lstsq(x, e, rcond=None)[0][0])
        r = e - b * x[:, 0]
        s = np.std(r)
        slopes.append(b)
        plain.append(np.sqrt(np.linalg.inv((x / s).T @ (x / s))[0, 0]))
        hac.append(np.sqrt(sandwich(x / s, r / s, np.arange(n), 40)[0, 0]))
    spread = np.std(slopes)
    assert np.median(plain) < 0.5 * spread
    assert abs(np.median(hac) / spread - 1.0) < 0.25


def test_a_joint_that_moved_one_way_leaves_its_coulomb_friction_and_offset_weak():
    one_way = JointMotion(speed=0.5, reverse=0.01)
    assert one_way.verdict("F_c")[0] == "weak" and one_way.verdict("offset")[0] == "weak"
    assert one_way.verdict("F_v") is None and one_way.verdict("armature") is None
    still = JointMotion(speed=0.5 * MIN_SPEED, reverse=0.0)
    assert all(still.verdict(k)[0] == "not excited" for k in ("armature", "F_v", "F_c", "offset"))


def test_the_simulators_set_point_delay_is_told_from_a_torque_delay(go2):
    """The hung Go2's drivers hold back their set-points: the balance closes clearly better so than with the whole
    torque held back, and the identification says the log tells which (:func:`structure_gain`)."""
    result = identified(go2, simulated(go2).table)
    assert result.options.delayed == "setpoints" and result.delayed_known
    assert "does not tell" not in result.velocity_reason


def test_still_setpoints_do_not_tell_what_the_delay_holds_back(go2):
    result = identified(go2, simulated(go2, amplitude=0.0).table)
    assert not result.delayed_known and "does not tell what the delay holds back" in result.velocity_reason
