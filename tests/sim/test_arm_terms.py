"""The arm simulator with friction beyond velocity (issue 40): a load-dependent Coulomb level, a viscous level by
direction, a position ripple and temperature-dependent levels applied at every physics step, and what
:func:`~wbfriction.fit.term_selection.fit_terms` recovers from the log: each injected coefficient within 5 %, no
term on the joints that have none, over 10 seeds."""

from __future__ import annotations

import numpy as np
import pytest

from wbfriction.exceptions import InputError
from wbfriction.fit.options import TermOptions
from wbfriction.fit.selection import fit_friction
from wbfriction.fit.term_selection import fit_terms
from wbfriction.fit.terms import TermFit, term_signals
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.models import CoulombViscousParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import log_from_table
from wbfriction.sim.arm import ArmOptions, simulate_arm

T_REF = 40.0
VELOCITY = CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.1)
TRUTH = {
    "panda_joint4": TermFit(VELOCITY, ("load", "temperature"), 0, {"F_L": 0.02, "F_cT": -0.008, "F_vT": -0.004},
                            reference_temperature=T_REF),
    "panda_joint2": TermFit(VELOCITY, ("direction",), 0, {"dF_v": 0.05}),
    "panda_joint6": TermFit(VELOCITY, ("ripple",), 1, {"ripple_sin1": 0.1, "ripple_cos1": 0.05}),
    "panda_joint3": TermFit(VELOCITY, ("temperature",), 0, {"F_cT": -0.025, "F_vT": -0.005, "rate_T": -0.025},
                            reference_temperature=T_REF),
}
"""Injected: on the elbow k_L = 0.02 / (N·m) and k_Tc = -0.8 %/°C, k_Tv = -2 %/°C (linear) over a 25-55 °C warm-up;
a viscous level 25 % higher one way than the other on the shoulder; a ripple of 0.11 N·m on the wrist (whose angles
span 2 rad); on the upper arm both levels falling exponentially, ``F exp(-0.025 (T - T_ref))`` (Bittencourt's law:
the friction halves over the warm-up)."""


def run(seed: int, noisy: bool = False) -> dict[str, TermFit]:
    """60 s of the Panda's excitation, 5 physics steps per sample (with 2, the friction from each step's starting
    velocity biases dF_v by 9 %), 0.05 N·m of torque noise and exact positions (central differences: no smoothing),
    every joint's terms fitted on the estimate. ``noisy``: the
    studies' sensor noise (1e-4 rad, 19-bit encoders) and the default route (the momentum route's window), the
    velocity model and the terms passed through the estimate's smoother."""
    from wbfriction.model import load_robot

    robot = load_robot("panda")
    others = {j: VELOCITY for j in robot.actuated if j not in TRUTH}
    noise = {"position_std": 1e-4, "encoder_bits": 19} if noisy else {"encoder_bits": None}
    sim = simulate_arm(robot, others, options=ArmOptions(duration=60.0, substeps=5, torque_std=0.05, seed=seed,
                                                        temperature=(25.0, 55.0), **noise), terms=TRUTH)
    options = EstimateOptions() if noisy else EstimateOptions(diff="central", route="acceleration")
    est = estimate_log(robot, log_from_table(sim.table, robot, "arm"), options)
    out = {}
    for i, joint in enumerate(est.joints):
        use = est.valid[:, i] & np.isfinite(est.tau_f[:, i]) & (np.abs(est.qd[:, i]) > 0.02)
        signals = term_signals(est, i)  # the log's angles and temperatures, the model's rigid-body torque
        base = fit_friction(est.qd[:, i], est.tau_f[:, i], model="coulomb-viscous", mask=use, smoother=est.smoother)
        assert base.params is not None
        out[joint] = fit_terms(base.params, est.qd[:, i], est.tau_f[:, i], use, signals,
                               TermOptions(reference_temperature=T_REF), smoother=est.smoother)
    return out


@pytest.mark.slow
def test_the_simulated_terms_are_recovered_and_no_other():
    worst: dict[str, float] = {}
    for seed in range(10):
        fits = run(seed)
        for joint, fit in fits.items():
            truth = TRUTH.get(joint)
            assert set(fit.kept) == (set() if truth is None else set(truth.kept)), (seed, joint, fit.reasons)
            if truth is None:
                continue
            size = max(abs(v) for v in truth.coefficients.values())
            for name, value in truth.coefficients.items():
                worst[name] = max(worst.get(name, 0.0), abs(fit.coefficients[name] / value - 1))
                tolerance = 0.05 * (abs(value) if value else size)
                assert abs(fit.coefficients[name] - value) < tolerance, (seed, joint, name, fit.coefficients)
            assert fit.params.F_c == pytest.approx(1.0, rel=0.05) and fit.params.F_v == pytest.approx(0.2, rel=0.05)
            assert (fit.temperature_rate != 0.0) == ("rate_T" in truth.coefficients), (seed, joint, fit.reasons)
    print("\nworst relative error over 10 seeds", {k: f"{100 * v:.2f} %" for k, v in worst.items()})


@pytest.mark.slow
def test_through_the_estimates_smoother_on_noisy_positions():
    """The studies' sensor noise and the momentum route (its window the estimate's smoother): no term where there is
    none; the load, temperature (both laws) and ripple terms recovered within 5 %. The viscous level by direction
    (dF_v 25 % of F_v) is not kept: its held-out gain under this noise stays below the 2 % rule (issue 40's note)."""
    fits = run(0, noisy=True)
    for joint, fit in fits.items():
        truth = TRUTH.get(joint)
        assert set(fit.kept) <= (set() if truth is None else set(truth.kept)), (joint, fit.reasons)
    for joint in ("panda_joint3", "panda_joint4", "panda_joint6"):
        assert set(fits[joint].kept) == set(TRUTH[joint].kept), fits[joint].reasons
        for name, value in TRUTH[joint].coefficients.items():
            assert fits[joint].coefficients[name] == pytest.approx(value, rel=0.05), (joint, name)


def test_a_temperature_term_needs_the_temperature_and_joints_are_checked():
    from wbfriction.model import load_robot

    robot = load_robot("panda")
    with pytest.raises(InputError, match="temperature"):
        simulate_arm(robot, {}, options=ArmOptions(duration=0.1), terms={"panda_joint4": TRUTH["panda_joint4"]})
    with pytest.raises(InputError, match="not a joint"):
        simulate_arm(robot, {}, options=ArmOptions(duration=0.1), terms={"elbow": TRUTH["panda_joint2"]})
