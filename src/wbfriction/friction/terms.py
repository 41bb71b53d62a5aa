"""Friction beyond velocity (issue 40): terms in the joint's load, angle, direction of motion and temperature, each
kept only where held-out samples say it predicts better.

The thesis's models (:mod:`~wbfriction.friction.models`) are functions of the velocity alone. Real joints are not:
the friction of a gear grows with the load its teeth carry, a torque sensor or transmission adds a torque periodic
in the joint's angle, the Coulomb level may differ by direction, and warm grease drags less than cold (Bittencourt &
Axelsson, "Modeling and experiment design for identification of wear in a robot joint under load and temperature
uncertainties based on friction data", IEEE/ASME Trans. Mechatronics 19(5), 2014: load and temperature change
friction more than wear does). With the velocity model's non-linear parameters held at their fit (the tanh slope
``a``, the Stribeck velocity ``v_s``), the model and every term below are linear in their coefficients: one
weighted least-squares solve fits them together (:func:`fit_terms`). ``g(qd)`` is the model's Coulomb shape,
``sgn(qd)`` or ``tanh(a qd)`` (:func:`coulomb_shape`):

* ``load``: load-dependent Coulomb friction ``F_c (1 + k_L |tau_load|) g(qd)``, ``tau_load`` the joint's rigid-body
  torque [N·m] (gear-tooth load): coefficient ``F_L = F_c k_L`` on ``|tau_load| g``; ``k_L`` [1/(N·m)].
* ``direction``: the viscous level by direction of motion, ``F_v± = F_v ± dF_v``: coefficient ``dF_v`` on ``|qd|``.
  The Coulomb level by direction needs no term: away from rest ``F_c± = F_c ± tau_os`` (the offset of (3.4) is the
  half-difference of the two levels, which no moving sample tells apart from a sensor offset), reported with it.
* ``ripple``: a torque periodic in the joint's angle ``q`` [rad], ``sum_h s_h sin(h q) + c_h cos(h q)`` for
  ``h = 1..H`` (``H`` chosen on held-out samples, at most :attr:`TermOptions.max_harmonic`): torque sensing or
  transmission ripple, neither friction nor inertia. It is tried only where, fitted on the samples moving one way,
  it predicts those moving the other (:func:`direction_gain`): a torque of the angle does not care which way the
  joint moves, a model error that follows the trajectory does (on the KUKA LWR4+, the wrist's ripple carries over
  by 44-50 %, the upper arm's "ripple" makes the other direction worse by 10-35 %); and with no more harmonics than
  its angles tell apart (:data:`MAX_CONDITION`). It is not dissipative: it is reported apart, left out of the
  energy check (eq. 7.9) and of the exports; predictions include it, within the angles it was fitted on (outside,
  it is held at its value at the nearest fitted angle: a Fourier series fitted on less than a turn is not known
  beyond its data, and would run away there).
* ``temperature``: ``F_c (1 + k_Tc (T - T_ref))`` and ``F_v (1 + k_Tv (T - T_ref))`` (the linear form of
  Bittencourt's decrease), ``T`` the logged joint temperature [°C], ``T_ref`` the reference temperature every output
  states: coefficients ``F_cT = F_c k_Tc`` on ``(T - T_ref) g`` and ``F_vT = F_v k_Tv`` on ``(T - T_ref) qd``.

**Which terms are kept**: stepwise selection on blocked held-out samples (the split of the model choice,
:func:`~wbfriction.friction.fit.held_out_split`), with the model choice's rule: forward, the term that lowers the
held-out RMS most joins while it lowers it by more than :attr:`TermOptions.tolerance`; backward, a term whose
leaving raises it by less leaves (a load term that stood in for a ripple, their regressors alike); the ripple has
the fewest harmonics whose held-out RMS is within the tolerance of the smallest. Then every coefficient is fitted
on every sample, with standard errors from the fit's Newey-West sandwich.

Sign convention: as everywhere, the characteristic ``f`` points along the velocity and ``tau_f = -f``; a term's
coefficients are positive where it adds friction opposing the motion (``F_L``, ``F_cT``, ``F_vT`` > 0: more friction
under load or warm; ``k_Tc < 0``: less friction warm). The ripple's sign is that of ``f``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal, get_args

import numpy as np

from wbfriction.choices import check_choice, check_range
from wbfriction.friction.models import CoulombViscousParams, FrictionParams, ModelParams, StribeckParams
from wbfriction.friction.options import SELECTION_TOLERANCE
from wbfriction.friction.regression import correlation_lag, held_out_split, standard_errors
from wbfriction.friction.status import MIN_SPEED

Term = Literal["load", "direction", "ripple", "temperature"]
"""A term beyond velocity (module docstring)."""
TERMS: tuple[Term, ...] = get_args(Term)
"""Every term, in the order they are reported."""
NOT_DISSIPATIVE: tuple[Term, ...] = ("ripple",)
"""Terms that are not friction: left out of the energy check and of the exports."""


@dataclass(frozen=True)
class TermSignals:
    """What the terms are functions of, per sample of one joint, the same rows as its ``qd``; None: not logged.

    Attributes:
        q: joint angle (N,) [rad] (``ripple``).
        tau_load: the joint's rigid-body torque (N,) [N·m] (``load``).
        temperature: the joint's motor or gear temperature (N,) [°C] (``temperature``).
    """

    q: np.ndarray | None = None
    tau_load: np.ndarray | None = None
    temperature: np.ndarray | None = None

    def logged(self) -> tuple[Term, ...]:
        """The terms these signals allow (``direction`` always)."""
        have = {"load": self.tau_load is not None, "direction": True, "ripple": self.q is not None,
                "temperature": self.temperature is not None}
        return tuple(t for t in TERMS if have[t])


@dataclass(frozen=True)
class TermOptions:
    """Which terms are tried and how.

    Attributes:
        terms: the candidates (those whose signals are logged are tried).
        max_harmonic: the ripple's highest harmonic tried.
        reference_temperature: ``T_ref`` [°C]; None: the median temperature of the samples fitted.
        tolerance: a term is kept when it lowers the held-out RMS by more than this share (the model choice's,
            :data:`~wbfriction.friction.options.SELECTION_TOLERANCE`).

    Raises:
        OptionError: an unknown term, ``max_harmonic`` below 1 or above 20, ``tolerance`` outside (0, 1).
    """

    terms: tuple[Term, ...] = TERMS
    max_harmonic: int = 4
    reference_temperature: float | None = None
    tolerance: float = SELECTION_TOLERANCE

    def __post_init__(self) -> None:
        for term in self.terms:
            check_choice("terms", term, TERMS)
        check_range("max_harmonic", self.max_harmonic, low=1, high=20)
        check_range("tolerance", self.tolerance, low=0.0, high=1.0, strict=True)


def coulomb_shape(params: ModelParams, qd: np.ndarray) -> np.ndarray:
    """``g(qd)``: the model's Coulomb shape, ``tanh(a qd)`` for (3.5), ``sgn(qd)`` for the others (N,)."""
    if isinstance(params, FrictionParams):
        return np.tanh(params.a * qd)
    return np.sign(qd)


def velocity_basis(params: ModelParams, qd: np.ndarray) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    """The velocity model as linear in its coefficients, its non-linear parameters held (``a``, ``v_s``,
    ``delta_s``): ``f(qd) = B c`` exactly.

    Returns:
        ``(names, B, c)``: the coefficients' names, the regressors (N, k) and the coefficients (k,) of ``params``:
        ``F_v, F_c, tau_os`` (Coulomb-viscous), ``F_v, F_c, F_s, tau_os`` (Stribeck), ``F_v, F_c, F_cS, tau_os``
        with ``F_cS = F_c S`` (3.5).
    """
    qd = np.asarray(qd, dtype=float)
    one = np.ones_like(qd)
    if isinstance(params, CoulombViscousParams):
        return ("F_v", "F_c", "tau_os"), np.column_stack([qd, np.sign(qd), one]), \
            np.array([params.F_v, params.F_c, params.tau_os])
    e = np.exp(-np.abs(qd / params.v_s) ** params.delta_s)
    if isinstance(params, StribeckParams):
        s = np.sign(qd)
        return ("F_v", "F_c", "F_s", "tau_os"), np.column_stack([qd, s * (1 - e), s * e, one]), \
            np.array([params.F_v, params.F_c, params.F_s, params.tau_os])
    th = np.tanh(params.a * qd)
    return ("F_v", "F_c", "F_cS", "tau_os"), np.column_stack([qd, th, th * e, one]), \
        np.array([params.F_v, params.F_c, params.F_c * params.S, params.tau_os])


def with_coefficients(params: ModelParams, c: np.ndarray) -> ModelParams:
    """``params`` with the linear coefficients ``c`` of :func:`velocity_basis` (the non-linear ones kept)."""
    if isinstance(params, CoulombViscousParams):
        return replace(params, F_v=float(c[0]), F_c=float(c[1]), tau_os=float(c[2]))
    if isinstance(params, StribeckParams):
        return replace(params, F_v=float(c[0]), F_c=float(c[1]), F_s=float(c[2]), tau_os=float(c[3]))
    S = float(c[2] / c[1]) if c[1] != 0 else 0.0
    return replace(params, F_v=float(c[0]), F_c=float(c[1]), S=S, tau_os=float(c[3]))


def fourier(q: np.ndarray, harmonics: int, constant: bool = False) -> np.ndarray:
    """``[sin q, cos q, ..., sin Hq, cos Hq]`` (N, 2H), after a column of ones with ``constant``."""
    angle = np.asarray(q, dtype=float)
    columns = [f(h * angle) for h in range(1, harmonics + 1) for f in (np.sin, np.cos)]
    return np.column_stack(([np.ones_like(angle)] if constant else []) + columns)


def term_basis(term: Term, params: ModelParams, qd: np.ndarray, signals: TermSignals, *, harmonics: int = 1,
               reference_temperature: float = 0.0) -> tuple[tuple[str, ...], np.ndarray]:
    """One term's coefficient names and regressors (N, k) (module docstring).

    Raises:
        ValueError: a term whose signal is not in ``signals``.
    """
    qd = np.asarray(qd, dtype=float)
    g = coulomb_shape(params, qd)
    if term == "direction":
        return ("dF_v",), np.abs(qd)[:, None]
    if term == "load":
        if signals.tau_load is None:
            raise ValueError("the load term needs the joint's rigid-body torque")
        return ("F_L",), (np.abs(signals.tau_load) * g)[:, None]
    if term == "ripple":
        if signals.q is None:
            raise ValueError("the ripple term needs the joint's angle")
        names = tuple(n for k in range(1, harmonics + 1) for n in (f"ripple_sin{k}", f"ripple_cos{k}"))
        return names, fourier(signals.q, harmonics)
    if term == "temperature":
        if signals.temperature is None:
            raise ValueError("the temperature term needs the joint's temperature")
        dT = np.asarray(signals.temperature, dtype=float) - reference_temperature
        return ("F_cT", "F_vT"), np.column_stack([dT * g, dT * qd])
    raise ValueError(f"unknown term {term!r}")


@dataclass(frozen=True)
class TermFit:
    """The velocity model refitted with the terms kept.

    Attributes:
        params: the velocity model's parameters, their linear coefficients refitted with the terms (the non-linear
            ones as given); the given ones when no term is kept.
        kept: the terms kept, in :data:`TERMS` order; ``harmonics``: the ripple's ``H`` (0: no ripple).
        coefficients, stderr: every term coefficient (module docstring) and its standard error, by name.
        derived: the physical parameters the coefficients give, by name (``k_L`` [1/(N·m)], ``F_v+``, ``F_v-``,
            ``F_c+ = F_c + tau_os``, ``F_c- = F_c - tau_os``, ``k_Tc``, ``k_Tv`` [1/°C], ``ripple_rms``: the ripple's
            standard deviation over the samples fitted [N·m]).
        reference_temperature: ``T_ref`` [°C] (None: no temperature term tried).
        q_range: the angles the ripple was fitted on, ``(q_min, q_max)`` [rad] (None: no ripple).
        reasons: per term tried, why it was kept or not (one sentence).
        held_out_rms: the held-out RMS [N·m] of the velocity model alone and with the terms kept.
    """

    params: ModelParams
    kept: tuple[Term, ...] = ()
    harmonics: int = 0
    coefficients: dict[str, float] = field(default_factory=dict)
    stderr: dict[str, float] = field(default_factory=dict)
    derived: dict[str, float] = field(default_factory=dict)
    reference_temperature: float | None = None
    q_range: tuple[float, float] | None = None
    reasons: dict[str, str] = field(default_factory=dict)
    held_out_rms: tuple[float, float] = (float("nan"), float("nan"))

    def friction(self, qd: np.ndarray, signals: TermSignals) -> np.ndarray:
        """The dissipative part ``f`` [N·m] (N,): the velocity model and every kept term but the ripple."""
        return self._value(qd, signals, dissipative=True)

    def ripple(self, qd: np.ndarray, signals: TermSignals) -> np.ndarray:
        """The position ripple [N·m] (N,) (zero without one)."""
        return self._value(qd, signals, dissipative=False) - self._value(qd, signals, dissipative=True)

    def torque(self, qd: np.ndarray, signals: TermSignals) -> np.ndarray:
        """What the model predicts of the estimate ``tau_f`` [N·m] (N,): ``-(friction + ripple)``."""
        return -self._value(qd, signals, dissipative=False)

    def torque_at(self, qd: float, q: float = 0.0, tau_load: float = 0.0, temperature: float = 0.0) -> float:
        """:meth:`torque` of one sample, in plain floats (a simulator's physics step): velocity [rad/s], angle
        [rad], load [N·m], temperature [°C]."""
        p, c = self.params, self.coefficients
        f = float(p.f(qd))
        g = math.tanh(p.a * qd) if isinstance(p, FrictionParams) else math.copysign(1.0, qd) if qd else 0.0
        for term in self.kept:
            if term == "load":
                f += c["F_L"] * abs(tau_load) * g
            elif term == "direction":
                f += c["dF_v"] * abs(qd)
            elif term == "temperature":
                f += (c["F_cT"] * g + c["F_vT"] * qd) * (temperature - (self.reference_temperature or 0.0))
            else:
                angle = q if self.q_range is None else min(max(q, self.q_range[0]), self.q_range[1])
                f += sum(c[f"ripple_sin{h}"] * math.sin(h * angle) + c[f"ripple_cos{h}"] * math.cos(h * angle)
                         for h in range(1, self.harmonics + 1))
        return -f

    def _value(self, qd: np.ndarray, signals: TermSignals, dissipative: bool) -> np.ndarray:
        f = self.params.f(qd)
        if self.q_range is not None and signals.q is not None:  # the ripple is known on its fitted angles only
            signals = replace(signals, q=np.clip(signals.q, *self.q_range))
        for term in self.kept:
            if dissipative and term in NOT_DISSIPATIVE:
                continue
            names, X = term_basis(term, self.params, qd, signals, harmonics=self.harmonics,
                                  reference_temperature=self.reference_temperature or 0.0)
            f = f + X @ np.array([self.coefficients[n] for n in names])
        return f


def _design(params: ModelParams, qd: np.ndarray, signals: TermSignals, terms: tuple[Term, ...], harmonics: int,
            t_ref: float, smoother=None) -> tuple[tuple[str, ...], np.ndarray, int]:
    """The joint design ``[B | Phi_1 | ...]`` (N, k + m), its names, and ``k`` (the velocity model's count)."""
    names, B, _ = velocity_basis(params, qd)
    blocks, all_names = [B], list(names)
    for term in terms:
        n, X = term_basis(term, params, qd, signals, harmonics=harmonics, reference_temperature=t_ref)
        blocks.append(X)
        all_names += n
    X = np.column_stack(blocks)
    if smoother is not None:  # the estimate went through it: so does the model, along the whole series
        X = smoother(X)
    return tuple(all_names), X, len(names)


MAX_CONDITION = 1e3
"""The largest condition number of a ripple's regressors (a constant and ``H`` harmonics, columns scaled) on the
angles fitted: over part of a turn the harmonics grow alike, and more of them than the angles tell apart give
amplitudes of hundreds of N·m that cancel."""


def ripple_condition(q: np.ndarray, harmonics: int) -> float:
    """The condition number of ``[1, sin q, cos q, ..., sin Hq, cos Hq]`` (columns scaled to unit norm) on ``q``."""
    F = fourier(q, harmonics, constant=True)
    return float(np.linalg.cond(F / np.maximum(np.linalg.norm(F, axis=0), 1e-300)))


def direction_gain(residual: np.ndarray, qd: np.ndarray, use: np.ndarray, q: np.ndarray, harmonics: int,
                   smoother=None) -> float:
    """How much a ripple of ``harmonics`` harmonics, fitted on the friction's residual ``y - f`` (N,) [N·m] of the
    samples moving one way, lowers the residual's RMS on those moving the other way (the smaller of the two ways;
    relative, 1: all of it). A torque periodic in the angle is the same whichever way the joint moves; a residual
    that follows the trajectory (a model error, a log that repeats one motion) is not, and does not carry over: its
    gain is about zero or negative. ``smoother``: the estimate's (the ripple goes through it as the model does)."""
    F = fourier(q, harmonics, constant=True)
    if smoother is not None:
        F = np.nan_to_num(smoother(F))
    gains = []
    moving = use & (np.abs(qd) > MIN_SPEED)  # a sample at rest has no direction
    for train, test in ((moving & (qd > 0), moving & (qd < 0)), (moving & (qd < 0), moving & (qd > 0))):
        if train.sum() <= F.shape[1] or not test.any():
            return float("nan")
        c = _solve(F[train], residual[train])
        before = residual[test] - residual[test].mean()
        after = residual[test] - F[test] @ c
        gains.append(1.0 - float(np.sqrt(np.mean(after**2) / np.mean(before**2))))
    return min(gains)


def _solve(X: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.linalg.lstsq(X, y, rcond=None)[0]


def fit_terms(params: ModelParams, qd: np.ndarray, tau_f: np.ndarray, use: np.ndarray, signals: TermSignals,
              options: TermOptions = TermOptions(), smoother=None) -> TermFit:
    """The terms beyond velocity that held-out samples support, fitted with the velocity model's linear
    coefficients (module docstring).

    Args:
        params: the velocity model's fit (:attr:`~wbfriction.friction.fit.FitResult.params`).
        qd: joint velocity (N,) [rad/s]; tau_f: the friction estimate (N,) [N·m] (``tau_f = -f``).
        use: (N,) samples to fit (finite, valid, not stuck), in time order.
        signals: the terms' signals, the same rows.
        options: which terms to try.
        smoother: the zero-phase smoother the estimate went through
            (:attr:`~wbfriction.friction.estimated.FrictionEstimate.smoother`), or None: ``qd``, ``tau_f`` and the
            signals are then whole time series and the model's regressors go through it before they are compared
            (as the fit's model does); the samples where they are undefined are not used.

    Returns:
        the :class:`TermFit`; with no term kept, ``params`` unchanged.
    """
    qd = np.asarray(qd, dtype=float)
    y = -np.asarray(tau_f, dtype=float)
    use = np.asarray(use, dtype=bool) & np.isfinite(qd) & np.isfinite(y)
    for s in (signals.q, signals.tau_load, signals.temperature):
        if s is not None:
            use &= np.isfinite(s)
    if smoother is None:
        qd_ = np.where(use, qd, 0.0)
    else:  # the whole series through the smoother: rows it leaves undefined are not used
        qd_ = qd
        _, X0, _ = _design(params, qd_, signals, tuple(t for t in signals.logged() if t in options.terms), 1, 0.0,
                           smoother)
        use &= np.isfinite(X0).all(axis=1)
    y_ = np.where(use, y, 0.0)
    candidates = tuple(t for t in options.terms if t in signals.logged())
    t_ref = None
    if "temperature" in candidates and signals.temperature is not None:
        t_ref = (float(np.median(signals.temperature[use])) if options.reference_temperature is None
                 else options.reference_temperature)
    train, test = held_out_split(use)
    designs: dict[tuple[tuple[Term, ...], int], tuple[tuple[str, ...], np.ndarray, int]] = {}

    def design(terms: tuple[Term, ...], h: int) -> tuple[tuple[str, ...], np.ndarray, int]:
        """:func:`_design` of ``terms`` (in :data:`TERMS` order) with ``h`` harmonics, built (and smoothed) once."""
        key = (tuple(t for t in TERMS if t in terms), h if "ripple" in terms else 0)
        if key not in designs:
            designs[key] = _design(params, qd_, signals, key[0], key[1], t_ref or 0.0, smoother)
        return designs[key]

    def score(terms: tuple[Term, ...], h: int) -> float:
        """The held-out RMS of the model of ``terms`` fitted on the training samples."""
        _, X, _ = design(terms, h)
        r = y_[test] - X[test] @ _solve(X[train], y_[train])
        return float(np.sqrt(np.mean(r**2))) if r.size else float("nan")

    counts: tuple[int, ...] = ()  # the ripple's harmonic counts its angles tell apart
    if "ripple" in candidates and signals.q is not None:
        counts = tuple(h for h in range(1, options.max_harmonic + 1)
                       if ripple_condition(np.asarray(signals.q)[use], h) <= MAX_CONDITION)
    cache: dict[tuple[Term, ...], dict[int, float]] = {}

    def direction_gains(terms: tuple[Term, ...]) -> dict[int, float]:
        """Per harmonic count, how far a ripple carries over between the directions of motion
        (:func:`direction_gain`) on what the friction with the friction terms of ``terms`` leaves."""
        friction = tuple(t for t in terms if t != "ripple")
        if friction not in cache:
            X = np.nan_to_num(design(friction, 0)[1])
            left = y_ - X @ _solve(X[use], y_[use])
            cache[friction] = {h: direction_gain(left, qd_, use, np.asarray(signals.q), h, smoother) for h in counts}
        return cache[friction]

    def best_harmonics(terms: tuple[Term, ...]) -> tuple[float, int]:
        """The held-out RMS of ``terms`` and the ripple's ``H`` that gives it (0 without a ripple, or when no count
        holds whichever way the joint moves: then the terms' without it)."""
        if "ripple" not in terms:
            return score(terms, 0), 0
        allowed = [h for h, g in direction_gains(terms).items() if g > options.tolerance]
        if not allowed:  # no ripple holds here: the terms without it
            return score(tuple(t for t in terms if t != "ripple"), 0), 0
        scores: dict[int, float] = {h: score(terms, h) for h in allowed}
        best_rms = min(scores.values())
        h: int = min(count for count, rms in scores.items() if rms <= (1.0 + options.tolerance) * best_rms)
        return scores[h], h  # the fewest harmonics within the tolerance of the best

    base_rms = score((), 0)
    tol = options.tolerance
    kept: list[Term] = []
    current, harmonics = base_rms, 0
    remaining = list(candidates)
    while remaining:  # forward: the term that lowers the held-out RMS most, while it lowers it by more than tol
        trials = {term: best_harmonics((*kept, term)) for term in remaining}
        best = min(trials, key=lambda t: trials[t][0])
        if not trials[best][0] < (1.0 - tol) * current:
            break
        kept.append(best)
        current, harmonics = trials[best]
        remaining.remove(best)
    while len(kept) > 1:  # backward: a term another has made redundant leaves (a load that stood for a ripple)
        without = {term: best_harmonics(tuple(t for t in kept if t != term)) for term in kept}
        weakest = min(without, key=lambda t: without[t][0])
        if not without[weakest][0] < (1.0 + tol) * current:
            break
        kept.remove(weakest)
        current, harmonics = without[weakest]
    reasons: dict[str, str] = {}
    while True:  # a friction term that makes the friction generate power (eq. 7.9) on the samples is not friction
        names, X, k = design(tuple(kept), harmonics)
        coef = _solve(X[use], y_[use])
        bad = _unphysical(with_coefficients(params, coef[:k]), dict(zip(names[k:], map(float, coef[k:]))), signals,
                          use, t_ref or 0.0)
        if bad is None:
            break
        kept.remove(bad[0])
        reasons[bad[0]] = f"not kept: {bad[1]}: not friction"
        current, harmonics = best_harmonics(tuple(kept))
    if "ripple" in candidates and "ripple" not in kept:
        gains = direction_gains(tuple(kept))
        if not any(g > tol for g in gains.values()):
            reasons["ripple"] = ("not kept: fitted on one direction of motion it does not predict the other by more "
                                 f"than {100 * tol:g} % (best {100 * max(gains.values(), default=float('nan')):+.2g} "
                                 "%): not a torque of the angle")
    for term in candidates:
        if term in reasons:
            continue
        if term in kept:
            rms_without = best_harmonics(tuple(t for t in kept if t != term))[0]
            reasons[term] = (f"kept: held-out RMS {current:.4g} N·m with it, {rms_without:.4g} without "
                             f"(+{100 * (rms_without / current - 1):.2g} %)"
                             + (f"; {harmonics} harmonics" if term == "ripple" else ""))
        else:
            rms_with = best_harmonics((*kept, term))[0]
            reasons[term] = (f"not kept: held-out RMS {current:.4g} N·m without it, {rms_with:.4g} with "
                             f"({100 * (rms_with / current - 1):+.2g} %; kept from -{100 * tol:g} %)")
    kept_sorted = tuple(t for t in TERMS if t in kept)
    if not kept_sorted:
        return TermFit(params, reference_temperature=t_ref, reasons=reasons, held_out_rms=(base_rms, base_rms))
    names, X, k = design(kept_sorted, harmonics)
    coef = _solve(X[use], y_[use])
    residual = y_[use] - X[use] @ coef
    rows_used = np.flatnonzero(use)  # residuals correlated over a filter's window: Newey-West, as the fit's
    errors = standard_errors(X[use], residual, rows=rows_used, max_lag=correlation_lag(residual, rows_used))
    refitted = with_coefficients(params, coef[:k])
    coefficients = dict(zip(names[k:], map(float, coef[k:])))
    stderr = dict(zip(names, map(float, errors)))
    q_range = None
    derived = _derived(refitted, coefficients)
    if "ripple" in kept_sorted and signals.q is not None:
        q_used = np.asarray(signals.q, dtype=float)[use]
        q_range = (float(q_used.min()), float(q_used.max()))
        ripple = fourier(q_used, harmonics) @ np.array([coefficients[n] for n in names if n.startswith("ripple")])
        derived["ripple_rms"] = float(np.std(ripple))  # its size where it was fitted (harmonics may cancel)
    return TermFit(refitted, kept_sorted, harmonics, coefficients, stderr, derived, t_ref, q_range, reasons,
                   (base_rms, current))


def _unphysical(params: ModelParams, c: dict[str, float], signals: TermSignals, use: np.ndarray,
                t_ref: float) -> tuple[Term, str] | None:
    """The first friction term whose levels go below zero on the samples (a viscous level in a direction, a Coulomb
    level under a load met, a level at a temperature met) and what goes below; None when all stay physical."""
    F_c, F_v = params.F_c, params.F_v
    if "dF_v" in c and min(F_v + c["dF_v"], F_v - c["dF_v"]) < 0:
        return "direction", f"a viscous level below zero in one direction (F_v {F_v:.3g}, dF_v {c['dF_v']:.3g})"
    if "F_L" in c and signals.tau_load is not None:
        lowest = F_c + c["F_L"] * float(np.max(np.abs(np.asarray(signals.tau_load)[use])))
        if lowest < 0:
            return "load", f"a Coulomb level below zero under the largest load met ({lowest:.3g} N·m)"
    if "F_cT" in c and signals.temperature is not None:
        dT = np.asarray(signals.temperature, dtype=float)[use] - t_ref
        levels = (F_c + c["F_cT"] * dT, F_v + c["F_vT"] * dT)
        if min(float(np.min(x)) for x in levels) < 0:
            return "temperature", "a Coulomb or viscous level below zero at a temperature met"
    return None


def _derived(params: ModelParams, c: dict[str, float]) -> dict[str, float]:
    """The physical parameters of the coefficients (:attr:`TermFit.derived`)."""
    out: dict[str, float] = {}
    F_c, F_v = params.F_c, params.F_v
    if "F_L" in c:
        out["k_L"] = c["F_L"] / F_c if F_c else float("nan")
    if "dF_v" in c:
        out.update({"F_v+": F_v + c["dF_v"], "F_v-": F_v - c["dF_v"], "F_c+": F_c + params.tau_os,
                    "F_c-": F_c - params.tau_os})
    if "F_cT" in c:
        out["k_Tc"] = c["F_cT"] / F_c if F_c else float("nan")
        out["k_Tv"] = c["F_vT"] / F_v if F_v else float("nan")
    return out
