"""The report of fits with terms beyond velocity (issue 53, class 11): before, the HTML never named the terms, its F_c
"usable" was the level at zero load and T_ref went unstated. Now the summary says at which conditions F_c and F_v
hold, and a section gives each term, its status, its values and the ranges it was fitted on."""

from __future__ import annotations

import html
import re

import numpy as np

from helpers import run_cli
from term_params import JOINT, edited, ok_fit, params_file, table_file, term_fit
from wbfriction.report.terms import terms_section


def _text(page: str) -> str:
    """The page's text as a reader sees it: no tags, no embedded images, entities decoded, spaces collapsed."""
    page = re.sub(r'src="data:image/png;base64,[^"]*"', "", page)
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", page)).split())


def test_the_conditions_follow_the_terms_kept():
    assert term_fit(("load", "temperature")).reference_conditions() == "zero load, T_ref 40 °C"
    assert term_fit(("ripple",)).reference_conditions() == "no ripple"
    assert term_fit(("load", "ripple", "temperature")).reference_conditions() == "zero load, T_ref 40 °C, no ripple"


def test_the_section_names_each_term_its_status_and_its_fitted_range():
    fits = {JOINT: ok_fit(term_fit()), "other": ok_fit(None, "other")}
    text = _text(terms_section([JOINT, "other"], fits, lambda j: f"<td>{j}</td>"))
    assert "F_c 1.000" in text and "at zero load, T_ref 40 °C, no ripple" in text, text
    for term, fitted in (("load", "|load| 0 to 30 N·m"), ("ripple", "q 0.5 to 2.5 rad"),
                         ("temperature", "T 25 to 55 °C")):
        assert re.search(rf"{term} ok .*?{re.escape(fitted)}", text), (term, text)
    assert "F_L 0.0200" in text and "k_L 0.0200" in text and "2 harmonics" in text, text
    assert "other" not in text  # no terms: no row
    assert terms_section(["other"], fits, str) == ""


def test_report_states_the_terms_and_the_reference_conditions(tmp_path, capsys):
    table = table_file(tmp_path / "friction.parquet", np.linspace(25.0, 55.0, 400))
    good = params_file(tmp_path / "params.json", term_fit())
    old = edited(good, lambda e: e["terms"].pop("ranges"), tmp_path / "old.json")
    for params in (good, old):
        out = tmp_path / f"{params.stem}.html"
        code, err = run_cli(capsys, "report", table, "--params", params, "-o", out, "--workers", "1")
        assert code == 0, err
        text = _text(out.read_text())
        assert "usable; F_c, F_v at zero load, T_ref 40 °C, no ripple (terms beyond velocity: load, ripple, " \
               "temperature)" in text, text
        assert "Terms beyond velocity" in text and "q 0.5 to 2.5 rad" in text
        assert ("T 25 to 55 °C" in text) == (params == good) and ("not recorded" in text) == (params == old)
