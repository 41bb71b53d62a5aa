"""Which fit an export writes where the model ``--model auto`` chose is not ``ok`` (issue 64, item 1;
:func:`~wbfriction.export.mapping.exported_fit`): the simplest family's fit beside it when that is ``ok``, or when
neither is and both are included; the chosen one when only its status is included; the file's note and the
terminal say which replaced which."""

from __future__ import annotations

import dataclasses

import pytest

from helpers import run_cli_printed
from wbfriction.exceptions import InputError
from wbfriction.export.mapping import exported_fit, select_fits
from wbfriction.fit.params_file import write_params
from wbfriction.friction.models import CoulombViscousParams
from wbfriction.model import load_robot
from wbfriction.pipeline.export_step import export_files


def simple_of(fit_of, joint: str, status: str, F_v: float = 0.3, F_c: float = 0.6):
    """A Coulomb-viscous fit of ``status`` (the fit_of fixture's rules)."""
    fit = fit_of(joint, status, F_v=F_v, F_c=F_c)
    params = CoulombViscousParams(F_v=F_v, F_c=F_c, tau_os=0.02)
    fit = dataclasses.replace(fit, params=params, stderr={"F_v": fit.stderr["F_v"], "F_c": 0.05 * F_c,
                                                          "tau_os": 0.001},
                              at_bound={n: False for n in params.names})
    if status == "at bound":
        fit.pressed = {"F_v": (-0.2, 0.03)}
        fit.at_bound["F_v"] = True
    assert fit.verdict().status == status, fit.verdict()
    return fit


@pytest.mark.parametrize("chosen, simple, include, want", [
    ("ok", "ok", (), "chosen"),
    ("at bound", "ok", (), "simple"),  # the simplest family's ok fit, though nothing is included
    ("at bound", "weak", ("weak",), "simple"),
    ("weak", "at bound", ("weak", "at bound"), "simple"),  # neither ok, both included: the fewer parameters
    ("weak", "at bound", ("weak",), "chosen"),
    ("weak", "at bound", (), None),
    ("failed", "weak", ("weak",), "simple"),
    ("weak", "failed", ("weak",), "chosen"),  # a failed fit is never exported
])
def test_the_fit_exported(fit_of, chosen, simple, include, want):
    fit = fit_of("panda_joint1", chosen)
    fit.fallback = simple_of(fit_of, "panda_joint1", simple) if simple != "failed" else fit_of("panda_joint1", simple)
    got = exported_fit(fit, {"ok", *include})
    assert got is {"chosen": fit, "simple": fit.fallback, None: None}[want]


def test_the_note_and_the_terminal_say_which(fit_of, tmp_path, capsys):
    robot = load_robot("panda")
    chosen = fit_of("panda_joint1", "at bound")
    chosen.fallback = simple_of(fit_of, "panda_joint1", "ok")
    params = tmp_path / "p.json"
    write_params(params, [chosen, fit_of("panda_joint2", "ok")], {"provenance": {"robot": "panda"}})
    selection = select_fits({"panda_joint1": chosen, "panda_joint2": fit_of("panda_joint2", "ok")}, robot)
    assert selection.exported["panda_joint1"] is chosen.fallback and list(selection.instead) == ["panda_joint1"]
    assert selection.instead_note("panda_joint1").startswith("in place of the thesis fit chosen (at bound")
    out = tmp_path / "a.xml"
    export_files(robot, params, [out])
    text = out.read_text()
    assert ("<!-- wbfriction fit of panda_joint1: ok; its coulomb-viscous fit in place of the thesis fit chosen "
            "(at bound") in text
    assert 'frictionloss="0.6"' in text  # the simplest family's F_c, not the chosen fit's 1.0
    code, _, err = run_cli_printed(capsys, "export", params, "--robot", "panda", "-o", tmp_path / "b.xml")
    assert code == 0 and "exported in place of the model chosen, not ok: panda_joint1 (thesis, at bound)" in err


def test_without_a_fit_ok_or_included_nothing_qualifies(fit_of, tmp_path):
    chosen = fit_of("panda_joint1", "weak")
    chosen.fallback = simple_of(fit_of, "panda_joint1", "at bound")
    with pytest.raises(InputError, match="no fit qualifies"):
        select_fits({"panda_joint1": chosen}, load_robot("panda"))
