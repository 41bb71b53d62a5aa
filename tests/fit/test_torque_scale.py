"""The logged torque's scale error in the friction's standard errors (:mod:`wbfriction.fit.torque_scale`): the
linearised shift against the fit itself refitted on a torque scaled by ``1 + eps`` (two routes agreeing), for any
family and draw; zero without a scale error or a free parameter; the robot TOML's ``[torque_scale_sd]`` read, range
checked, and carried by the estimate's metadata into the fit's model spread."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.selection import fit_friction
from wbfriction.fit.torque_scale import torque_scale_spread
from wbfriction.friction.models import CoulombViscousParams, FrictionParams


def _swing(seed: int, n: int = 3000) -> tuple[np.ndarray, np.ndarray]:
    """A joint swinging back and forth (1.3 and 3.1 rad/s tones) and its torque: a gravity load of a few N·m and an
    inertial one, as a leg's [rad/s], [N·m]."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.002
    qd = 1.5 * np.sin(2 * np.pi * 1.3 * t + rng.uniform(0, 6)) + 0.6 * np.sin(2 * np.pi * 3.1 * t)
    q = np.cumsum(qd) * 0.002
    tau = rng.uniform(2, 6) * np.sin(q + rng.uniform(-1, 1)) + 0.3 * np.gradient(qd, 0.002)
    return qd, tau


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2**16), eps=st.sampled_from([-0.03, -0.01, 0.01, 0.03]),
       model=st.sampled_from(["coulomb-viscous", "thesis"]))
def test_the_shift_is_the_fit_refitted_on_the_scaled_torque(seed, eps, model):
    """A friction torque ``tau_f`` estimated with the torque ``(1 + eps) tau`` is off by ``-eps tau``: the fit on it
    moves F_c and F_v by what the spread says of ``|eps|`` (within 10 % of the shift and 0.2 % of the value: the
    linearisation)."""
    qd, tau = _swing(seed)
    truth = (CoulombViscousParams(F_v=0.07, F_c=0.6, tau_os=0.0) if model == "coulomb-viscous"
             else FrictionParams(F_v=0.07, F_c=0.6, S=0.5, v_s=0.3, tau_os=0.0, a=20.0))
    tau_f = -truth.f(qd)
    fit = fit_friction(qd, tau_f, model=model)
    moved = fit_friction(qd, tau_f - eps * tau, model=model, x0=fit.params.as_vector())
    free = [n for n, se in fit.stderr.items() if np.isfinite(se) and se > 0 and not fit.at_bound.get(n)]
    spread = torque_scale_spread(fit.params, qd, tau, np.ones(qd.size, bool), abs(eps), free)
    assert set(spread) == {"F_c", "F_v"}
    for n in ("F_c", "F_v"):
        shift = abs(getattr(moved.params, n) - getattr(fit.params, n))
        assert spread[n] == pytest.approx(shift, rel=0.1, abs=0.002 * getattr(truth, n))


def test_no_scale_error_no_free_parameter_no_sample_no_spread():
    qd, tau = _swing(0)
    params = CoulombViscousParams(F_v=0.07, F_c=0.6, tau_os=0.0)
    rows = np.ones(qd.size, bool)
    assert torque_scale_spread(params, qd, tau, rows, 0.0, params.names) == {}
    assert torque_scale_spread(params, qd, tau, rows, 0.02, ()) == {}
    assert torque_scale_spread(params, qd, tau, ~rows, 0.02, params.names) == {}
    assert set(torque_scale_spread(params, qd, tau, rows, 0.02, ["F_c", "tau_os"])) == {"F_c"}  # F_v held


def test_a_torque_without_load_moves_nothing_but_its_own_share():
    """A torque that is the friction itself (``tau = tau_f``, a joint moving nothing else): a scale error ``eps``
    scales the friction by ``1 + eps``, so F_c and F_v move by ``sd`` times their values, exactly."""
    qd, _ = _swing(1)
    params = CoulombViscousParams(F_v=0.07, F_c=0.6, tau_os=0.0)
    spread = torque_scale_spread(params, qd, -params.f(qd), np.ones(qd.size, bool), 0.02, params.names)
    assert spread == pytest.approx({"F_c": 0.02 * 0.6, "F_v": 0.02 * 0.07}, rel=1e-6)


def test_the_robot_toml_states_it_and_its_range_is_checked(tmp_path):
    from importlib import resources

    from wbfriction.exceptions import InputError
    from wbfriction.logs.torque import torque_record
    from wbfriction.model.loading import load_robot

    robot = load_robot("go2_logged")
    assert robot.torque_scale_sd["RR_calf_joint"] == pytest.approx(0.0173)
    assert torque_record(robot, "current", None)["scale_sd"] == robot.torque_scale_sd
    assert "scale_sd" not in torque_record(load_robot("go2_walking"), "sensor", None)  # not stated: none carried
    text = resources.files("wbfriction.model.robots").joinpath("go2_logged.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("FL_hip_joint = 0.0173", "FL_hip_joint = 0.8", 1))
    with pytest.raises(InputError, match=r"\[torque_scale_sd\] FL_hip_joint"):
        load_robot(config=bad)
