"""What a parameters file's values may be: the rules :func:`~wbfriction.fit.params_file.read_params` applies to every
joint it reads (issue 53), the same for ``predict``, ``export`` and ``report``.

``wbfriction fit`` writes a joint's friction within the fit's bounds (:func:`~wbfriction.fit.coordinates.model_bounds`)
and its terms beyond velocity (:mod:`~wbfriction.fit.terms`) whole. A hand-edited file may not be either, and
was used silently before: a negative F_c predicted (only ``export`` refused it), ``reference_temperature: null`` was
taken as 0 °C, a reversed ``q_range`` held the ripple at one angle, a ``terms.model`` changed to another model read
its parameters under that model's defaults, a kept term's coefficient removed was a ``KeyError`` in ``predict``, a
``rate_T`` of 1e3 overflowed into RuntimeWarnings. Each is refused here in one :class:`ValueError` naming the key at
fault (the reader adds the file and the joint).

The rules:

* a model's parameters (``params``, ``terms.params``): finite numbers; dissipative friction, ``F_v >= 0``,
  ``F_c >= 0`` and a static level ``F_s >= 0`` (``S >= -1`` of (3.5)), as the exports require
  (:class:`~wbfriction.export.mapping.JointExport`; ``F_s`` of
  :meth:`~wbfriction.friction.models.ModelParamsBase.quantities`); a positive Stribeck velocity ``v_s``, tanh
  slope ``a`` and Stribeck exponent ``delta_s``;
* ``terms.model`` is the joint's ``model`` (the terms refit that model's coefficients);
* ``terms.harmonics`` is at least 1 with the ripple kept, 0 without; ``terms.coefficients`` are exactly the kept
  terms' (:func:`term_coefficient_names`), finite, and ``rate_T`` only with the temperature term;
* with the temperature term, ``terms.reference_temperature`` is a finite number [°C], and ``rate_T`` (if any) at
  most :data:`MAX_RATE` in size and, where the fitted temperatures are recorded, within the fit's search
  (``RATE_SPAN`` over the largest ``|T - T_ref|`` fitted);
* with the ripple, ``terms.q_range`` is a range ``[low, high]`` of finite angles, low first;
* ``terms.ranges`` (:class:`~wbfriction.fit.ranges.FittedRanges`; read by its own reader) hold ranges low first.
"""

from __future__ import annotations

import math
from dataclasses import fields

from wbfriction.fit.ranges import check_span
from wbfriction.fit.temperature_law import RATE_SPAN
from wbfriction.fit.terms import TERM_COEFFICIENTS, TermFit
from wbfriction.friction.models import ModelParams

MAX_RATE = 1.0
"""The largest size of the temperature law's rate ``rate_T`` [1/°C] a file may hold: friction changing e-fold per
degree, beyond any grease's (``fit`` searches within ``RATE_SPAN`` over the temperatures logged, 0.1 /°C over 30 °C)."""
POSITIVE = ("v_s", "a", "delta_s")
"""Parameters that are positive by definition (a speed, a slope, an exponent)."""


def check_model_params(params: ModelParams, key: str) -> None:
    """Refuse parameters ``fit`` does not write (module docstring).

    Raises:
        ValueError: naming ``key.<parameter>`` and the value.
    """
    values = {f.name: getattr(params, f.name) for f in fields(params)}
    for name, value in values.items():
        if not math.isfinite(value):
            raise ValueError(f"{key}.{name} is {value}: not a finite number")
    for name, unit in (("F_v", "N·m·s/rad"), ("F_c", "N·m")):
        if name in values and values[name] < 0:
            raise ValueError(f"{key}.{name} = {values[name]:g} {unit} < 0: friction that is not dissipative")
    static = params.quantities()["F_s"]
    if static < 0:
        raise ValueError(f"{key}: a static friction level F_s of {static:g} N·m < 0 (S < -1 of (3.5)): friction "
                         "that is not dissipative")
    for name in POSITIVE:
        if name in values and not values[name] > 0:
            raise ValueError(f"{key}.{name} = {values[name]:g}: not positive")


def term_coefficient_names(terms: TermFit) -> tuple[str, ...]:
    """The coefficients ``terms``' kept terms have (:data:`~wbfriction.fit.terms.TERM_COEFFICIENTS`; the
    ripple's ``ripple_sin<h>``, ``ripple_cos<h>`` for ``h = 1..harmonics``), without the optional ``rate_T``."""
    names: list[str] = []
    for term in terms.kept:
        if term == "ripple":
            names += [n for h in range(1, terms.harmonics + 1) for n in (f"ripple_sin{h}", f"ripple_cos{h}")]
        else:
            names += TERM_COEFFICIENTS[term]
    return tuple(names)


def check_terms(terms: TermFit, model: str, key: str = "terms") -> None:
    """Refuse a joint's terms beyond velocity that ``fit`` does not write for a joint of ``model`` (module
    docstring).

    Raises:
        ValueError: naming ``key.<what>`` and why.
    """
    if terms.params.model != model:
        raise ValueError(f"{key}.model is '{terms.params.model}', the joint's model '{model}': the terms refit the "
                         "joint's own model")
    check_model_params(terms.params, f"{key}.params")
    ripple = "ripple" in terms.kept
    if (ripple and terms.harmonics < 1) or (not ripple and terms.harmonics != 0):
        raise ValueError(f"{key}.harmonics is {terms.harmonics}: " + (
            "the ripple kept needs at least 1" if ripple else "0 without the ripple kept"))
    expected = term_coefficient_names(terms)
    for name in expected:
        if name not in terms.coefficients:
            term = next(t for t in terms.kept if name in TERM_COEFFICIENTS[t] or t == "ripple" and "ripple" in name)
            raise ValueError(f"{key}.coefficients has no '{name}': the kept {term} term needs it"
                             + (f" ({terms.harmonics} harmonics)" if term == "ripple" else ""))
    allowed = set(expected) | ({"rate_T"} if "temperature" in terms.kept else set())
    for name, value in terms.coefficients.items():
        if name not in allowed:
            raise ValueError(f"{key}.coefficients.{name} is not a coefficient of the kept terms "
                             f"({', '.join(terms.kept) or 'none'}"
                             + (f", {terms.harmonics} harmonics)" if ripple else ")"))
        if not math.isfinite(value):
            raise ValueError(f"{key}.coefficients.{name} is {value}: not a finite number")
    t_ref = terms.reference_temperature
    if t_ref is not None and not math.isfinite(t_ref):
        raise ValueError(f"{key}.reference_temperature is {t_ref}: not a finite number [°C]")
    if "temperature" in terms.kept:
        if t_ref is None:
            raise ValueError(f"{key}.reference_temperature is null: the kept temperature term is a law of T - T_ref "
                             "and needs T_ref [°C]")
        _check_rate(terms, t_ref, key)
    span = check_span(None if terms.q_range is None else list(terms.q_range), f"{key}.q_range")
    if ripple and span is None:
        raise ValueError(f"{key}.q_range is null: the kept ripple needs the angles it was fitted on [rad]")


def _check_rate(terms: TermFit, t_ref: float, key: str) -> None:
    """Refuse a temperature law's rate ``fit`` would not have found (module docstring)."""
    rate = terms.temperature_rate
    if abs(rate) > MAX_RATE:
        raise ValueError(f"{key}.coefficients.rate_T is {rate:g} /°C: beyond ±{MAX_RATE:g} /°C (friction changing "
                         "e-fold per degree)")
    fitted = None if terms.ranges is None else terms.ranges.temperature
    if fitted is not None and rate != 0.0:
        widest = max(abs(fitted[0] - t_ref), abs(fitted[1] - t_ref))
        if widest > 0 and abs(rate) > RATE_SPAN / widest * (1 + 1e-6):
            raise ValueError(f"{key}.coefficients.rate_T is {rate:g} /°C: beyond the ±{RATE_SPAN / widest:.3g} /°C "
                             f"'fit' searches over the temperatures fitted ({fitted[0]:g} to {fitted[1]:g} °C)")
