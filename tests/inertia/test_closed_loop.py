"""The thesis's proposed loop (ch. 8) on a simulated walk seen through a wrong model:
identify the inertia model, re-estimate the friction with it; and ``wbfriction identify``,
its corrected URDF and JSON, and the report's section; the loop on a simulated arm's motor
currents, its rotor inertia identified."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

from helpers import assert_stages, run_cli, run_cli_printed, said, widest_line
from wbfriction.fit.result import FitResult
from wbfriction.friction.models import CoulombViscousParams, FrictionParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.closed_loop import stribeck_velocity
from wbfriction.inertia.consistency import is_consistent
from wbfriction.inertia.io import read_identification
from wbfriction.inertia.options import InertialOptions
from wbfriction.inertia.regressor import body_parameters
from wbfriction.inertia.sensitivity import scaled_robot
from wbfriction.inertia.urdf import write_urdf
from wbfriction.logs.log import write_log
from wbfriction.model.loading import load_robot
from wbfriction.pipeline.identify_step import identify_file
from wbfriction.signals.options import FilterOptions
from wbfriction.studies.common import leg_joints


@pytest.fixture(scope="module")
def wrong(talos):
    """TALOS with every body's principal moments x1.1 and mass x1.05 (thesis Fig. 7.5/7.6)."""
    return scaled_robot(scaled_robot(talos, 1.1, "rotational"), 1.05, "mass")


def _fit(joint, v_s, se_v_s, F_c=1.0, se=0.01) -> FitResult:
    return FitResult(joint, 100, FrictionParams(F_v=0.2, F_c=F_c, S=0.2, v_s=v_s, tau_os=0.0, a=40.0),
                     {"F_v": se, "F_c": se, "S": se, "v_s": se_v_s, "tau_os": se, "a": np.inf}, success=True)


def test_stribeck_velocity_is_the_median_of_the_determined_joints():
    fits = [_fit("a", 0.1, 0.01), _fit("b", 0.2, 0.01), _fit("c", 0.4, 0.01),
            _fit("d", 5.0, np.inf), _fit("e", 0.3, 0.01, F_c=1e-6, se=1.0), FitResult("f", 3),
            FitResult("g", 100, CoulombViscousParams(F_v=0.2, F_c=1.0, tau_os=0.0),
                      {"F_v": 0.01, "F_c": 0.01, "tau_os": 0.01}, success=True, model="coulomb-viscous")]
    assert stribeck_velocity(fits) == (0.2, ("a", "b", "c"))
    assert stribeck_velocity(fits[3:]) == (None, ())


@pytest.mark.slow
def test_identify_command_closes_the_loop(talos, wrong, combined_walk, tmp_path, capsys, monkeypatch):
    """``identify`` on the combined walk seen through the wrong model (one pass, the Stribeck
    velocity given): the leg joints' friction moves back toward the truth (F_c and tau_os
    within 5 %) and no joint's friction generates power; the held-out torques are predicted
    far better; the URDF reloads as
    the identified model, ``estimate --urdf`` runs on it, the report shows the RMS table. In a 100-column
    terminal no printed line is wider (issue 39)."""
    log = tmp_path / "walk.parquet"
    write_log(combined_walk.log, talos, log)
    given = tmp_path / "given.urdf"
    write_urdf(talos, body_parameters(wrong.model), given)
    monkeypatch.setenv("COLUMNS", "100")  # what the command's console reads as the terminal's width
    code, printed, err = run_cli_printed(capsys, "identify", log, "--urdf", given, "-o", tmp_path / "id.urdf",
                                         "--json", tmp_path / "id.json", "--stribeck-velocity", "0.2")
    assert code == 0, err
    assert_stages(err, "estimating with the given model", "fit", "the identification's samples",
                  "identifying the inertia model (pass 1", "estimating with the identified model (pass 1)", "fit")
    assert widest_line(printed) <= 100 and "Held-out torques" in printed, printed
    doc = json.loads((tmp_path / "id.json").read_text())
    legs = [j for j, _, _ in leg_joints(talos)]
    before = {n: max(doc["joints"][j]["acceleration_route_given_model"]["error_percent"][n] for j in legs)
              for n in ("F_v", "F_c", "tau_os")}
    after = {n: max(doc["joints"][j]["acceleration_route"]["error_percent"][n] for j in legs)
             for n in ("F_v", "F_c", "tau_os")}
    with capsys.disabled():
        print("\nleg joints' worst errors [%], given model", before, "identified", after)
    assert all(after[n] < 0.5 * before[n] for n in after), (before, after)
    assert after["F_c"] < 5.0 and after["tau_os"] < 5.0, after  # F_v: the hip yaws turn in 3 steps only
    assert max(doc["joints"][j]["generating_share_given_model"] for j in legs) > 0.05
    # no joint's friction generates power any more, the frictionless upper body's included
    assert max(j["generating_share"] for j in doc["joints"].values()) < 0.01
    rms = np.array([[doc["joints"][j]["holdout_rms"][k] for k in ("given", "identified")] for j in legs])
    assert np.all(rms[:, 1] < 0.1 * rms[:, 0])

    ident = load_robot("talos", urdf=tmp_path / "id.urdf")
    masses = body_parameters(ident.model)[:, 0]
    assert np.allclose(masses, [b["mass"] for b in doc["bodies"]], rtol=1e-12)
    assert is_consistent(body_parameters(ident.model)).all()
    assert abs(masses.sum() - body_parameters(talos.model)[:, 0].sum()) < 0.01 * masses.sum()
    code, err = run_cli(capsys, "estimate", log, "--urdf", tmp_path / "id.urdf", "-o", tmp_path / "f.parquet")
    assert code == 0, err
    code, err = run_cli(capsys, "report", tmp_path / "f.parquet", "--identification", tmp_path / "id.json",
                        "-o", tmp_path / "r.html")
    assert code == 0, err
    html = (tmp_path / "r.html").read_text()
    assert 'id="holdout-rms"' in html and 'id="inertia-changes"' in html
    assert f"{doc['joints']['leg_left_4_joint']['holdout_rms']['identified']:.4f}" in html


@pytest.mark.parametrize("args, message", [
    (["--stribeck-velocity", "fast"], "--stribeck-velocity must be auto, none or a number"),
    (["--holdout", "1.5"], "--holdout must be between 0 and 1"),
    (["--link-margin", "1"], "--link-margin must be at least 0 and below 1"),
    (["--link-margin", "-0.1"], "--link-margin must be at least 0 and below 1"),
])
def test_identify_bad_options(tmp_path, capsys, args, message):
    (tmp_path / "log.parquet").write_bytes(b"")
    code, err = run_cli(capsys, "identify", tmp_path / "log.parquet", "-o", tmp_path / "id.urdf", *args)
    assert code == 2 and message in err and len(said(err)) == 1
    assert not (tmp_path / "id.urdf").exists()


def test_report_refuses_a_malformed_identification(tmp_path, capsys):
    bad = tmp_path / "id.json"
    bad.write_text(json.dumps({"joints": {"leg_left_1_joint": {"holdout_rms": {"given": 1.0}}}}))
    (tmp_path / "f.parquet").write_bytes(b"")
    code, err = run_cli(capsys, "report", tmp_path / "f.parquet", "--identification", bad, "-o", tmp_path / "r.html")
    assert code == 2 and len(said(err)) == 1 and not (tmp_path / "r.html").exists()
    assert "id.json" in err and "holdout_rms" in err


def test_identify_an_arm_with_its_rotor_inertia(panda, panda_friction, panda_log, tmp_path):
    """The simulated Panda's motor currents (19-bit encoders at 1 kHz, filtered at 20 Hz) through a wrong
    model without armature (principal moments x1.1, masses x1.05), the armature identified, end to end
    (files in, files out): F_v, F_c and the armature of every joint within 5 % of the injected ones,
    and the acceleration route with the identified model (its armature included) within 5 % too; the
    JSON names the armature and what the data did not determine."""
    log = tmp_path / "arm.parquet"
    write_log(panda_log, panda, log)
    wrong = scaled_robot(scaled_robot(panda, 1.1, "rotational"), 1.05, "mass")
    wrong.model.armature = np.zeros(wrong.model.nv)
    v_s = panda_friction["panda_joint1"].v_s
    done = identify_file(wrong, log, tmp_path / "arm.urdf", tmp_path / "arm.json",
                         estimate_options=EstimateOptions(diff="butterworth", filtering=FilterOptions(cutoff=20.0)),
                         options=InertialOptions(armature="identify", prior=100.0), stribeck=v_s, passes=1)
    doc = read_identification(tmp_path / "arm.json")
    assert doc == done.identification
    assert doc.armature_mode == "identify" and doc.passes[0].not_excited
    truth = dict(zip(panda.actuated, panda.model.armature[panda.act_v_index]))
    for joint, j in doc.joints.items():
        true = panda_friction[joint]
        assert j.acceleration_route.params is not None
        for name in ("F_v", "F_c"):
            assert abs(j.identified[name] / getattr(true, name) - 1) < 0.05, (joint, name, j.identified)
            assert abs(getattr(j.acceleration_route.params, name) / getattr(true, name) - 1) < 0.05, (joint, name)
        assert j.armature_given == 0.0 and j.armature is not None
        assert abs(j.armature / truth[joint] - 1) < 0.05, (joint, j.armature)
    assert is_consistent(done.loop.final.identification.pi).all()
    toml = tomllib.loads(done.armature_toml() or "")
    assert toml["armature"] == pytest.approx({j: doc.joints[j].armature for j in doc.joints})
