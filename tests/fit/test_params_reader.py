"""The parameters file read through one validating reader (issue 53, classes 9 and 14): what ``fit`` would not have
written is refused in one line naming the file, the joint and the key, by ``predict``, ``export`` and ``report``
alike, before any work; what it writes reads back, the fitted ranges with it, and a file of an earlier version (no
ranges) still reads."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import run_cli, said
from term_params import JOINT, RANGES, edited, params_file, table_file, term_fit
from wbfriction.exceptions import InputError
from wbfriction.fit.params_file import read_params


def _set(*keys, value):
    """An edit setting ``entry[k1][k2]... = value``."""
    def edit(entry):
        for k in keys[:-1]:
            entry = entry[k]
        entry[keys[-1]] = value
    return edit


def _drop(*keys):
    def edit(entry):
        for k in keys[:-1]:
            entry = entry[k]
        del entry[keys[-1]]
    return edit


HAND_EDITS = {  # case: (edit of the joint's entry, what the one line must name)
    "negative F_c": (_set("params", "F_c", value=-0.5), "params.F_c = -0.5 N·m < 0"),
    "negative F_v": (_set("params", "F_v", value=-0.1), "params.F_v = -0.1 N·m·s/rad < 0"),
    "terms' negative F_c": (_set("terms", "params", "F_c", value=-0.5), "terms.params.F_c = -0.5 N·m < 0"),
    "F_c not finite": (_set("params", "F_c", value=float("nan")), "params.F_c is nan"),
    "T_ref null": (_set("terms", "reference_temperature", value=None), "terms.reference_temperature is null"),
    "q_range reversed": (_set("terms", "q_range", value=[2.5, 0.5]), "terms.q_range is [2.5, 0.5]: reversed"),
    "terms.model changed": (_set("terms", "model", value="stribeck"),
                            "terms.model is 'stribeck', the joint's model 'coulomb-viscous'"),
    "rate_T 1e3": (_set("terms", "coefficients", "rate_T", value=1e3), "terms.coefficients.rate_T is 1000 /°C"),
    "rate_T beyond the fit's search": (_set("terms", "coefficients", "rate_T", value=0.5),
                                       "terms.coefficients.rate_T is 0.5 /°C: beyond the ±0.2 /°C"),
    "coefficient removed": (_drop("terms", "coefficients", "F_L"), "terms.coefficients has no 'F_L'"),
    "harmonics raised": (_set("terms", "harmonics", value=3), "terms.coefficients has no 'ripple_sin3'"),
    "harmonics lowered": (_set("terms", "harmonics", value=1), "terms.coefficients.ripple_sin2 is not a coefficient"),
    "ranges reversed": (_set("terms", "ranges", "temperature", value=[55.0, 25.0]),
                        "ranges.temperature is [55, 25]: reversed"),
}


@pytest.fixture()
def good(tmp_path):
    return params_file(tmp_path / "params.json", term_fit())


@pytest.mark.parametrize("case", HAND_EDITS)
def test_a_hand_edited_file_is_refused_naming_the_file_the_joint_and_the_key(good, case):
    edit, needle = HAND_EDITS[case]
    bad = edited(good, edit)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # rate_T 1e3 printed RuntimeWarnings: none now
        with pytest.raises(InputError) as err:
            read_params(bad)
    assert str(err.value).startswith(f"{bad}: joint '{JOINT}': "), err.value
    assert needle in str(err.value), err.value


def test_what_fit_writes_reads_back_with_its_ranges(good):
    fit = read_params(good)[JOINT]
    assert fit.terms == term_fit() and fit.terms.ranges == RANGES
    assert json.loads(good.read_text())["joints"][JOINT]["terms"]["ranges"] == {
        "angle": [0.5, 2.5], "load": [0.0, 30.0], "temperature": [25.0, 55.0]}


def test_a_file_of_an_earlier_version_reads_without_ranges(good):
    fit = read_params(edited(good, _drop("terms", "ranges")))[JOINT]
    assert fit.terms is not None and fit.terms.ranges is None and fit.terms.kept == ("load", "ripple", "temperature")


@pytest.mark.parametrize("command", ["predict", "export", "report"])
@pytest.mark.parametrize("case", ["negative F_c", "T_ref null", "coefficient removed", "harmonics raised"])
def test_every_command_refuses_it_in_one_line_before_any_work(good, tmp_path, capsys, command, case):
    """The same rule for the three readers: exit 2, one line naming the file, the joint and the key, nothing written
    (before: predict gave a plausible number or a KeyError traceback, export refused F_c < 0 without naming the file,
    report drew the curve)."""
    edit, needle = HAND_EDITS[case]
    bad = edited(good, edit)
    table = table_file(tmp_path / "friction.parquet", np.linspace(25.0, 55.0, 400))
    out = {"predict": None, "export": tmp_path / "out.urdf", "report": tmp_path / "out.html"}[command]
    args = {"predict": (table, "--params", bad), "export": (bad, "--robot", "panda", "-o", out),
            "report": (table, "--params", bad, "-o", out, "--workers", "1")}[command]
    code, err = run_cli(capsys, command, *args)
    lines = said(err)
    assert code == 2 and len(lines) == 1, err
    assert f"{bad}: joint '{JOINT}': " in lines[0] and needle in lines[0], err
    assert out is None or not out.exists()


def _numbers(doc, key=()):
    """The key paths of every number in a JSON document (not the booleans)."""
    if isinstance(doc, dict):
        return [p for k, v in doc.items() for p in _numbers(v, (*key, k))]
    if isinstance(doc, list):
        return [p for i, v in enumerate(doc) for p in _numbers(v, (*key, i))]
    return [key] if isinstance(doc, (int, float)) and not isinstance(doc, bool) else []


@pytest.fixture(scope="module")
def rich(tmp_path_factory):
    """A parameters file as ``fit`` writes it, with terms, standard errors, ranges and a covariance."""
    path = params_file(tmp_path_factory.mktemp("rich") / "params.json", term_fit())
    doc = json.loads(path.read_text())
    doc["joints"][JOINT]["covariance"] = np.diag([4e-6, 1e-4, 1e-6]).tolist()
    path.write_text(json.dumps(doc))
    read_params(path)  # it reads back
    return path, _numbers(doc["joints"][JOINT])


@settings(max_examples=40, deadline=None)
@given(data=st.data(), value=st.sampled_from([float("nan"), float("inf"), float("-inf"), "NaN", "nan", "-inf"]))
def test_a_value_that_is_not_finite_is_refused_whatever_its_key(rich, tmp_path_factory, data, value):
    """Round 5 (class 8): a parameters file whose ``speed`` is NaN read back ``ok`` (the verdict compares the speed
    with its floor: NaN compares false); only the model's parameters were held finite. Every number of a joint's
    entry, as ``NaN``, an infinity or a string spelling one, is refused in one line naming the file, the joint and
    the key (``fit`` writes ``null`` where a value is not finite)."""
    good, paths = rich
    key = data.draw(st.sampled_from(paths))
    path = tmp_path_factory.mktemp("nan") / "params.json"
    doc = json.loads(good.read_text())
    entry = doc["joints"][JOINT]
    for k in key[:-1]:
        entry = entry[k]
    entry[key[-1]] = value
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError) as err:
        read_params(path)
    shown = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in key)[1:]
    assert str(err.value).startswith(f"{path}: joint '{JOINT}': {shown} is "), (key, err.value)
    assert "\n" not in str(err.value)


def test_a_nan_speed_is_not_read_back_ok(good):
    """The case of round 5: ``speed`` NaN (what Python's json writes for a float NaN)."""
    bad = edited(good, _set("speed", value=float("nan")))
    with pytest.raises(InputError, match=f"joint '{JOINT}': speed is nan: not a finite number"):
        read_params(bad)
