"""Friction beyond velocity (issue 40): terms in the joint's load, angle, direction of motion and temperature, each
kept only where held-out samples say it predicts better.

The thesis's models (:mod:`~wbfriction.friction.models`) are functions of the velocity alone. Real joints are not:
the friction of a gear grows with the load its teeth carry, a torque sensor or transmission adds a torque periodic
in the joint's angle, the Coulomb level may differ by direction, and warm grease drags less than cold (Bittencourt &
Axelsson, "Modeling and experiment design for identification of wear in a robot joint under load and temperature
uncertainties based on friction data", IEEE/ASME Trans. Mechatronics 19(5), 2014: load and temperature change
friction more than wear does). With the velocity model's non-linear parameters held at their fit (the tanh slope
``a``, the Stribeck velocity ``v_s``), the model and every term below are linear in their coefficients: one
weighted least-squares solve fits them together (``term_selection.fit_terms``). ``g(qd)`` is the model's Coulomb shape,
``sgn(qd)`` or ``tanh(a qd)`` (:func:`coulomb_shape`):

* ``load``: load-dependent Coulomb friction ``F_c (1 + k_L |tau_load|) g(qd)``, ``tau_load`` the joint's rigid-body
  torque [N·m] (gear-tooth load): coefficient ``F_L = F_c k_L`` on ``|tau_load| g``; ``k_L`` [1/(N·m)].
* ``direction``: the viscous level by direction of motion, ``F_v± = F_v ± dF_v``: coefficient ``dF_v`` on ``|qd|``.
  The Coulomb level by direction needs no term: away from rest ``F_c± = F_c ± tau_os`` (the offset of (3.4) is the
  half-difference of the two levels, which no moving sample tells apart from a sensor offset), reported with it.
* ``ripple``: a torque periodic in the joint's angle ``q`` [rad], ``sum_h s_h sin(h q) + c_h cos(h q)`` for
  ``h = 1..H`` (``H`` chosen on held-out samples, at most :attr:`TermOptions.max_harmonic`): torque sensing or
  transmission ripple, neither friction nor inertia. It is tried only where, fitted on the samples moving one way,
  it predicts those moving the other (``term_checks.direction_gain``): a torque of the angle does not care which
  way the joint moves, a model error that follows the trajectory does (on the KUKA LWR4+, the wrist's ripple carries
  over by 44-50 %, the upper arm's "ripple" makes the other direction worse by 10-35 %); and with no more harmonics than
  its angles tell apart (``term_checks.MAX_CONDITION``). It is not dissipative: it is reported apart, left out of the
  energy check (eq. 7.9) and of the exports; predictions include it, at the angle reduced modulo 2π into the turn
  around the arc of the angles it was fitted on (a continuous joint logged on another branch is at the same angle,
  :func:`ripple_angle`; the arc is that of the physical angles, :func:`~wbfriction.fit.ranges.angle_arc`), within
  those angles (outside, it is held at its value at the nearest fitted angle: a Fourier series fitted on less than a
  turn is not known beyond its data, and would run away there).
* ``temperature``: the Coulomb and viscous levels ``F_c + F_cT phi(T - T_ref)`` and ``F_v + F_vT phi(T - T_ref)``,
  ``T`` the logged joint temperature [°C], ``T_ref`` the reference temperature every output states: coefficients
  ``F_cT`` on ``phi g`` and ``F_vT`` on ``phi qd``, the levels' slopes at ``T_ref`` [N·m/°C, N·m·s/(rad·°C)]
  (``k_Tc = F_cT / F_c``, ``k_Tv = F_vT / F_v`` relative [1/°C]). The law ``phi`` (:func:`temperature_shape`) is
  linear, ``phi(dT) = dT``, or exponential, ``phi(dT) = (exp(r dT) - 1) / r`` with a rate ``r`` [1/°C]
  (``rate_T``; Bittencourt's exponential decrease of friction with temperature: ``F_c exp(k_Tc dT)`` when
  ``F_cT = r F_c``, levels that flatten as grease thins); the exponential is kept where held-out samples say it
  predicts better than the linear (:attr:`~wbfriction.fit.options.TermOptions.temperature_law`), its rate
  fitted by a bounded scalar search with the coefficients solved at each rate (variable projection) and its
  standard error from the Jacobian column of the rate.

Which terms a joint keeps, and their fit: :mod:`~wbfriction.fit.term_selection`.

Sign convention: as everywhere, the characteristic ``f`` points along the velocity and ``tau_f = -f``; a term's
coefficients are positive where it adds friction opposing the motion (``F_L``, ``F_cT``, ``F_vT`` > 0: more friction
under load or warm; ``k_Tc < 0``: less friction warm). The ripple's sign is that of ``f``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any, cast

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.fit.ranges import TERM_SIGNAL, FittedRanges, RangeUse, SignalUse, ripple_angle, same_turn
from wbfriction.fit.status import TERM_WEAK, FitVerdict, routes_disagree
from wbfriction.friction.estimated import FrictionEstimate
from wbfriction.friction.families.registry import family
from wbfriction.friction.models import (
    ModelParams,
    params_from_dict,
)
from wbfriction.friction.options import TERMS, Term

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


def load_torque(est: FrictionEstimate) -> np.ndarray | None:
    """The load term's signal of every column (N, n_tc) [N·m]: the rigid-body torque ``M qdd + h = tau + tau_f``
    (the sign convention's, :mod:`~wbfriction.friction.estimate`; NaN where the friction is not estimated), not the
    measured torque, which holds the friction itself (a drive's current does); None without measured torques."""
    return None if est.tau is None else est.tau + est.tau_f


def term_signals(est: FrictionEstimate, joint: int) -> TermSignals:
    """The terms' signals of column ``joint`` of an estimate: its ``q``; its load (:func:`load_torque`); its
    ``temperature`` (a column all NaN: not logged)."""
    temperature = None if est.temperature is None else est.temperature[:, joint]
    if temperature is not None and np.all(np.isnan(temperature)):
        temperature = None
    load = load_torque(est)
    return TermSignals(None if est.q is None else est.q[:, joint], None if load is None else load[:, joint],
                       temperature)


SIGNAL_COLUMNS: dict[Term, str] = {"load": "tau", "ripple": "q", "temperature": "temperature"}
"""The friction table's column (``<name>.<joint>``) each term's signal is read from."""
NOT_TRIED = "not tried"
"""How a term's reason starts where the table lacks its signal (:data:`SIGNAL_COLUMNS`)."""


def coulomb_shape(params: ModelParams, qd: np.ndarray) -> np.ndarray:
    """``g(qd)``: the model's Coulomb shape (N,), ``tanh(a qd)`` for (3.5), ``sgn(qd)`` for the others (its family's
    :meth:`~wbfriction.friction.families.base.FrictionFamily.coulomb_shape`)."""
    return family(params.model).coulomb_shape(params, qd)


def velocity_basis(params: ModelParams, qd: np.ndarray) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
    """The velocity model as linear in its coefficients, its non-linear parameters held (``a``, ``v_s``,
    ``delta_s``): ``f(qd) = B c`` exactly (its family's
    :meth:`~wbfriction.friction.families.base.FrictionFamily.velocity_basis`).

    Returns:
        ``(names, B, c)``: the coefficients' names, the regressors (N, k) and the coefficients (k,) of ``params``:
        ``F_v, F_c, tau_os`` (Coulomb-viscous), ``F_v, F_c, F_s, tau_os`` (Stribeck), ``F_v, F_c, F_cS, tau_os``
        with ``F_cS = F_c S`` (3.5).
    """
    return family(params.model).velocity_basis(params, qd)


def with_coefficients(params: ModelParams, c: np.ndarray) -> ModelParams:
    """``params`` with the linear coefficients ``c`` of :func:`velocity_basis` (the non-linear ones kept)."""
    return cast(ModelParams, family(params.model).with_coefficients(params, c))


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
        q_range: the arc of the angles the ripple was fitted on, ``(q_low, q_high)`` [rad] (None: no ripple;
            :func:`~wbfriction.fit.ranges.angle_arc`, whatever branches the table held them on); it predicts at angles
            reduced modulo 2π and held within it (:func:`ripple_angle`).
        reasons: per term tried, why it was kept or not (one sentence).
        held_out_rms: the held-out RMS [N·m] of the velocity model alone and with the terms kept.
        check: the kept terms refitted on the other route's estimate (``term_selection.refit_terms``), or None.
        later: per kept term, how far its torque fitted on the earlier samples departs on the later ones from theirs
            and how far the noise and its standard errors allow [N·m] (``term_checks.later_check``); empty: not
            checked.
        at_bound: the velocity model's magnitudes held at zero in the refit (``term_design.NONNEGATIVE``): with
            the terms, the data would put them below it (standard error 0: held, not fitted).
        covariance: the coefficients' covariance, the velocity model's (:func:`velocity_basis` order) then the
            terms', or None (read from a parameters file, which keeps the standard errors only).
        ranges: the angles, loads and temperatures of the samples fitted
            (:class:`~wbfriction.fit.ranges.FittedRanges`), or None (not recorded: a parameters file of an
            earlier version); a prediction says where a table leaves them (:meth:`range_use`).
        block_spread: the velocity model's linear coefficients' and the terms' block-jackknife standard errors
            (:func:`~wbfriction.fit.block_spread.linear_block_spread`), by name; empty: not computed (a parameters
            file of an earlier version). The read error takes the larger of it and :attr:`stderr`.
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
    later: dict[str, tuple[float, float]] = field(default_factory=dict)
    ranges: FittedRanges | None = None
    block_spread: dict[str, float] = field(default_factory=dict)

    @property
    def temperature_rate(self) -> float:
        """The temperature law's rate ``rate_T`` [1/°C] (0: linear; :func:`temperature_shape`)."""
        return self.coefficients.get("rate_T", 0.0)

    def verdicts(self) -> dict[Term, FitVerdict]:
        """Per kept term, whether its numbers can be used (``ok``, ``weak``, ``routes disagree``, ``does not predict``)
        and why.

        * ``routes disagree``: the other route's estimate gives one of its coefficients (the ripple: its size,
          ``term_design.ripple_size``) more than :data:`~wbfriction.fit.status.ROUTE_Z` combined standard
          errors and :data:`~wbfriction.fit.status.ROUTE_REL` away (:attr:`check`);
        * ``weak``: a coefficient's (the ripple's size's) standard error above
          :data:`~wbfriction.fit.status.TERM_WEAK` of its value;
        * ``does not predict`` (issue 52): fitted on the earlier samples, its torque departs on the later ones from
          theirs beyond what the noise and its standard errors allow (:attr:`later`,
          ``term_checks.later_check``);
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
            weak = [f"{n} {v:.3g} ±{se:.2g}" for n, (v, se) in mine.items() if not se <= TERM_WEAK * abs(v)]
            d, allowed = self.later.get(term, (0.0, math.inf))
            out[term] = (FitVerdict("routes disagree", "; ".join(off)) if off
                         else FitVerdict("weak", "large standard errors: " + ", ".join(weak)) if weak
                         else FitVerdict("does not predict", f"fitted on the earlier samples its torque departs on "
                                                             f"the later ones by {d:.2g} N·m from theirs, the noise "
                                                             f"and its standard errors allow {allowed:.2g}")
                         if not d <= allowed
                         else FitVerdict("ok"))
        return out

    def _read(self, term: Term, c: Mapping[str, float], se: Mapping[str, float]) -> dict[str, tuple[float, float]]:
        """The values a status judges of ``term`` (name -> value, standard error): its coefficients, the ripple's
        size (``term_design.ripple_size``)."""
        names = TERM_COEFFICIENTS[term] + (("rate_T",) if term == "temperature" else ())
        return {n: (c[n], se.get(n, math.inf)) for n in names if n in c}

    def reference_conditions(self) -> str:
        """The conditions the refitted F_c and F_v (:attr:`params`) hold at, by the terms kept: ``zero load``,
        ``T_ref 40 °C``, ``the mean of both directions``, ``no ripple`` (comma-separated; "" with none kept)."""
        parts = []
        if "load" in self.kept:
            parts.append("zero load")
        if "temperature" in self.kept and self.reference_temperature is not None:
            parts.append(f"T_ref {self.reference_temperature:.3g} °C")
        if "direction" in self.kept:
            parts.append("the mean of both directions")
        if "ripple" in self.kept:
            parts.append("no ripple")
        return ", ".join(parts)

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
                "later": {t: [clean(d), clean(a)] for t, (d, a) in self.later.items()},
                "ranges": None if self.ranges is None else self.ranges.to_dict(),
                **({"block_spread": {k: clean(v) for k, v in self.block_spread.items()}} if self.block_spread else {}),
                "status": {t: v.status for t, v in verdicts.items()},
                "status_reason": {t: v.reason for t, v in verdicts.items() if v.reason}}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> TermFit:
        """Inverse of :meth:`to_dict` (``null`` reads back as ``inf`` for a standard error, NaN otherwise; the
        statuses follow from the rest; without ``ranges``, a file of an earlier version, the ranges are not known).
        What the values may be is checked by the parameters file's reader (:mod:`~wbfriction.fit.params_check`).

        Raises:
            InputError: a missing key, an unknown term or model, a value of the wrong kind (named).
        """
        try:
            kept = tuple(check_term(str(t)) for t in d["kept"])
            rng = d.get("q_range")
            check = d.get("check")
            t_ref = d.get("reference_temperature")
            ranges = d.get("ranges")
            return cls(params_from_dict(str(d["model"]), d["params"]), kept, int(d.get("harmonics", 0)),
                       {str(k): float(v) for k, v in d["coefficients"].items()},
                       {str(k): math.inf if v is None else float(v) for k, v in (d.get("stderr") or {}).items()},
                       {str(k): _number(v) for k, v in (d.get("derived") or {}).items()},
                       None if t_ref is None else float(t_ref),
                       None if rng is None else (float(rng[0]), float(rng[1])),
                       {str(k): str(v) for k, v in (d.get("reasons") or {}).items()},
                       tuple(_number(x) for x in d.get("held_out_rms", (None, None))),  # type: ignore[arg-type]
                       None if check is None else TermCheck.from_dict(check),
                       tuple(str(n) for n in d.get("at_bound", ())),
                       later={str(t): (_number(v[0]), math.inf if v[1] is None else float(v[1]))
                              for t, v in (d.get("later") or {}).items()},
                       ranges=None if ranges is None else FittedRanges.from_dict(ranges),
                       block_spread={str(k): _number(v) for k, v in (d.get("block_spread") or {}).items()})
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

    def range_use(self, signals: TermSignals, rows: np.ndarray, joint: str = "") -> RangeUse:
        """Where the samples ``rows`` (N,) bool of ``signals`` leave the ranges these terms were fitted on
        (:mod:`~wbfriction.fit.ranges`), for each kept term that reads a signal: the ripple's angle, reduced
        modulo 2π as it predicts with it (:func:`~wbfriction.fit.ranges.ripple_angle`), against
        :attr:`q_range`; the load's magnitude and the temperature against :attr:`ranges` (not recorded: said so)."""
        outside: list[SignalUse] = []
        unknown: list[str] = []
        for term in self.kept:
            signal = TERM_SIGNAL.get(term)
            if signal is None:
                continue
            fitted = self.q_range if signal == "angle" else None if self.ranges is None else self.ranges.get(signal)
            if fitted is None:
                unknown.append(term)
                continue
            x = {"angle": signals.q, "load": signals.tau_load, "temperature": signals.temperature}[signal]
            if x is None:
                continue
            x = np.asarray(x, dtype=float)[rows]
            x = np.abs(x) if signal == "load" else same_turn(x, fitted) if signal == "angle" else x
            x = x[np.isfinite(x)]
            excess = np.maximum(fitted[0] - x, x - fitted[1])
            if x.size and excess.max() > 0:
                outside.append(SignalUse(signal, fitted, (float(x.min()), float(x.max())),
                                         float(np.mean(excess > 0)), float(excess.max())))
        return RangeUse(joint, tuple(outside), tuple(unknown))

    def speed_friction(self, v: float, load: float = 0.0) -> tuple[float, float]:
        """The dissipative friction at speed ``v`` [rad/s] at the reference temperature ``T_ref``, without the
        ripple, under the load ``|load|`` [N·m] where a load term is kept (0: the reference conditions):
        ``(f(+v) - f(-v)) / 2`` [N·m], and its standard error from :attr:`covariance` (NaN without)."""
        speeds = np.array([v, -v])
        _, B, c = velocity_basis(self.params, speeds)
        g = 0.5 * (B[0] - B[1])
        if "load" in self.kept:  # F_L |tau_load| g(qd): the first term's column (TERMS order)
            shape = coulomb_shape(self.params, speeds)
            g = np.append(g, 0.5 * (shape[0] - shape[1]) * abs(load))
            c = np.append(c, self.coefficients["F_L"])
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
        f = p.f_at(qd)
        g = family(p.model).coulomb_sign(p, qd)
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
                angle = q
                if self.q_range is not None:  # ripple_angle of one float
                    lo, hi = self.q_range
                    angle = q - 2.0 * math.pi * round((q - 0.5 * (lo + hi)) / (2.0 * math.pi))
                    angle = min(max(angle, lo), hi)
                f += sum(c[f"ripple_sin{h}"] * math.sin(h * angle) + c[f"ripple_cos{h}"] * math.cos(h * angle)
                         for h in range(1, self.harmonics + 1))
        return -f

    def _value(self, qd: np.ndarray, signals: TermSignals, dissipative: bool) -> np.ndarray:
        f = self.params.f(qd)
        if self.q_range is not None and signals.q is not None:  # the ripple is known on its fitted angles only
            signals = replace(signals, q=ripple_angle(signals.q, self.q_range))
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
"""Each term's values a status judges: its coefficients; for the ripple, its size (``term_design.ripple_size``; its
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
        block_spread: their block-jackknife standard errors, by name (:attr:`TermFit.block_spread`; empty: not
            computed).
    """

    route: str
    coefficients: dict[str, float]
    stderr: dict[str, float]
    block_spread: dict[str, float] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"route": self.route, "coefficients": dict(self.coefficients),
                "stderr": {k: _finite_or_none(v) for k, v in self.stderr.items()},
                **({"block_spread": {k: _finite_or_none(v) for k, v in self.block_spread.items()}}
                   if self.block_spread else {})}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> TermCheck:
        return cls(str(d["route"]), {str(k): float(v) for k, v in d["coefficients"].items()},
                   {str(k): math.inf if v is None else float(v) for k, v in (d.get("stderr") or {}).items()},
                   {str(k): _number(v) for k, v in (d.get("block_spread") or {}).items()})
