"""The report's terms beyond velocity (issue 53, class 11): what a fit with terms (:mod:`wbfriction.fit.terms`)
means for the numbers the report shows.

A fit that kept terms reports its velocity model refitted with them
(:meth:`~wbfriction.fit.result.FitResult.reported`): its F_c and F_v are the levels at the reference conditions
(zero load, the reference temperature ``T_ref``, no ripple, the mean of both directions), not the joint's friction
under its own load or warmth. The report says so beside them
(:meth:`~wbfriction.fit.terms.TermFit.reference_conditions`) and gives each joint's terms in a table
(:func:`terms_section`): each term's status, its coefficients ± standard errors and the physical parameters they
give, and the ranges of angle, load and temperature it was fitted on
(:class:`~wbfriction.fit.ranges.FittedRanges`: beyond them its law is extrapolated).
"""

from __future__ import annotations

import html
from collections.abc import Callable, Mapping, Sequence

from wbfriction.fit.result import FitResult
from wbfriction.fit.terms import TERM_COEFFICIENTS, TermFit
from wbfriction.report.numbers import with_error

DERIVED: dict[str, tuple[str, ...]] = {"load": ("k_L",), "direction": ("F_v+", "F_v-"),
                                       "temperature": ("k_Tc", "k_Tv"), "ripple": ()}
"""The physical parameters each term's row shows after its coefficients (:attr:`TermFit.derived`)."""
UNITS: dict[str, str] = {"F_L": "", "k_L": "/(N·m)", "dF_v": "N·m·s/rad", "F_v+": "N·m·s/rad", "F_v-": "N·m·s/rad",
                         "F_cT": "N·m/°C", "F_vT": "N·m·s/(rad·°C)", "k_Tc": "/°C", "k_Tv": "/°C", "rate_T": "/°C",
                         "ripple_rms": "N·m"}


def _value(terms: TermFit, name: str) -> str:
    """``name value ± standard error unit`` of a coefficient or derived parameter of ``terms``."""
    values = {**terms.coefficients, **terms.derived}
    unit = UNITS.get(name, "")
    return f"{name} {with_error(values[name], terms.stderr.get(name))}" + (f" {unit}" if unit else "")


def _fitted_range(terms: TermFit, term: str) -> str:
    """The range of the term's signal it was fitted on, or that it is not recorded (a file of an earlier
    version); "" for a term without a signal (direction)."""
    if term == "ripple":
        span, what, unit = terms.q_range, "q", "rad"
    elif term in ("load", "temperature"):
        span = None if terms.ranges is None else terms.ranges.get(term)
        what, unit = ("|load|", "N·m") if term == "load" else ("T", "°C")
    else:
        return ""
    return "not recorded" if span is None else f"{what} {span[0]:.3g} to {span[1]:.3g} {unit}"


def terms_section(joints: Sequence[str], fits: Mapping[str, FitResult], cell: Callable[[str], str]) -> str:
    """The HTML section of the terms beyond velocity of the ``joints`` whose fit kept some (``cell(joint)``: the
    joint's first cell), "" when none did: per joint a row of F_c, F_v refitted with the terms and the conditions
    they hold at, then a row per term (its status and reason, values, fitted range)."""
    rows = []
    for joint in joints:
        fit = fits.get(joint)
        terms = None if fit is None else fit.kept_terms
        if fit is None or terms is None or fit.params is None:
            continue
        levels = ", ".join(f"{n} {with_error(getattr(terms.params, n), terms.stderr.get(n))}" for n in ("F_c", "F_v"))
        rows.append(f"<tr>{cell(joint)}<td class=\"text\">velocity</td><td></td>"
                    f"<td class=\"text\">{html.escape(levels)} at {html.escape(terms.reference_conditions())}</td>"
                    "<td></td></tr>")
        for term, verdict in terms.verdicts().items():
            names = list(dict.fromkeys((*TERM_COEFFICIENTS[term], *DERIVED[term])))  # the ripple: its size
            if term == "temperature" and terms.temperature_rate:
                names.append("rate_T")
            parts = [_value(terms, n) for n in names if n in terms.coefficients or n in terms.derived]
            if term == "ripple":
                parts.append(f"{terms.harmonics} harmonic{'s' if terms.harmonics > 1 else ''}")
            values = "; ".join(parts)
            status = str(verdict)
            rows.append(f"<tr{'' if verdict.ok else ' class=notok'}><td></td><td class=\"text\">{term}</td>"
                        f"<td class=\"status\">{html.escape(status)}</td><td class=\"text\">{html.escape(values)}</td>"
                        f"<td class=\"text\">{html.escape(_fitted_range(terms, term))}</td></tr>")
    if not rows:
        return ""
    return ('<h2 id="terms-section">Terms beyond velocity</h2>'
            '<p class="sub">Where a joint\'s fit kept terms in its load, angle, direction of motion or temperature, '
            "its F_c and F_v above are its velocity model refitted with them: the levels at the reference conditions "
            "each row names (zero load, the reference temperature T_ref), not the friction under the joint's own load "
            "or warmth. The ripple is a torque of the angle, not friction (left out of the energy check and the "
            "exports). Beyond the ranges a term was fitted on its law is extrapolated.</p>"
            '<div class="scroll"><table id="terms"><tr><th>joint</th><th class="text">term</th>'
            '<th class="text">status</th><th class="text">values (± standard error)</th>'
            f'<th class="text">fitted on</th></tr>{"".join(rows)}</table></div>')
