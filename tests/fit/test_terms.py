"""Friction beyond velocity (issue 40): each term's regressor against the physical model it stands for (finite
differences), and on simulated joints with known terms, each coefficient recovered and each absent term left out."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError, OptionError
from wbfriction.fit.options import TermOptions
from wbfriction.fit.selection import fit_friction
from wbfriction.fit.term_selection import fit_terms
from wbfriction.fit.terms import (
    TermCheck,
    TermFit,
    TermSignals,
    term_basis,
    velocity_basis,
    with_coefficients,
)
from wbfriction.friction.models import CoulombViscousParams, FrictionParams
from wbfriction.friction.options import TERMS

RATE = 1000.0
T_REF = 40.0


def trajectory(seed: int, seconds: float = 20.0) -> tuple[np.ndarray, np.ndarray, TermSignals]:
    """A joint's motion (sums of sines: positions over a few radians, speeds up to about 2 rad/s), a load torque
    of tens of N·m varying with it, a temperature warming from 25 to 55 °C."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 1.0 / RATE)
    w = rng.uniform(0.3, 1.5, 3)
    amp = rng.uniform(0.4, 1.0, 3)
    phase = rng.uniform(0, 2 * np.pi, 3)
    q = (amp[:, None] * np.sin(w[:, None] * t + phase[:, None])).sum(0) * 2.0
    qd = (2.0 * amp[:, None] * w[:, None] * np.cos(w[:, None] * t + phase[:, None])).sum(0)
    tau_load = 25.0 * np.sin(0.9 * t + rng.uniform(0, 6)) + 10.0 * np.cos(q)
    temperature = 25.0 + 30.0 * t / seconds
    return t, qd, TermSignals(q=q, tau_load=tau_load, temperature=temperature)


TRUE = {"F_L": 0.02, "dF_v": 0.04, "ripple_sin1": 0.10, "ripple_cos1": 0.05, "ripple_sin2": 0.03,
        "ripple_cos2": -0.02, "F_cT": -0.008, "F_vT": -0.002}
"""Injected coefficients: k_L = 0.02 / (N·m) (+50 % of F_c at 25 N·m), dF_v 20 % of F_v, a ripple of 0.11 N·m and a
second harmonic, k_Tc = -0.8 %/°C and k_Tv = -1 %/°C (Bittencourt: tens of percent over the temperature range)."""
TERM_COEFFICIENTS = {"load": ("F_L",), "direction": ("dF_v",),
                     "ripple": ("ripple_sin1", "ripple_cos1", "ripple_sin2", "ripple_cos2"),
                     "temperature": ("F_cT", "F_vT")}


def physical_f(params: CoulombViscousParams, qd: np.ndarray, s: TermSignals, present: tuple[str, ...], *,
               k_L: float = 0.0, dF_v: float = 0.0, ripple: tuple[float, ...] = (), k_Tc: float = 0.0,
               k_Tv: float = 0.0) -> np.ndarray:
    """The joint's friction written in its physical parameters, independently of :mod:`wbfriction.fit.terms`:
    ``F_c (1 + k_L |tau_load|)(1 + k_Tc dT) sgn(qd) + (F_v + dF_v sgn(qd))(1 + k_Tv dT) qd + tau_os + ripple``, terms
    not ``present`` left out (a product of two terms is not modelled: each term alone)."""
    dT = s.temperature - T_REF
    F_c = params.F_c * (1 + (k_L * np.abs(s.tau_load) if "load" in present else 0)
                        + (k_Tc * dT if "temperature" in present else 0))
    F_v = params.F_v + (dF_v * np.sign(qd) if "direction" in present else 0) \
        + (params.F_v * k_Tv * dT if "temperature" in present else 0)
    out = F_c * np.sign(qd) + F_v * qd + params.tau_os
    if "ripple" in present:
        for h in range(len(ripple) // 2):
            out = out + ripple[2 * h] * np.sin((h + 1) * s.q) + ripple[2 * h + 1] * np.cos((h + 1) * s.q)
    return out


TRUTH = CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.1)
PHYSICAL = {"k_L": TRUE["F_L"] / TRUTH.F_c, "dF_v": TRUE["dF_v"],
            "ripple": tuple(TRUE[n] for n in TERM_COEFFICIENTS["ripple"]), "k_Tc": TRUE["F_cT"] / TRUTH.F_c,
            "k_Tv": TRUE["F_vT"] / TRUTH.F_v}


@pytest.mark.parametrize("term", TERMS)
def test_each_regressor_is_the_derivative_of_the_physical_model(term):
    """The term's regressors, times its coefficients, are the physical model's change (the terms are linear in their
    coefficients: the derivative by a central finite difference of the physical parameter, scaled)."""
    _, qd, s = trajectory(0, 2.0)
    names, X = term_basis(term, TRUTH, qd, s, harmonics=2, reference_temperature=T_REF)
    with_term = physical_f(TRUTH, qd, s, (term,), **PHYSICAL)
    without = physical_f(TRUTH, qd, s, ())
    assert X @ np.array([TRUE[n] for n in names]) == pytest.approx(with_term - without, abs=1e-12)
    # finite differences in each physical parameter against the regressor, scaled by the chain rule
    h = 1e-6
    scale = {"k_L": TRUTH.F_c, "dF_v": 1.0, "k_Tc": TRUTH.F_c, "k_Tv": TRUTH.F_v}
    for name, column in zip(names, X.T):
        if name.startswith("ripple"):
            continue  # the ripple's coefficients are its physical parameters
        key = {"F_L": "k_L", "dF_v": "dF_v", "F_cT": "k_Tc", "F_vT": "k_Tv"}[name]
        up = physical_f(TRUTH, qd, s, (term,), **{**PHYSICAL, key: PHYSICAL[key] + h})
        down = physical_f(TRUTH, qd, s, (term,), **{**PHYSICAL, key: PHYSICAL[key] - h})
        assert (up - down) / (2 * h) / scale[key] == pytest.approx(column, abs=1e-6)


def test_the_velocity_basis_is_the_model():
    qd = np.linspace(-2, 2, 401)
    p = FrictionParams(F_v=0.2, F_c=1.0, S=0.3, v_s=0.15, tau_os=-0.1, a=30.0)
    _, B, c = velocity_basis(p, qd)
    assert B @ c == pytest.approx(p.f(qd), abs=1e-12)
    back = with_coefficients(p, c)
    assert back.as_vector() == pytest.approx(p.as_vector(), rel=1e-12)  # S back from F_c S


def joint(seed: int, present: tuple[str, ...], noise: float = 0.05) -> tuple[np.ndarray, np.ndarray, TermSignals]:
    """60 s of a joint whose friction has the terms ``present``, its estimate with ``noise`` [N·m]."""
    _, qd, s = trajectory(seed, 60.0)
    f = physical_f(TRUTH, qd, s, present, **PHYSICAL)
    tau_f = -f + noise * np.random.default_rng(100 + seed).standard_normal(qd.size)
    return qd, tau_f, s


CASES = [(), ("load",), ("direction",), ("ripple",), ("temperature",), ("load", "ripple", "temperature")]


@pytest.mark.parametrize("present", CASES, ids=lambda p: "+".join(p) or "none")
def test_terms_in_the_truth_are_recovered_and_others_left_out(present):
    """10 seeds, 60 s at 1 kHz, torque noise 0.05 N·m: the velocity model fitted first (Coulomb-viscous, as the
    truth), then the terms: exactly those present kept, each coefficient within 5 %, F_c and F_v too."""
    for seed in range(10):
        qd, tau_f, s = joint(seed, present)
        use = np.abs(qd) > 0.02
        base = fit_friction(qd, tau_f, model="coulomb-viscous", mask=use)
        assert base.params is not None
        fit = fit_terms(base.params, qd, tau_f, use, s, TermOptions(reference_temperature=T_REF))
        assert set(fit.kept) == set(present), (seed, fit.kept, fit.reasons)
        for term in present:
            names = TERM_COEFFICIENTS[term]
            if term == "ripple":
                assert fit.harmonics == 2, (seed, fit.harmonics)
            for n in names:
                assert fit.coefficients[n] == pytest.approx(TRUE[n], rel=0.05), (seed, n, fit.coefficients)
                assert fit.stderr[n] < 0.05 * abs(TRUE[n]), (seed, n, fit.stderr)
        assert fit.params.F_c == pytest.approx(TRUTH.F_c, rel=0.05) and fit.params.F_v == pytest.approx(TRUTH.F_v,
                                                                                                          rel=0.05)


def test_the_ripple_is_not_friction():
    qd, tau_f, s = joint(0, ("ripple",))
    use = np.abs(qd) > 0.02
    base = fit_friction(qd, tau_f, model="coulomb-viscous", mask=use)
    fit = fit_terms(base.params, qd, tau_f, use, s)
    assert isinstance(fit, TermFit) and fit.kept == ("ripple",)
    ripple = fit.ripple(qd, s)
    truth = physical_f(TRUTH, qd, s, ("ripple",), **PHYSICAL) - physical_f(TRUTH, qd, s, ())
    assert np.sqrt(np.mean((ripple - truth) ** 2)) < 0.01 * np.sqrt(np.mean(truth**2)) + 2e-3
    assert fit.friction(qd, s) == pytest.approx(fit.params.f(qd))  # the dissipative part: the velocity model
    assert fit.torque(qd, s) == pytest.approx(-(fit.params.f(qd) + ripple))
    assert fit.derived["ripple_rms"] == pytest.approx(np.std(truth[use]), rel=0.05)


def test_the_ripple_is_held_outside_the_angles_it_was_fitted_on():
    """A ripple fitted on part of a turn predicts nothing new beyond it: outside its angles it is held at the value
    at the nearest one (a Fourier series would run away there)."""
    qd, tau_f, s = joint(0, ("ripple",))
    use = (np.abs(qd) > 0.02) & (np.abs(s.q) < 1.0)
    base = fit_friction(qd, tau_f, model="coulomb-viscous", mask=use)
    fit = fit_terms(base.params, qd, tau_f, use, s)
    assert "ripple" in fit.kept and fit.q_range is not None and -1.0 <= fit.q_range[0] < fit.q_range[1] <= 1.0
    far = TermSignals(q=np.array([-3.0, -1.0, 1.0, 3.0]))
    ripple = fit.ripple(np.ones(4), far)
    assert ripple[0] == pytest.approx(fit.ripple(np.ones(1), TermSignals(q=np.array([fit.q_range[0]])))[0])
    assert ripple[3] == pytest.approx(fit.ripple(np.ones(1), TermSignals(q=np.array([fit.q_range[1]])))[0])


@given(st.floats(-3, 3), st.floats(-4, 4), st.floats(-50, 50), st.floats(0, 80))
@settings(max_examples=200, deadline=None)
def test_one_sample_in_floats_is_the_model(qd, q, tau_load, temperature):
    """What a simulator's physics step calls (:meth:`TermFit.torque_at`) is :meth:`TermFit.torque` of that sample,
    for the tanh model with every term, the ripple held at its angles' edge."""
    fit = TermFit(FrictionParams(F_v=0.2, F_c=1.0, S=0.3, v_s=0.1, tau_os=0.05, a=30.0), TERMS, 2,
                  {"F_L": 0.02, "dF_v": 0.03, "ripple_sin1": 0.1, "ripple_cos1": -0.05, "ripple_sin2": 0.02,
                   "ripple_cos2": 0.01, "F_cT": -0.008, "F_vT": -0.002}, reference_temperature=40.0,
                  q_range=(-2.0, 2.5))
    s = TermSignals(q=np.array([q]), tau_load=np.array([tau_load]), temperature=np.array([temperature]))
    assert fit.torque_at(qd, q, tau_load, temperature) == pytest.approx(fit.torque(np.array([qd]), s)[0],
                                                                         rel=1e-12, abs=1e-12)


@given(st.floats(0.01, 3), st.floats(-50, 50))
@settings(max_examples=100, deadline=None)
def test_the_friction_at_a_speed_under_a_load_is_the_models_odd_part(v, tau_load):
    """What a fleet's row reports (:meth:`TermFit.speed_friction` at the log's load) is ``(f(+v) - f(-v)) / 2`` of the
    dissipative friction under that load at the reference temperature, every kept term applied; its standard error
    the delta method's through the covariance (F_L's variance alone: ``|g| |load|`` times its standard error)."""
    fit = TermFit(FrictionParams(F_v=0.2, F_c=1.0, S=0.3, v_s=0.1, tau_os=0.05, a=30.0), TERMS, 1,
                  {"F_L": 0.02, "dF_v": 0.03, "ripple_sin1": 0.1, "ripple_cos1": -0.05, "F_cT": -0.008, "F_vT": -0.002},
                  reference_temperature=40.0, covariance=np.diag([0.0, 0.0, 0.0, 0.0, 1e-6, 0.0, 0.0, 0.0, 0.0, 0.0]))
    s = TermSignals(q=np.zeros(2), tau_load=np.full(2, tau_load), temperature=np.full(2, 40.0))
    f = fit.friction(np.array([v, -v]), s)
    value, se = fit.speed_friction(v, tau_load)
    assert value == pytest.approx(0.5 * (f[0] - f[1]), rel=1e-12, abs=1e-12)
    assert se == pytest.approx(np.tanh(30.0 * v) * abs(tau_load) * 1e-3, rel=1e-9, abs=1e-15)
    assert fit.speed_friction(v)[0] == pytest.approx(value - 0.02 * abs(tau_load) * np.tanh(30.0 * v), abs=1e-12)


def test_options_are_checked_where_they_are_defined():
    with pytest.raises(OptionError, match="--terms"):
        TermOptions(terms=("wear",))  # type: ignore[arg-type]
    with pytest.raises(OptionError, match="--max-harmonic"):
        TermOptions(max_harmonic=0)


def test_a_fit_reads_back_as_written():
    """The parameters JSON's ``terms`` (:meth:`TermFit.to_dict`) through JSON text and back: the same fit, and the
    same statuses."""
    import json

    qd, tau_f, s = joint(1, ("load", "ripple", "temperature"))
    use = np.abs(qd) > 0.02
    base = fit_friction(qd, tau_f, model="coulomb-viscous", mask=use)
    fit = fit_terms(base.params, qd, tau_f, use, s, TermOptions(reference_temperature=T_REF))
    back = TermFit.from_dict(json.loads(json.dumps(fit.to_dict())))
    assert back == fit and back.verdicts() == fit.verdicts()
    assert fit.to_dict()["status"] == {"load": "ok", "ripple": "ok", "temperature": "ok"}
    with pytest.raises(InputError, match="unknown term 'wear'"):
        TermFit.from_dict({**fit.to_dict(), "kept": ["wear"]})
    with pytest.raises(InputError, match="missing key 'coefficients'"):
        TermFit.from_dict({k: v for k, v in fit.to_dict().items() if k != "coefficients"})


def test_statuses_say_what_the_data_do_not_carry():
    """A coefficient whose standard error passes half its value is weak; the other route's value beyond three
    combined standard errors (and 2 %) makes the term's routes disagree, naming both values."""
    fit = TermFit(CoulombViscousParams(F_v=0.2, F_c=1.0), ("load", "direction"), 0, {"F_L": 0.02, "dF_v": 0.04},
                  {"F_L": 0.001, "dF_v": 0.03})
    assert fit.verdicts()["load"].ok
    assert fit.verdicts()["direction"].status == "weak" and "dF_v" in fit.verdicts()["direction"].reason
    other = TermCheck("momentum", {"F_L": 0.03, "dF_v": 0.04}, {"F_L": 0.001, "dF_v": 0.03})
    off = replace(fit, check=other).verdicts()["load"]
    assert off.status == "routes disagree" and "0.02" in off.reason and "0.03" in off.reason
    assert "momentum" in off.reason
    near = TermCheck("momentum", {"F_L": 0.0202, "dF_v": 0.04}, {"F_L": 0.001, "dF_v": 0.03})
    assert replace(fit, check=near).verdicts()["load"].ok
    ripple = TermFit(CoulombViscousParams(F_v=0.2, F_c=1.0), ("ripple",), 1, {"ripple_sin1": 0.1, "ripple_cos1": 0.0},
                     {"ripple_rms": 0.004}, {"ripple_rms": 0.07})  # judged by its size
    assert ripple.verdicts()["ripple"].ok
    assert replace(ripple, stderr={"ripple_rms": 0.05}).verdicts()["ripple"].status == "weak"
    other = TermCheck("momentum", {"ripple_rms": 0.03}, {"ripple_rms": 0.004})
    assert replace(ripple, check=other).verdicts()["ripple"].status == "routes disagree"


def test_the_ripples_size_has_the_spread_of_its_repeats():
    """The ripple's size and its standard error (:func:`ripple_size`, the delta method through the coefficients'
    covariance): over 40 noise draws of one joint whose angles span less than a turn, the sizes' spread is within
    35 % of the standard error each draw states (white torque noise, so the Newey-West sum adds little)."""
    from wbfriction.fit.term_design import ripple_size

    _, qd, s = trajectory(3, 20.0)
    assert s.q is not None
    truth = physical_f(TRUTH, qd, s, ("ripple",), **PHYSICAL)
    X = np.column_stack([velocity_basis(TRUTH, qd)[1], term_basis("ripple", TRUTH, qd, s, harmonics=2)[1]])
    names = ("F_v", "F_c", "tau_os", "ripple_sin1", "ripple_cos1", "ripple_sin2", "ripple_cos2")
    from wbfriction.fit.regression import parameter_covariance

    sizes, errors = [], []
    rng = np.random.default_rng(0)
    for _ in range(40):
        y = truth + 0.3 * rng.standard_normal(qd.size)
        coef = np.linalg.lstsq(X, y, rcond=None)[0]
        size, se = ripple_size(s.q, 2, names, coef, parameter_covariance(X, y - X @ coef))
        sizes.append(size)
        errors.append(se)
    assert np.std(sizes) == pytest.approx(np.mean(errors), rel=0.35)
    assert np.mean(sizes) == pytest.approx(np.std(truth - physical_f(TRUTH, qd, s, ())), rel=0.05)


def test_a_magnitude_the_terms_would_drive_negative_is_held_at_zero():
    """A joint whose estimate has a negative viscous slope (an inertia error, say) and a ripple: the velocity fit
    puts F_v at its bound of zero; refitted with the ripple, F_v is held there (``at_bound``, standard error 0), not
    printed below zero as a friction that generates power."""
    qd, tau_f, s = joint(2, ("ripple",))
    tau_f = tau_f + (TRUTH.F_v + 0.15) * qd  # f's viscous slope: 0.2 - 0.35 = -0.15 N·m s/rad
    use = np.abs(qd) > 0.02
    base = fit_friction(qd, tau_f, model="coulomb-viscous", mask=use)
    assert base.params is not None and base.params.F_v == pytest.approx(0.0, abs=1e-9)
    fit = fit_terms(base.params, qd, tau_f, use, s)
    assert fit.kept == ("ripple",) and fit.params.F_v == 0.0
    assert fit.at_bound == ("F_v",) and fit.stderr["F_v"] == 0.0 and fit.stderr["F_c"] > 0.0


def test_a_fit_with_terms_reports_the_model_its_status_judges():
    """A velocity fit that is weak alone (F_c 0.04 ± 0.08, lwr_6's on the KUKA) but well determined once its ripple is
    fitted (0.061 ± 0.005): its status is the refitted model's, and so are the numbers shown beside it
    (:meth:`~wbfriction.fit.result.FitResult.reported`); no Cramér-Rao bound of the other model is shown with
    them. Without terms kept, the fit reports itself."""
    from wbfriction.fit.result import FitResult

    velocity = CoulombViscousParams(F_v=0.0, F_c=0.04, tau_os=-0.1)
    fit = FitResult("j", 5000, velocity, {"F_v": 0.13, "F_c": 0.08, "tau_os": 0.04}, 0.05, True, "",
                    at_bound={"F_v": True}, speed=1.0, crb={"F_c": 0.03, "F_v": 0.07})
    assert fit.verdict().status == "weak" and fit.reported() is fit
    terms = TermFit(CoulombViscousParams(F_v=0.0, F_c=0.061, tau_os=-0.1), ("ripple",), 1,
                    {"ripple_sin1": 0.2, "ripple_cos1": 0.1}, {"F_v": 0.0, "F_c": 0.005, "tau_os": 0.6,
                                                                "ripple_rms": 0.008}, {"ripple_rms": 0.225},
                    at_bound=("F_v",))
    with_terms = replace(fit, terms=terms)
    shown = with_terms.reported()
    assert with_terms.verdict().ok and shown.verdict() == with_terms.verdict()
    assert shown.params == terms.params and shown.stderr["F_c"] == 0.005 and shown.crb == {}
    assert shown.at_bound == {"F_v": True, "F_c": False, "tau_os": False}
    none_kept = replace(fit, terms=replace(terms, kept=(), harmonics=0))
    assert none_kept.reported() is none_kept and none_kept.verdict().status == "weak"


RATE_T = -0.015
"""An exponential temperature law's rate [1/°C]: both levels fall by 1.5 %/°C at T_ref and flatten as the joint
warms, halving between 20 and 70 °C (Bittencourt's exponential decrease)."""


def exponential_joint(seed: int, law_rate: float, noise: float = 0.05):
    """60 s of a Coulomb-viscous joint warming from 20 to 70 °C whose levels are ``F exp(law_rate (T - T_ref))``
    (``law_rate`` 0: constant), written in the physical parameters (independently of the module), and its estimate
    with ``noise`` [N·m]."""
    t, qd, s = trajectory(seed, 60.0)
    s = replace(s, temperature=20.0 + 50.0 * t / 60.0)
    scale = np.exp(law_rate * (s.temperature - T_REF))
    f = TRUTH.F_c * scale * np.sign(qd) + TRUTH.F_v * scale * qd + TRUTH.tau_os
    return qd, -f + noise * np.random.default_rng(200 + seed).standard_normal(qd.size), s


def test_the_temperature_laws_regressors_and_rate_column_are_the_exponential():
    """``F + F_T phi(dT)`` with ``F_T = rate F`` is ``F exp(rate dT)``; the rate column is its derivative (central
    finite differences); rate 0 is the linear law."""
    from wbfriction.fit.terms import temperature_shape, temperature_shape_rate

    dT = np.linspace(-30.0, 30.0, 61)
    for rate in (-0.02, -0.005, 0.01):
        assert 2.0 + 2.0 * rate * temperature_shape(dT, rate) == pytest.approx(2.0 * np.exp(rate * dT), rel=1e-12)
        h = 1e-7
        numeric = (temperature_shape(dT, rate + h) - temperature_shape(dT, rate - h)) / (2 * h)
        assert temperature_shape_rate(dT, rate) == pytest.approx(numeric, rel=1e-6, abs=1e-9)
    assert np.array_equal(temperature_shape(dT, 0.0), dT)
    assert temperature_shape_rate(dT, 1e-9) == pytest.approx(temperature_shape_rate(dT, 0.0), rel=1e-6)


@pytest.mark.parametrize("law_rate", [RATE_T, 0.0], ids=["exponential", "constant"])
def test_the_exponential_temperature_law_is_chosen_where_the_truth_has_it(law_rate):
    """10 seeds, 0.05 N·m of noise: with an exponential truth the exponential law is kept (``auto``), its rate, F_cT =
    rate F_c and F_vT = rate F_v within 5 %, each within three standard errors; with a linear truth (the case above)
    the linear law is kept, every seed; with no temperature effect, no temperature term."""
    for seed in range(10):
        if law_rate:
            qd, tau_f, s = exponential_joint(seed, law_rate)
        else:  # the linear truth of the cases above
            qd, tau_f, s = joint(seed, ("temperature",))
        use = np.abs(qd) > 0.02
        base = fit_friction(qd, tau_f, model="coulomb-viscous", mask=use)
        assert base.params is not None
        options = TermOptions(terms=("temperature",), reference_temperature=T_REF)
        fit = fit_terms(base.params, qd, tau_f, use, s, options)
        assert fit.kept == ("temperature",), (seed, fit.reasons)
        if not law_rate:
            assert fit.temperature_rate == 0.0 and "law linear" in fit.reasons["temperature"], (seed, fit.reasons)
            continue
        assert "law exponential" in fit.reasons["temperature"], (seed, fit.reasons)
        truth = {"rate_T": law_rate, "F_cT": law_rate * TRUTH.F_c, "F_vT": law_rate * TRUTH.F_v}
        for n, v in truth.items():
            assert fit.coefficients[n] == pytest.approx(v, rel=0.05), (seed, n, fit.coefficients)
            assert abs(fit.coefficients[n] - v) < 3 * fit.stderr[n], (seed, n, fit.coefficients[n], fit.stderr[n])
        assert fit.params.F_c == pytest.approx(TRUTH.F_c, rel=0.05) and fit.verdicts()["temperature"].ok
        one = TermSignals(temperature=np.array([65.0]))  # the model at one sample, in arrays and in floats
        expected = -(TRUTH.F_c + TRUTH.F_v * 0.5) * np.exp(law_rate * 25.0) - TRUTH.tau_os
        assert fit.torque_at(0.5, temperature=65.0) == pytest.approx(fit.torque(np.array([0.5]), one)[0], rel=1e-12)
        assert fit.torque_at(0.5, temperature=65.0) == pytest.approx(expected, rel=0.03)


def test_a_fit_with_the_exponential_law_reads_back_and_the_linear_law_can_be_forced():
    import json

    qd, tau_f, s = exponential_joint(0, RATE_T)
    use = np.abs(qd) > 0.02
    base = fit_friction(qd, tau_f, model="coulomb-viscous", mask=use)
    fit = fit_terms(base.params, qd, tau_f, use, s, TermOptions(terms=("temperature",), reference_temperature=T_REF))
    back = TermFit.from_dict(json.loads(json.dumps(fit.to_dict())))
    assert back == fit and back.temperature_rate == fit.temperature_rate != 0.0
    linear = fit_terms(base.params, qd, tau_f, use, s, TermOptions(terms=("temperature",), reference_temperature=T_REF,
                                                                    temperature_law="linear"))
    assert linear.temperature_rate == 0.0 and "rate_T" not in linear.coefficients
    with pytest.raises(OptionError, match="--temperature-law"):
        TermOptions(temperature_law="arrhenius")  # type: ignore[arg-type]


def test_a_load_law_that_changes_later_in_the_log_does_not_predict():
    """Issue 52: a load term is kept where it predicts the log's later stretch; one whose law changes there (the
    last 30 % with twice the load coefficient, a stand-in for a term that does not carry over) is not ``ok``: fitted
    on the earlier samples its torque departs on the later ones beyond the noise and its standard errors."""
    t, qd, s = trajectory(3, 30.0)
    rng = np.random.default_rng(3)
    steady = physical_f(TRUTH, qd, s, ("load",), k_L=PHYSICAL["k_L"]) + rng.normal(0.0, 0.02, qd.size)
    use = np.abs(qd) > 0.05
    params = fit_friction(qd, -steady, model="coulomb-viscous", mask=use).params
    fit = fit_terms(params, qd, -steady, use, s, TermOptions(terms=("load",)))
    assert fit.kept == ("load",) and fit.verdicts()["load"].status == "ok", (fit.reasons, fit.later)
    late = t >= 0.7 * t[-1]
    changed = steady + np.where(late, TRUE["F_L"] * np.abs(s.tau_load) * np.sign(qd), 0.0)
    fit = fit_terms(params, qd, -changed, use, s, TermOptions(terms=("load",)))
    verdict = fit.verdicts()["load"]
    assert verdict.status == "does not predict", (fit.reasons, fit.later)
    assert TermFit.from_dict(fit.to_dict()).verdicts()["load"].status == "does not predict"


def test_a_term_that_takes_the_friction_s_place_is_named():
    """A regressor that holds 1.2 times the Coulomb column and a torque of its own (a ripple that, over the angles a
    joint swept one way and the other, follows the direction of motion): fitted with it, F_c would go below zero and
    is held there; F_c carries the friction without it, so the term takes the friction's place (``displaced_part``
    names the Coulomb part). A regressor independent of the friction's takes nothing (None); nor does a held
    magnitude too small to matter."""
    from wbfriction.fit.term_checks import displaced_part
    from wbfriction.fit.term_design import nonnegative_solve

    rng = np.random.default_rng(0)
    qd = 1.5 * np.sin(np.linspace(0.0, 40.0, 4000))
    names, B, _ = velocity_basis(TRUTH, qd)
    angle = np.cos(np.linspace(0.0, 7.0, qd.size))  # what the term holds of its own
    y = B @ np.array([TRUTH.F_v, TRUTH.F_c, TRUTH.tau_os]) + 0.1 * angle + 0.01 * rng.standard_normal(qd.size)
    X = np.column_stack([B, 1.2 * np.sign(qd) + 0.1 * angle])  # and 1.2 x the Coulomb level with it
    all_names = (*names, "ripple_sin1")
    coef, held = nonnegative_solve(X, y, all_names)
    assert held == ("F_c",) and coef[1] == 0.0
    assert displaced_part(all_names, X, y, 3, held, TermOptions()) == "Coulomb"
    independent = np.column_stack([B, angle])
    coef, held = nonnegative_solve(independent, y, all_names)
    assert held == () and displaced_part(all_names, independent, y, 3, held, TermOptions()) is None
    small = y - TRUTH.F_c * np.sign(qd) + 0.004 * np.sign(qd)  # a Coulomb level of 4 mN·m: below what matters
    assert displaced_part(all_names, X, small, 3, ("F_c",), TermOptions()) is None


def test_a_coulomb_level_that_is_all_load_keeps_its_load_term():
    """A Coulomb level proportional to the load (F_c = 0, F_L = 0.04: 0-1.4 N·m) is friction: the load term takes all
    of the Coulomb level the velocity model alone fits, F_c held at zero, and is kept (F_L within 2 %), not refused
    as a term in the friction's place."""
    t, qd, s = trajectory(4)
    truth = CoulombViscousParams(F_v=0.2, F_c=0.0, tau_os=0.1)
    rng = np.random.default_rng(4)
    y = truth.F_v * qd + truth.tau_os + 0.04 * np.abs(s.tau_load) * np.sign(qd) + 0.01 * rng.standard_normal(qd.size)
    start = CoulombViscousParams(F_v=0.2, F_c=0.5, tau_os=0.1)
    fit = fit_terms(start, qd, -y, np.ones(qd.size, dtype=bool), s, TermOptions(terms=("load",)))
    assert fit.kept == ("load",) and fit.params.F_c == 0.0 and "F_c" in fit.at_bound, fit.reasons
    assert fit.coefficients["F_L"] == pytest.approx(0.04, rel=0.02)


def test_a_ripple_in_the_friction_s_place_is_refused_and_a_load_law_is_not():
    """``ripple_in_place``: with the ripple a part of the friction is held at zero and without it not: the ripple
    is refused, naming the part; where the other terms hold it at zero without the ripple (a Coulomb level all
    load), or nothing is held, the ripple is not the cause: None."""
    from wbfriction.fit.term_checks import ripple_in_place

    def best(terms):
        return 0.1, 3 if "ripple" in terms else 0

    def held_with_ripple(terms, h):
        return "Coulomb" if "ripple" in terms else None

    bad = ripple_in_place(["load", "ripple"], 3, held_with_ripple, best)
    assert bad is not None and bad[0] == "ripple" and "Coulomb" in bad[1]
    assert ripple_in_place(["load", "ripple"], 3, lambda terms, h: "Coulomb", best) is None
    assert ripple_in_place(["ripple"], 3, lambda terms, h: None, best) is None


def test_a_term_no_value_of_which_is_determined_is_refused():
    """``undetermined_term``: a term whose coefficient's standard error is above half its value (a regressor of noise,
    whose coefficient is noise) is named with its value and error; a term the data determine is not."""
    from wbfriction.fit.term_checks import undetermined_term

    rng = np.random.default_rng(1)
    qd = 1.5 * np.sin(np.linspace(0.0, 40.0, 2000))
    names, B, c = velocity_basis(TRUTH, qd)
    noise = rng.standard_normal(qd.size)
    y = B @ c + 0.05 * rng.standard_normal(qd.size)
    use = np.ones(qd.size, dtype=bool)
    X = np.column_stack([B, np.abs(qd) * noise])
    bad = undetermined_term((*names, "dF_v"), X, y, use, 3, ["direction"], 0, TermSignals())
    assert bad is not None and bad[0] == "direction" and "not determined" in bad[1]
    real = y + 0.3 * np.abs(qd)
    assert undetermined_term((*names, "dF_v"), np.column_stack([B, np.abs(qd)]), real, use, 3, ["direction"], 0,
                         TermSignals()) is None


def test_a_coulomb_level_held_at_zero_holds_its_stribeck_part():
    """(3.5) with F_c held at zero by the terms holds F_cS = F_c S with it: a Stribeck rise with no Coulomb level is
    no (3.5) (S infinite), which ``with_coefficients`` would turn into S = 0, dropping the rise silently."""
    from wbfriction.fit.term_design import nonnegative_solve

    params = FrictionParams(F_v=0.2, F_c=0.3, S=1.0, v_s=0.3, tau_os=0.0, a=50.0)
    qd = 1.5 * np.sin(np.linspace(0.0, 40.0, 4000))
    names, B, c = velocity_basis(params, qd)
    angle = np.cos(np.linspace(0.0, 7.0, qd.size))
    X = np.column_stack([B, 1.5 * B[:, 1] + angle])  # a term that holds 1.5 x the tanh column
    coef, held = nonnegative_solve(X, B @ c + angle, (*names, "extra"))
    assert {"F_c", "F_cS"} <= set(held) and coef[1] == coef[2] == 0.0


def test_a_stribeck_static_level_the_terms_would_drive_below_zero_is_held_at_zero():
    """Issue 63: a Stribeck joint's terms refit left its static level ``F_s`` free; a term holding the Stribeck column
    and a torque of its own drove it below zero (a humanoid's torso roll: -0.048 N·m), a file ``predict`` then
    refused whole. The static level is a magnitude: held at zero, named, and the refitted parameters are what the
    readers take."""
    from wbfriction.fit.params_check import check_model_params
    from wbfriction.fit.term_design import nonnegative_solve
    from wbfriction.fit.terms import with_coefficients
    from wbfriction.friction.models import StribeckParams

    params = StribeckParams(F_v=0.2, F_c=0.3, F_s=0.4, v_s=0.3, tau_os=0.0)
    qd = 1.5 * np.sin(np.linspace(0.0, 40.0, 4000))
    names, B, c = velocity_basis(params, qd)
    assert names[2] == "F_s"
    angle = np.cos(np.linspace(0.0, 7.0, qd.size))
    X = np.column_stack([B, 1.5 * B[:, 2] + angle])  # a term that holds 1.5 x the Stribeck column
    free = np.linalg.lstsq(X, B @ c + angle, rcond=None)[0]
    assert free[2] < 0  # what the refit wrote before
    coef, held = nonnegative_solve(X, B @ c + angle, (*names, "extra"))
    assert "F_s" in held and coef[2] == 0.0 and (coef[:2] >= 0).all()
    check_model_params(with_coefficients(params, coef[:len(names)]), "terms.params")
