"""The model choice on data it was not fitted on, and transitions kept only where the data resolve them (issue 63)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.bound import at_least_bound
from wbfriction.fit.selection import fit_friction
from wbfriction.fit.solve import stick_speed
from wbfriction.fit.transition import creep_floor, transition_counts, unresolved
from wbfriction.friction.models import CoulombViscousParams, FrictionParams, StribeckParams


def crawl_leg(seed: int, n_steps: int = 12, rate: float = 400.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A walking leg's joint velocity [rad/s] at ``rate`` [Hz]: a stance (three quarters of each step) that creeps
    at 0.002-0.015 rad/s, then a swing there and back (peak 1.5 rad/s); its friction torque ``tau_f`` [N·m]:
    Coulomb-viscous (F_c 0.8, F_v 0.3) where it swings, and in stance what a loaded contact gives, any value up to the
    Coulomb level and no function of the velocity (as MuJoCo's soft friction loss with a load does); and the truth
    on the samples that move (the creep's friction is no model's)."""
    rng = np.random.default_rng(seed)
    step, qd, tau_f = int(rate), [], []
    truth = CoulombViscousParams(F_v=0.3, F_c=0.8, tau_os=0.0)
    for _ in range(n_steps):
        stance = int(0.75 * step)
        creep = rng.uniform(0.002, 0.015) * np.sign(rng.normal()) * (1 + 0.3 * np.sin(np.linspace(0, 6, stance)))
        # creep: the friction follows the contact's load, a smooth presliding curve well below the Coulomb level
        qd.append(creep)
        tau_f.append(-0.8 * np.tanh(creep / 0.004) * rng.uniform(0.2, 0.6))
        t = np.linspace(0.0, 1.0, step - stance, endpoint=False)
        swing = 1.5 * np.sin(2 * np.pi * t)
        qd.append(swing)
        tau_f.append(-truth.f(swing))
    qd_all, tau_all = np.concatenate(qd), np.concatenate(tau_f)
    return qd_all, tau_all + rng.normal(0.0, 0.01, qd_all.size), np.abs(qd_all) > 0.05


def test_creep_below_a_transition_is_no_evidence_for_it():
    """A stance leg creeping inside the friction's transition: the automatic choice takes no Stribeck or (3.5) curve
    whose transition sits among the creep, and its Coulomb-viscous fit is within 5 % of the truth."""
    qd, tau_f, moving = crawl_leg(0)
    fit = fit_friction(qd, tau_f, model="auto", mask=moving, stick=stick_speed(0.0))  # the default floor
    assert fit.model == "coulomb-viscous", fit.selection.reason
    assert abs(fit.params.F_c - 0.8) < 0.05 * 0.8 and abs(fit.params.F_v - 0.3) < 0.05 * 0.3
    # the creep given as well (3-D foot forces determine the stance): at `fit --stick-floor 0.02` its lingering
    # samples are left out as a stuck joint's, the values the same
    fit_all = fit_friction(qd, tau_f, model="auto", stick=stick_speed(0.0, 0.02))
    assert abs(fit_all.params.F_c - 0.8) < 0.05 * 0.8 and abs(fit_all.params.F_v - 0.3) < 0.05 * 0.3
    assert fit_all.n_stuck > 0.5 * qd.size
    # at the default floor (3e-3 rad/s) the creep is fitted: a (3.5) curve may place its v_s among it (the creep's
    # friction is then its Stribeck term), F_c and F_v still within 5 %
    creeping = fit_friction(qd, tau_f, model="auto", stick=stick_speed(0.0))
    assert abs(creeping.params.F_c - 0.8) < 0.05 * 0.8 and abs(creeping.params.F_v - 0.3) < 0.05 * 0.3


def test_a_resolved_stribeck_curve_is_still_chosen():
    """Slow passes through a Stribeck velocity of 0.15 rad/s, fast ones beyond: the transition is resolved and the
    Stribeck family chosen, its v_s within 10 %."""
    t = np.arange(0.0, 8.0, 2e-3)
    qd = 1.2 * np.sin(2 * np.pi * 0.31 * t) + 0.4 * np.sin(2 * np.pi * 1.7 * t + 0.5)
    truth = StribeckParams(F_v=0.3, F_c=0.6, F_s=1.2, v_s=0.15, tau_os=-0.2)
    tau_f = truth.torque(qd) + np.random.default_rng(1).normal(0.0, 0.05, qd.size)
    fit = fit_friction(qd, tau_f, model="auto")
    assert fit.model == "stribeck" and fit.selection.scores[1].unresolved == ()
    assert abs(fit.params.v_s - 0.15) < 0.1 * 0.15


def test_transition_counts_and_floor():
    qd = np.concatenate([np.full(30, 0.006), np.full(25, 0.03), np.full(40, -0.05), np.full(7, 0.2)])
    assert transition_counts(0.04, qd, 0.02) == (25, 7)  # below: [0.02, 0.04), settled: from 0.08
    assert transition_counts(0.04, qd, 0.0) == (55, 7)
    assert transition_counts(0.02, qd, 0.0) == (30, 47)  # settled from 0.04
    assert transition_counts(0.01, qd, 0.02) == (0, 72)  # in the noise: nothing below counts
    assert creep_floor(0.0) == 0.0 and creep_floor(0.01) == 0.03
    creeping = StribeckParams(F_v=0.3, F_c=0.6, F_s=1.0, v_s=0.01, tau_os=0.0)
    assert unresolved(creeping, qd, 0.007)[0].startswith("v_s 0.01 rad/s (0 samples below")
    assert unresolved(creeping, qd[30:])[0].startswith("v_s 0.01 rad/s (0 samples below")
    resolved = StribeckParams(F_v=0.3, F_c=0.6, F_s=1.0, v_s=0.04, tau_os=0.0)
    assert unresolved(resolved, qd) == ()
    # a Stribeck curve decaying over the whole range of speeds (up to 0.2 rad/s): nothing where it has settled
    decaying = StribeckParams(F_v=0.3, F_c=0.0, F_s=1.0, v_s=0.15, tau_os=0.0)
    assert unresolved(decaying, qd) == ("v_s 0.15 rad/s (95 samples below, 0 beyond 2 times it)",)
    # no Stribeck effect (F_s = F_c) or a tanh at its step: no transition to resolve
    assert unresolved(StribeckParams(F_v=0.3, F_c=0.6, F_s=0.6, v_s=0.01, tau_os=0.0), qd) == ()
    assert unresolved(FrictionParams(F_v=0.3, F_c=0.6, S=0.0, v_s=0.1, tau_os=0.0, a=1e4), qd) == ()
    assert unresolved(FrictionParams(F_v=0.3, F_c=0.6, S=0.0, v_s=0.1, tau_os=0.0, a=400.0), qd)[0].startswith("1/a")


@settings(max_examples=50, deadline=None)
@given(st.integers(1, 5), st.integers(0, 2**31 - 1))
def test_no_standard_error_below_its_bound(p, seed):
    """:func:`at_least_bound`: every standard error at least its bound, none lowered, the correlations kept."""
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(p, p))
    cov = a @ a.T + 1e-3 * np.eye(p)
    bound = np.abs(rng.normal(size=p)) * np.sqrt(np.diag(cov)) * 1.5
    out = at_least_bound(cov, bound)
    se, se_out = np.sqrt(np.diag(cov)), np.sqrt(np.diag(out))
    assert np.all(se_out >= np.maximum(se, bound) * (1 - 1e-12))
    np.testing.assert_allclose(se_out, np.maximum(se, bound), rtol=1e-12)
    np.testing.assert_allclose(out / np.outer(se_out, se_out), cov / np.outer(se, se), atol=1e-12)
