"""The thesis's proposed loop (ch. 8) on a simulated walk seen through a wrong model:
identify the inertia model, re-estimate the friction with it; and ``wbfriction identify``,
its corrected URDF and JSON, and the report's section."""

from __future__ import annotations

import json

import numpy as np
import pytest

from test_cli_bad_input import run_cli
from wbfriction.closed_loop import identify_and_estimate, loop_document, stribeck_velocity
from wbfriction.friction import FrictionParams
from wbfriction.identify import FitResult
from wbfriction.inertial import body_parameters, is_consistent
from wbfriction.log import write_log
from wbfriction.robot import load_robot
from wbfriction.sensitivity import scaled_robot
from wbfriction.study import _leg_joints
from wbfriction.urdf import write_urdf


@pytest.fixture(scope="module")
def wrong(talos):
    """TALOS with every body's principal moments x1.1 and mass x1.05 (thesis Fig. 7.5/7.6)."""
    return scaled_robot(scaled_robot(talos, 1.1, "rotational"), 1.05, "mass")


@pytest.fixture(scope="module")
def loop(wrong, combined_walk):
    return identify_and_estimate(wrong, combined_walk.log)


def _worst(route, legs, name):
    return max(route.fit(j).error_percent()[name] for j in legs)


def test_loop_brings_the_leg_friction_back(talos, loop):
    """Before: the wrong model shifts and splits the friction (errors of tens of %, power
    generated); after two passes: the leg joints' F_c and tau_os within 5 % of the truth,
    F_v within 10 % (3-step walk; the 10-step figures are in the README), and under 1 %
    of their samples generating power."""
    legs = [j for j, _, _ in _leg_joints(talos)]
    given, final = loop.given, loop.final.route
    assert _worst(given, legs, "F_v") > 30 and _worst(given, legs, "tau_os") > 30
    assert max(e.generating_share for e in given.energy if e.joint in legs) > 0.05
    assert _worst(final, legs, "F_c") < 5 and _worst(final, legs, "tau_os") < 5
    assert _worst(final, legs, "F_v") < 10
    assert max(e.generating_share for e in final.energy if e.joint in legs) < 0.01
    assert len(loop.passes) == 2 and abs(loop.passes[-1].stribeck_velocity - 0.2) < 0.02


def test_loop_identification_is_physical_and_predicts_held_out_torques(talos, loop):
    ident = loop.final.identification
    true = body_parameters(talos.model)
    assert is_consistent(ident.pi).all()
    assert abs(ident.pi[:, 0].sum() - true[:, 0].sum()) < 0.01 * true[:, 0].sum()
    legs = np.isin(talos.torque_controlled, [j for j, _, _ in _leg_joints(talos)])
    h = ident.holdout
    assert np.all(h.identified[legs] < 0.1 * h.given[legs])
    assert np.median(h.identified) < np.median(h.given_with_friction)
    doc = json.loads(json.dumps(loop_document(loop)))  # JSON-ready
    assert set(doc["joints"]) == set(talos.torque_controlled)
    assert doc["passes"][-1]["prior"] == ident.prior


def _fit(joint, v_s, se_v_s, F_c=1.0, se=0.01) -> FitResult:
    return FitResult(joint, 100, FrictionParams(F_v=0.2, F_c=F_c, S=0.2, v_s=v_s, tau_os=0.0, a=40.0),
                     {"F_v": se, "F_c": se, "S": se, "v_s": se_v_s, "tau_os": se, "a": np.inf}, success=True)


def test_stribeck_velocity_is_the_median_of_the_determined_joints():
    fits = [_fit("a", 0.1, 0.01), _fit("b", 0.2, 0.01), _fit("c", 0.4, 0.01),
            _fit("d", 5.0, np.inf), _fit("e", 0.3, 0.01, F_c=1e-6, se=1.0), FitResult("f", 3)]
    assert stribeck_velocity(fits) == (0.2, ("a", "b", "c"))
    assert stribeck_velocity(fits[3:]) == (None, ())


def test_identify_command_writes_urdf_json_and_closes_the_loop(talos, wrong, combined_walk, tmp_path, capsys):
    """``identify`` on the first 8 s of the walk: the URDF reloads as the identified model,
    ``estimate --urdf`` runs on it, the report shows the held-out RMS table."""
    log = tmp_path / "walk.parquet"
    write_log(combined_walk.log.rows(0, 8000), talos, log)
    given = tmp_path / "given.urdf"
    write_urdf(talos, body_parameters(wrong.model), given)
    code, err = run_cli(capsys, "identify", log, "--urdf", given, "-o", tmp_path / "id.urdf",
                        "--json", tmp_path / "id.json", "--passes", "1", "--stride", "10")
    assert code == 0, err
    doc = json.loads((tmp_path / "id.json").read_text())
    ident = load_robot("talos", urdf=tmp_path / "id.urdf")
    masses = body_parameters(ident.model)[:, 0]
    assert np.allclose(masses, [b["mass"] for b in doc["bodies"]], rtol=1e-12)
    assert abs(masses.sum() - body_parameters(talos.model)[:, 0].sum()) < 0.01 * masses.sum()
    code, err = run_cli(capsys, "estimate", log, "--urdf", tmp_path / "id.urdf", "-o", tmp_path / "f.parquet")
    assert code == 0, err
    code, err = run_cli(capsys, "report", tmp_path / "f.parquet", "--identification", tmp_path / "id.json",
                        "-o", tmp_path / "r.html")
    assert code == 0, err
    html = (tmp_path / "r.html").read_text()
    assert 'id="holdout-rms"' in html and 'id="inertia-changes"' in html
    rms = doc["joints"]["leg_left_4_joint"]["holdout_rms"]
    assert f"{rms['identified']:.4f}" in html and rms["identified"] < rms["given"]


@pytest.mark.parametrize("args, message", [
    (["--stribeck-velocity", "fast"], "--stribeck-velocity must be auto, none or a number"),
    (["--holdout", "1.5"], "--holdout must be between 0 and 1"),
])
def test_identify_bad_options(tmp_path, capsys, args, message):
    (tmp_path / "log.parquet").write_bytes(b"")
    code, err = run_cli(capsys, "identify", tmp_path / "log.parquet", "-o", tmp_path / "id.urdf", *args)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "id.urdf").exists()


def test_report_refuses_a_malformed_identification(tmp_path, capsys):
    bad = tmp_path / "id.json"
    bad.write_text(json.dumps({"joints": {"leg_left_1_joint": {"holdout_rms": {"given": 1.0}}}}))
    (tmp_path / "f.parquet").write_bytes(b"")
    code, err = run_cli(capsys, "report", tmp_path / "f.parquet", "--identification", bad, "-o", tmp_path / "r.html")
    assert code == 2 and len(err.strip().splitlines()) == 1 and not (tmp_path / "r.html").exists()
    assert "id.json" in err and "holdout_rms" in err
