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
* ``temperature``: the Coulomb and viscous levels ``F_c + F_cT phi(T - T_ref)`` and ``F_v + F_vT phi(T - T_ref)``,
  ``T`` the logged joint temperature [°C], ``T_ref`` the reference temperature every output states: coefficients
  ``F_cT`` on ``phi g`` and ``F_vT`` on ``phi qd``, the levels' slopes at ``T_ref`` [N·m/°C, N·m·s/(rad·°C)]
  (``k_Tc = F_cT / F_c``, ``k_Tv = F_vT / F_v`` relative [1/°C]). The law ``phi`` (:func:`temperature_shape`) is
  linear, ``phi(dT) = dT``, or exponential, ``phi(dT) = (exp(r dT) - 1) / r`` with a rate ``r`` [1/°C]
  (``rate_T``; Bittencourt's exponential decrease of friction with temperature: ``F_c exp(k_Tc dT)`` when
  ``F_cT = r F_c``, levels that flatten as grease thins); the exponential is kept where held-out samples say it
  predicts better than the linear (:attr:`~wbfriction.friction.options.TermOptions.temperature_law`), its rate
  fitted by a bounded scalar search with the coefficients solved at each rate (variable projection) and its
  standard error from the Jacobian column of the rate.

**Which terms are kept**: stepwise selection on blocked held-out samples (the split of the model choice,
:func:`~wbfriction.friction.fit.held_out_split`), with the model choice's rule: forward, the term that lowers the
held-out RMS most joins while it lowers it by more than :attr:`TermOptions.tolerance`; backward, a term whose
leaving raises it by less leaves (a load term that stood in for a ripple, their regressors alike); the ripple has
the fewest harmonics whose held-out RMS is within the tolerance of the smallest. The load and temperature terms,
like the ripple, are tried only where, fitted on the samples moving one way, they predict those moving the other
(:func:`direction_gain`): a law of the load or the temperature holds both ways, a residual that follows a repeated
trajectory does not (on the KUKA LWR4+, the rigid-body torque's "load" term on lwr_2 passed the held-out blocks,
whose twins were in training, and made run 3 worse by 6 %). Then every coefficient is fitted on every sample, with
standard errors from the fit's Newey-West sandwich; the velocity model's magnitudes (F_c, F_v) that the terms would
drive below zero are held at zero (:attr:`TermFit.at_bound`).

Sign convention: as everywhere, the characteristic ``f`` points along the velocity and ``tau_f = -f``; a term's
coefficients are positive where it adds friction opposing the motion (``F_L``, ``F_cT``, ``F_vT`` > 0: more friction
under load or warm; ``k_Tc < 0``: less friction warm). The ripple's sign is that of ``f``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any, cast

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.estimated import FrictionEstimate
from wbfriction.friction.models import (
    CoulombViscousParams,
    FrictionParams,
    ModelParams,
    StribeckParams,
    params_from_dict,
)
from wbfriction.friction.options import TERMS, Term, TermOptions
from wbfriction.friction.regression import (
    correlation_lag,
    covariance_errors,
    held_out_split,
    parameter_covariance,
)
from wbfriction.friction.status import MIN_SPEED, WEAK, FitVerdict, routes_disagree

NOT_DISSIPATIVE: tuple[Term, ...] = ("ripple",)
"""Terms that are not friction: left out of the energy check and of the exports."""


@dataclass(frozen=True)
class TermSignals:
    """What the terms are functions of, per sample of one joint, the same rows as its ``qd``; None: not logged.

    Attributes:
        q: joint angle (N,) [rad] (``ripple``).
        tau_load: the joint's rigid-body torque ``M qdd + h`` (N,) [N·m] (``load``).
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


def term_signals(est: FrictionEstimate, joint: int) -> TermSignals:
    """The terms' signals of column ``joint`` of an estimate: its ``q``; the rigid-body torque
    ``M qdd + h = tau + tau_f`` (the sign convention's, :mod:`~wbfriction.friction.estimate`) as the load (NaN where
    the friction is not estimated; not the measured torque, which holds the friction itself: a drive's current does);
    its ``temperature`` (a column all NaN: not logged)."""
    temperature = None if est.temperature is None else est.temperature[:, joint]
    if temperature is not None and np.all(np.isnan(temperature)):
        temperature = None
    return TermSignals(None if est.q is None else est.q[:, joint],
                       None if est.tau is None else est.tau[:, joint] + est.tau_f[:, joint], temperature)


SIGNAL_COLUMNS: dict[Term, str] = {"load": "tau", "ripple": "q", "temperature": "temperature"}
"""The friction table's column (``<name>.<joint>``) each term's signal is read from."""


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


def temperature_shape(dT: np.ndarray, rate: float = 0.0) -> np.ndarray:
    """The temperature law ``phi`` (N,) of ``dT = T - T_ref`` [°C] (module docstring): ``dT`` (``rate`` 0, linear)
    or ``(exp(rate dT) - 1) / rate`` (exponential, ``rate`` [1/°C]); slope 1 at ``T_ref`` either way."""
    dT = np.asarray(dT, dtype=float)
    return dT if rate == 0.0 else np.expm1(rate * dT) / rate


def temperature_shape_rate(dT: np.ndarray, rate: float) -> np.ndarray:
    """``d phi / d rate`` (N,) of :func:`temperature_shape` [°C^2] (``dT^2 / 2`` at rate 0)."""
    dT = np.asarray(dT, dtype=float)
    if rate == 0.0:
        return 0.5 * dT**2
    return (rate * dT * np.exp(rate * dT) - np.expm1(rate * dT)) / rate**2


def term_basis(term: Term, params: ModelParams, qd: np.ndarray, signals: TermSignals, *, harmonics: int = 1,
               reference_temperature: float = 0.0,
               temperature_rate: float = 0.0) -> tuple[tuple[str, ...], np.ndarray]:
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
        phi = temperature_shape(np.asarray(signals.temperature, dtype=float) - reference_temperature,
                                temperature_rate)
        return ("F_cT", "F_vT"), np.column_stack([phi * g, phi * qd])
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
        check: the kept terms refitted on the other route's estimate (:func:`refit_terms`), or None.
        at_bound: the velocity model's magnitudes held at zero in the refit (:data:`NONNEGATIVE`): with the terms,
            the data would put them below it (standard error 0: held, not fitted).
        covariance: the coefficients' covariance, the velocity model's (:func:`velocity_basis` order) then the
            terms', or None (read from a parameters file, which keeps the standard errors only).
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
    check: TermCheck | None = None
    at_bound: tuple[str, ...] = ()
    covariance: np.ndarray | None = field(default=None, repr=False, compare=False)

    @property
    def temperature_rate(self) -> float:
        """The temperature law's rate ``rate_T`` [1/°C] (0: linear; :func:`temperature_shape`)."""
        return self.coefficients.get("rate_T", 0.0)

    def verdicts(self) -> dict[Term, FitVerdict]:
        """Per kept term, whether its numbers can be used (``ok``, ``weak``, ``routes disagree``) and why.

        * ``routes disagree``: the other route's estimate gives one of its coefficients (the ripple: its size,
          :func:`ripple_size`) more than :data:`~wbfriction.friction.status.ROUTE_Z` combined standard errors and
          :data:`~wbfriction.friction.status.ROUTE_REL` away (:attr:`check`);
        * ``weak``: a coefficient's (the ripple's size's) standard error above
          :data:`~wbfriction.friction.status.WEAK` of its value;
        * ``ok``: neither.
        """
        out: dict[Term, FitVerdict] = {}
        for term in self.kept:
            mine = self._read(term, {**self.coefficients, **self.derived}, self.stderr)  # the ripple's size too
            check = self.check
            theirs = {} if check is None else self._read(term, check.coefficients, check.stderr)
            off = [f"{n} {v:.3g} ±{se:.2g} against {theirs[n][0]:.3g} ±{theirs[n][1]:.2g} ({check.route})"
                   for n, (v, se) in mine.items() if check is not None and n in theirs
                   and routes_disagree(v, se, *theirs[n])]
            weak = [f"{n} {v:.3g} ±{se:.2g}" for n, (v, se) in mine.items() if not se <= WEAK * abs(v)]
            out[term] = (FitVerdict("routes disagree", "; ".join(off)) if off
                         else FitVerdict("weak", "large standard errors: " + ", ".join(weak)) if weak
                         else FitVerdict("ok"))
        return out

    def _read(self, term: Term, c: Mapping[str, float], se: Mapping[str, float]) -> dict[str, tuple[float, float]]:
        """The values a status judges of ``term`` (name -> value, standard error): its coefficients, the ripple's
        size (:func:`ripple_size`)."""
        names = TERM_COEFFICIENTS[term] + (("rate_T",) if term == "temperature" else ())
        return {n: (c[n], se.get(n, math.inf)) for n in names if n in c}

    def to_dict(self) -> dict[str, Any]:
        """As the parameters JSON holds it (a value that is not finite: ``null``), with each term's status."""
        clean = _finite_or_none
        verdicts = self.verdicts()
        return {"kept": list(self.kept), "harmonics": self.harmonics, "model": self.params.model,
                "params": self.params.to_dict(), "coefficients": dict(self.coefficients),
                "stderr": {k: clean(v) for k, v in self.stderr.items()},
                "derived": {k: clean(v) for k, v in self.derived.items()},
                "reference_temperature": self.reference_temperature,
                "q_range": None if self.q_range is None else list(self.q_range), "reasons": dict(self.reasons),
                "held_out_rms": [clean(x) for x in self.held_out_rms],
                "check": None if self.check is None else self.check.to_dict(), "at_bound": list(self.at_bound),
                "status": {t: v.status for t, v in verdicts.items()},
                "status_reason": {t: v.reason for t, v in verdicts.items() if v.reason}}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> TermFit:
        """Inverse of :meth:`to_dict` (``null`` reads back as ``inf`` for a standard error, NaN otherwise; the
        statuses follow from the rest).

        Raises:
            InputError: a missing key, an unknown term or model, a value of the wrong kind (named).
        """
        try:
            kept = tuple(check_term(str(t)) for t in d["kept"])
            rng = d.get("q_range")
            check = d.get("check")
            t_ref = d.get("reference_temperature")
            return cls(params_from_dict(str(d["model"]), d["params"]), kept, int(d.get("harmonics", 0)),
                       {str(k): float(v) for k, v in d["coefficients"].items()},
                       {str(k): math.inf if v is None else float(v) for k, v in (d.get("stderr") or {}).items()},
                       {str(k): _number(v) for k, v in (d.get("derived") or {}).items()},
                       None if t_ref is None else float(t_ref),
                       None if rng is None else (float(rng[0]), float(rng[1])),
                       {str(k): str(v) for k, v in (d.get("reasons") or {}).items()},
                       tuple(_number(x) for x in d.get("held_out_rms", (None, None))),  # type: ignore[arg-type]
                       None if check is None else TermCheck.from_dict(check),
                       tuple(str(n) for n in d.get("at_bound", ())))
        except KeyError as exc:
            raise InputError(f"terms: missing key {exc}") from None
        except (TypeError, ValueError, AttributeError, IndexError) as exc:
            raise InputError(f"terms: {exc}") from None

    def check_signals(self, signals: TermSignals, joint: str, source: str) -> None:
        """Refuse signals that lack one a kept term needs (a friction table of an earlier version, a log without
        the joint's temperature).

        Raises:
            InputError: naming ``source``, the column and the term.
        """
        have = signals.logged()
        for term in self.kept:
            if term not in have:
                column = f"{SIGNAL_COLUMNS[term]}.{joint}"
                raise InputError(f"{source}: no column '{column}': the fit's {term} term needs it (estimate the "
                                 "log again with this version; a temperature term needs the log's temperature)")

    def speed_friction(self, v: float) -> tuple[float, float]:
        """The dissipative friction at speed ``v`` [rad/s] at the reference conditions (zero load, ``T_ref``, no
        ripple): ``(f(+v) - f(-v)) / 2`` [N·m], and its standard error from :attr:`covariance` (NaN without)."""
        _, B, c = velocity_basis(self.params, np.array([v, -v]))
        g = 0.5 * (B[0] - B[1])
        value = float(g @ c)
        if self.covariance is None:
            return value, float("nan")
        k = len(c)
        return value, float(np.sqrt(max(float(g @ self.covariance[:k, :k] @ g), 0.0)))

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
                dT = temperature - (self.reference_temperature or 0.0)
                rate = self.temperature_rate
                f += (c["F_cT"] * g + c["F_vT"] * qd) * (dT if rate == 0.0 else math.expm1(rate * dT) / rate)
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
                                  reference_temperature=self.reference_temperature or 0.0,
                                  temperature_rate=self.temperature_rate)
            f = f + X @ np.array([self.coefficients[n] for n in names])
        return f


TERM_COEFFICIENTS: dict[Term, tuple[str, ...]] = {"load": ("F_L",), "direction": ("dF_v",),
                                                   "temperature": ("F_cT", "F_vT"), "ripple": ("ripple_rms",)}
"""Each term's values a status judges: its coefficients; for the ripple, its size (:func:`ripple_size`; its
coefficients are ``ripple_sin<h>``, ``ripple_cos<h>`` for ``h = 1..H``)."""


def check_term(term: str) -> Term:
    """``term`` if it is one of :data:`TERMS`.

    Raises:
        ValueError: another name, with the choices.
    """
    if term not in TERMS:
        raise ValueError(f"unknown term {term!r}: choose among {', '.join(TERMS)}")
    return cast(Term, term)


def _finite_or_none(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def _number(x: Any) -> float:
    return float("nan") if x is None else float(x)


@dataclass(frozen=True)
class TermCheck:
    """The kept terms refitted on the other route's estimate (issue 38's check, for the terms).

    Attributes:
        route: that route (``acceleration`` or ``momentum``).
        coefficients, stderr: its coefficients (the velocity model's linear ones, :func:`velocity_basis`, and the
            terms') and their standard errors, by name.
    """

    route: str
    coefficients: dict[str, float]
    stderr: dict[str, float]

    def to_dict(self) -> dict[str, Any]:
        return {"route": self.route, "coefficients": dict(self.coefficients),
                "stderr": {k: _finite_or_none(v) for k, v in self.stderr.items()}}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> TermCheck:
        return cls(str(d["route"]), {str(k): float(v) for k, v in d["coefficients"].items()},
                   {str(k): math.inf if v is None else float(v) for k, v in (d.get("stderr") or {}).items()})


def _design(params: ModelParams, qd: np.ndarray, signals: TermSignals, terms: tuple[Term, ...], harmonics: int,
            t_ref: float, smoother=None, rate: float = 0.0) -> tuple[tuple[str, ...], np.ndarray, int]:
    """The joint design ``[B | Phi_1 | ...]`` (N, k + m), its names, and ``k`` (the velocity model's count);
    ``rate``: the temperature law's (:func:`temperature_shape`)."""
    names, B, _ = velocity_basis(params, qd)
    blocks, all_names = [B], list(names)
    for term in terms:
        n, X = term_basis(term, params, qd, signals, harmonics=harmonics, reference_temperature=t_ref,
                          temperature_rate=rate)
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


def direction_gain(residual: np.ndarray, qd: np.ndarray, use: np.ndarray, F: np.ndarray, smoother=None) -> float:
    """How much a term's regressors ``F`` (N, k) (a column of ones first), fitted on the friction's residual
    ``y - f`` (N,) [N·m] of the samples moving one way, lower the residual's RMS on those moving the other way, each
    way's mean taken out (the smaller of the two ways; relative, 1: all of it). A torque of the angle, a Coulomb
    level that grows with the load or falls with the temperature, is the same law whichever way the joint moves; a
    residual that follows the
    trajectory (a model error, a log that repeats one motion, whose held-out blocks have twins in training) is not,
    and does not carry over: its gain is about zero or negative. ``smoother``: the estimate's (the regressors go
    through it as the model does)."""
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
        after = after - after.mean()  # each way its own level: a Coulomb level the velocity model took flips sign
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
        use: (N,) samples to fit (valid, not stuck), in time order; those not finite or at rest (:func:`_moving`)
            are left out.
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
    use = _moving(use, qd, y, signals)
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
            cache[friction] = {h: direction_gain(left, qd_, use, fourier(np.asarray(signals.q), h, constant=True),
                                                 smoother) for h in counts}
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
    reasons: dict[str, str] = {}
    gains: dict[tuple[Term, tuple[Term, ...]], float] = {}

    def carry_over(term: Term, others: tuple[Term, ...]) -> float:
        """How far ``term`` (load or temperature: laws that hold whichever way the joint moves) carries over between
        the directions of motion (:func:`direction_gain`) on what the friction with the friction terms of
        ``others`` leaves."""
        friction = tuple(t for t in TERMS if t in others and t not in ("ripple", term))
        if (term, friction) not in gains:
            X0 = np.nan_to_num(design(friction, 0)[1])
            left = y_ - X0 @ _solve(X0[use], y_[use])
            _, X = term_basis(term, params, qd_, signals, reference_temperature=t_ref or 0.0)
            gains[term, friction] = direction_gain(left, qd_, use, np.column_stack([np.ones(len(qd_)),
                                                                                    np.nan_to_num(X)]), smoother)
        return gains[term, friction]

    def holds(term: Term, others: tuple[Term, ...]) -> bool:
        return term not in ("load", "temperature") or carry_over(term, others) > tol

    kept: list[Term] = []
    current, harmonics = base_rms, 0
    remaining = list(candidates)
    while remaining:  # forward: the term that lowers the held-out RMS most, while it lowers it by more than tol
        trials = {term: best_harmonics((*kept, term)) for term in remaining if holds(term, tuple(kept))}
        if not trials:
            break
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
    while True:  # a friction term that makes the friction generate power (eq. 7.9) on the samples is not friction
        names, X, k = design(tuple(kept), harmonics)
        coef, _ = _nonnegative_solve(X[use], y_[use], names)
        bad = _unphysical(with_coefficients(params, coef[:k]), dict(zip(names[k:], map(float, coef[k:]))), signals,
                          use, t_ref or 0.0) or _negligible(names, X[use], coef, k, options)
        if bad is None:
            break
        kept.remove(bad[0])
        reasons[bad[0]] = f"not kept: {bad[1]}"
        current, harmonics = best_harmonics(tuple(kept))
    if "ripple" in candidates and "ripple" not in kept:
        ripples = direction_gains(tuple(kept))
        if not any(g > tol for g in ripples.values()):
            reasons["ripple"] = ("not kept: fitted on one direction of motion it does not predict the other by more "
                                 f"than {100 * tol:g} % (best {100 * max(ripples.values(), default=float('nan')):+.2g} "
                                 "%): not a torque of the angle")
    for term in candidates:
        if term not in kept and term not in reasons and not holds(term, tuple(kept)):
            reasons[term] = ("not kept: fitted on one direction of motion it does not predict the other by more "
                             f"than {100 * tol:g} % ({100 * carry_over(term, tuple(kept)):+.2g} %): not a law of the "
                             f"{term}")
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
    rate = 0.0
    if "temperature" in kept_sorted and options.temperature_law != "linear":
        law = _TemperatureLaw(params, qd_, y_, use, signals, kept_sorted, harmonics, t_ref or 0.0, smoother)
        rate, note, rms = law.choose(train, test, options)
        reasons["temperature"] += note
        current = rms if rate else current
    names, X, k = _design(params, qd_, signals, kept_sorted, harmonics, t_ref or 0.0, smoother, rate)
    coef, cov, held = _final(X, y_, use, names, None if rate == 0.0 else partial(law.rate_column, rate, names))
    refitted = with_coefficients(params, coef[:k])
    coefficients = dict(zip(names[k:], map(float, coef[k:])))
    stderr = dict(zip(names, map(float, covariance_errors(cov))))
    if rate != 0.0:
        coefficients["rate_T"], stderr["rate_T"] = rate, float(np.sqrt(max(cov[-1, -1], 0.0)))
    q_range = None
    derived = _derived(refitted, coefficients)
    if "ripple" in kept_sorted and signals.q is not None:
        q_used = np.asarray(signals.q, dtype=float)[use]
        q_range = (float(q_used.min()), float(q_used.max()))
        derived["ripple_rms"], stderr["ripple_rms"] = ripple_size(q_used, harmonics, names, coef, cov)
    return TermFit(refitted, kept_sorted, harmonics, coefficients, stderr, derived, t_ref, q_range, reasons,
                   (base_rms, current), at_bound=held, covariance=cov)


NONNEGATIVE = ("F_v", "F_c", "F_cS")
"""The velocity model's linear coefficients that are magnitudes (the fit's bounds): refitted with the terms, one
that would go below zero is held at zero (:attr:`TermFit.at_bound`)."""


def _nonnegative_solve(X: np.ndarray, y: np.ndarray, names: tuple[str, ...]) -> tuple[np.ndarray, tuple[str, ...]]:
    """Least squares with the :data:`NONNEGATIVE` coefficients at zero where they would go below: the most negative
    held at zero and the rest refitted, until none is; and the names held."""
    free = np.ones(len(names), dtype=bool)
    while True:
        coef = np.zeros(len(names))
        coef[free] = _solve(X[:, free], y)
        negative = [i for i, n in enumerate(names) if n in NONNEGATIVE and free[i] and coef[i] < 0]
        if not negative:
            return coef, tuple(n for n, f in zip(names, free) if not f)
        free[min(negative, key=lambda i: coef[i])] = False


def _moving(use: np.ndarray, qd: np.ndarray, y: np.ndarray, signals: TermSignals) -> np.ndarray:
    """The samples of ``use`` the terms are fitted on: finite, signals too, and moving (``|qd|`` above
    :data:`~wbfriction.friction.status.MIN_SPEED`): a joint at rest has static friction, any value up to its static
    level, which no law of the load or the temperature of the moving friction describes (on the ideal simulator's
    noise-free walk, the 20 samples of 3,900 about the knees' reversals bias F_L by 5 %)."""
    use = np.asarray(use, dtype=bool) & np.isfinite(qd) & np.isfinite(y) & (np.abs(qd) > MIN_SPEED)
    for signal in (signals.q, signals.tau_load, signals.temperature):
        if signal is not None:
            use &= np.isfinite(signal)
    return use


def _final(X: np.ndarray, y: np.ndarray, use: np.ndarray, names: tuple[str, ...],
           rate_column: Callable[[np.ndarray], np.ndarray] | None = None,
           ) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """The coefficients on every sample ``use`` (:func:`_nonnegative_solve`), their covariance (residuals correlated
    over a filter's window: Newey-West, as the fit's; zero for one held at zero) and the names held. With
    ``rate_column`` (the model's derivative (N,) in the temperature law's rate, given the coefficients), the
    covariance is that of the coefficients and the rate (last): the full Jacobian's, the rate fitted too."""
    coef, held = _nonnegative_solve(X[use], y[use], names)
    free = np.array([n not in held for n in names])
    residual = y[use] - X[use] @ coef
    rows = np.flatnonzero(use)
    J = X[use]
    if rate_column is not None:
        J = np.column_stack([J, rate_column(coef)[use]])
        free = np.append(free, True)
    cov = np.zeros((len(free), len(free)))
    cov[np.ix_(free, free)] = parameter_covariance(J[:, free], residual, rows=rows,
                                                   max_lag=correlation_lag(residual, rows))
    return coef, cov, held


RATE_SPAN = 3.0
"""The exponential temperature law's rate is searched within ``RATE_SPAN`` over the largest ``|T - T_ref|`` met
[1/°C]: a level that changes by up to ``e^3`` (20 times) over the temperatures logged, beyond any grease's."""


@dataclass(frozen=True)
class _TemperatureLaw:
    """The exponential temperature law of a fit's kept terms (:func:`temperature_shape`): its rate found by variable
    projection (the coefficients solved at each rate) and kept where held-out samples say so."""

    params: ModelParams
    qd: np.ndarray
    y: np.ndarray
    use: np.ndarray
    signals: TermSignals
    terms: tuple[Term, ...]
    harmonics: int
    t_ref: float
    smoother: Any = None

    def design(self, rate: float) -> tuple[tuple[str, ...], np.ndarray]:
        names, X, _ = _design(self.params, self.qd, self.signals, self.terms, self.harmonics, self.t_ref,
                              self.smoother, rate)
        return names, np.nan_to_num(X)

    def residual(self, rate: float, train: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """The residual (on ``rows``) of the coefficients fitted on ``train`` at ``rate``."""
        _, X = self.design(rate)
        return self.y[rows] - X[rows] @ _solve(X[train], self.y[train])

    def choose(self, train: np.ndarray, test: np.ndarray, options: TermOptions) -> tuple[float, str, float]:
        """The rate (0: the linear law), a phrase for the temperature term's reason and the exponential's held-out
        RMS [N·m] (NaN when no rate was searched): the exponential when
        ``options.temperature_law`` asks for it, or (``auto``) when fitted on ``train`` it lowers the held-out RMS
        on ``test`` by more than the tolerance and keeps every level physical."""
        from scipy.optimize import minimize_scalar
        dT = np.asarray(self.signals.temperature, dtype=float)[self.use] - self.t_ref
        span = float(np.max(np.abs(dT))) if dT.size else 0.0
        if not span > 0.0:
            return 0.0, "", float("nan")
        bound = RATE_SPAN / span
        found = minimize_scalar(lambda r: float(np.sum(self.residual(r, train, train) ** 2)), bounds=(-bound, bound),
                                method="bounded", options={"xatol": 1e-6 * bound})
        rate = float(found.x)
        rms = {law: float(np.sqrt(np.mean(self.residual(r, train, test) ** 2))) for law, r in
               (("linear", 0.0), ("exponential", rate))}
        names, X = self.design(rate)
        coef, _ = _nonnegative_solve(X[self.use], self.y[self.use], names)
        k = len(velocity_basis(self.params, self.qd[:1])[0])
        unphysical = _unphysical(with_coefficients(self.params, coef[:k]), dict(zip(names[k:], map(float, coef[k:]))),
                                 self.signals, self.use, self.t_ref, rate)
        versus = (f"held-out RMS {rms['exponential']:.4g} N·m exponential (rate {rate:.3g} /°C), {rms['linear']:.4g} "
                  "linear")
        if unphysical is not None:
            return 0.0, f"; law linear: the exponential's levels go below zero ({versus})", rms["exponential"]
        if options.temperature_law == "exponential" or rms["exponential"] < (1.0 - options.tolerance) * rms["linear"]:
            return rate, f"; law exponential: {versus}", rms["exponential"]
        return 0.0, f"; law linear: {versus}", rms["exponential"]

    def rate_column(self, rate: float, names: tuple[str, ...], coef: np.ndarray) -> np.ndarray:
        """The model's derivative in the rate (N,), at the coefficients ``coef`` (``names``' order)."""
        dT = np.asarray(self.signals.temperature, dtype=float) - self.t_ref
        g = coulomb_shape(self.params, self.qd)
        c = dict(zip(names, coef))
        column = (c["F_cT"] * g + c["F_vT"] * self.qd) * temperature_shape_rate(dT, rate)
        return column if self.smoother is None else np.asarray(self.smoother(column[:, None]))[:, 0]


def ripple_size(q: np.ndarray, harmonics: int, names: tuple[str, ...], coef: np.ndarray,
                cov: np.ndarray) -> tuple[float, float]:
    """The ripple's standard deviation over the angles ``q`` it was fitted on [N·m], and its standard error (the
    delta method through the coefficients' covariance): a size its harmonics, correlated over part of a turn, do not
    blur as their amplitudes' errors do."""
    at = [names.index(f"ripple_{f}{h}") for h in range(1, harmonics + 1) for f in ("sin", "cos")]
    F = fourier(q, harmonics)
    ripple = F @ coef[at]
    size = float(np.std(ripple))
    if size == 0.0:
        return 0.0, math.inf
    gradient = (F - F.mean(axis=0)).T @ (ripple - ripple.mean()) / (len(q) * size)
    variance = float(gradient @ cov[np.ix_(at, at)] @ gradient)
    return size, math.sqrt(max(variance, 0.0)) if np.isfinite(variance) else math.inf


def refit_terms(fit: TermFit, params: ModelParams, qd: np.ndarray, tau_f: np.ndarray, use: np.ndarray,
                signals: TermSignals, route: str, smoother=None) -> TermCheck | None:
    """The terms ``fit`` kept, with its harmonics and reference temperature, fitted with the velocity model
    ``params`` (the other route's fit of the same joint) on another estimate of the same samples: what
    :attr:`TermFit.check` compares. Arguments as :func:`fit_terms`'s; None when no term is kept or no sample is
    left."""
    if not fit.kept:
        return None
    qd = np.asarray(qd, dtype=float)
    y = -np.asarray(tau_f, dtype=float)
    use = _moving(use, qd, y, signals)
    qd_ = qd if smoother is not None else np.where(use, qd, 0.0)
    names, X, k = _design(params, qd_, signals, fit.kept, fit.harmonics, fit.reference_temperature or 0.0,
                          smoother, fit.temperature_rate)
    use &= np.isfinite(X).all(axis=1)
    if use.sum() <= X.shape[1]:
        return None
    coef, cov, _ = _final(X, np.where(use, y, 0.0), use, names)
    coefficients = dict(zip(names, map(float, coef)))
    stderr = dict(zip(names, map(float, covariance_errors(cov))))
    if "ripple" in fit.kept and signals.q is not None:
        coefficients["ripple_rms"], stderr["ripple_rms"] = ripple_size(np.asarray(signals.q, dtype=float)[use],
                                                                      fit.harmonics, names, coef, cov)
    return TermCheck(route, coefficients, stderr)


def _unphysical(params: ModelParams, c: dict[str, float], signals: TermSignals, use: np.ndarray,
                t_ref: float, rate: float = 0.0) -> tuple[Term, str] | None:
    """The first friction term whose levels go below zero on the samples (a viscous level in a direction, a Coulomb
    level under a load met, a level at a temperature met) and what goes below; None when all stay physical."""
    F_c, F_v = params.F_c, params.F_v
    if "dF_v" in c and min(F_v + c["dF_v"], F_v - c["dF_v"]) < 0:
        return "direction", (f"a viscous level below zero in one direction (F_v {F_v:.3g}, dF_v {c['dF_v']:.3g}): "
                             "not friction")
    if "F_L" in c and signals.tau_load is not None:
        lowest = F_c + c["F_L"] * float(np.max(np.abs(np.asarray(signals.tau_load)[use])))
        if lowest < 0:
            return "load", f"a Coulomb level below zero under the largest load met ({lowest:.3g} N·m): not friction"
    if "F_cT" in c and signals.temperature is not None:
        phi = temperature_shape(np.asarray(signals.temperature, dtype=float)[use] - t_ref, rate)
        levels = (F_c + c["F_cT"] * phi, F_v + c["F_vT"] * phi)
        if min(float(np.min(x)) for x in levels) < 0:
            return "temperature", "a Coulomb or viscous level below zero at a temperature met: not friction"
    return None


def _negligible(names: tuple[str, ...], X: np.ndarray, coef: np.ndarray, k: int,
                options: TermOptions) -> tuple[Term, str] | None:
    """The kept term whose torque over the samples (the standard deviation of its regressors times its
    coefficients, ``X`` (n, p) the design on them) is the smallest, if it is below :attr:`TermOptions.min_effect`
    of the velocity model's friction or below :attr:`TermOptions.min_torque`: a term too small to matter (on
    noise-free data, the 2 % rule alone keeps terms of a thousandth of the friction); None when every term
    matters."""
    friction = float(np.sqrt(np.mean((X[:, :k] @ coef[:k]) ** 2)))
    effects: dict[Term, float] = {}
    for term in TERMS:
        cols = [i for i, n in enumerate(names) if i >= k and _term_of(n) == term]
        if cols:
            effects[term] = float(np.std(X[:, cols] @ coef[cols]))  # its mean is the offset's to take
    if not effects:
        return None
    term = min(effects, key=lambda t: effects[t])
    if effects[term] >= max(options.min_effect * friction, options.min_torque):
        return None
    return term, (f"its torque ({effects[term]:.2g} N·m standard deviation) is below "
                  f"{100 * options.min_effect:g} % of the friction's ({friction:.2g} N·m) or {options.min_torque:g} "
                  "N·m: too small to matter")


def _term_of(name: str) -> Term:
    """The term a coefficient belongs to."""
    if name.startswith("ripple"):
        return "ripple"
    if name == "rate_T":
        return "temperature"
    return next(t for t, names in TERM_COEFFICIENTS.items() if name in names)


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
