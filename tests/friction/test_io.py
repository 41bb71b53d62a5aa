"""The friction table and the parameters JSON: what is written reads back the same (one writer, one reader)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from wbfriction.exceptions import InputError
from wbfriction.fit.params_file import fit_from_dict, fit_to_dict, read_params, write_params
from wbfriction.fit.result import FitResult, HeldOutScore, ModelSelection
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.io import friction_table, read_friction_file
from wbfriction.friction.models import CoulombViscousParams, FrictionParams, StribeckParams
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.tables import write_table
from wbfriction.signals.filters import SavgolSmoother
from wbfriction.signals.options import FilterOptions


@pytest.mark.parametrize("suffix", [".parquet", ".h5"])
def test_friction_table_reads_back_as_the_estimate(talos, combined_walk, tmp_path, suffix):
    options = EstimateOptions(diff="savgol", filtering=FilterOptions(window=51))
    est = estimate_log(talos, combined_walk.log.rows(0, 3000), options, companion=True)
    write_table(friction_table(est), tmp_path / f"f{suffix}")
    back = read_friction_file(tmp_path / f"f{suffix}")
    # HDF5 keeps its datasets in name order: joints and frames are matched by name, not by position
    assert sorted(back.joints) == sorted(est.joints) and sorted(back.contact_frames) == sorted(est.contact_frames)
    j = [back.joints.index(n) for n in est.joints]
    c = [back.contact_frames.index(n) for n in est.contact_frames]
    np.testing.assert_array_equal(back.time, est.time)
    np.testing.assert_array_equal(back.unique, est.unique)
    np.testing.assert_array_equal(back.contact[:, c], est.contact)
    for name in ("qd", "tau_f", "valid", "qdd", "delta_qdd", "companion_delta_qdd"):
        np.testing.assert_array_equal(getattr(back, name)[:, j], getattr(est, name), err_msg=name)
    if suffix == ".parquet":  # the HDF5 reader keeps numeric datasets only: the phase text does not come back
        assert list(back.phase) == list(est.phase)
    assert back.companion_diff == "central"
    assert isinstance(back.smoother, SavgolSmoother) and back.smoother.window == 51  # the fit filters its model alike


def test_parameters_read_back_with_unidentifiable_ones_infinite(tmp_path):
    fit = FitResult("knee", 120, params=FrictionParams(0.2, 1.0, 0.2, 0.2, 1.0, 40.0),
                    stderr={"F_v": 0.01, "F_c": 0.02, "S": np.inf, "v_s": np.inf, "tau_os": 0.0, "a": 3.0},
                    rms_residual=0.05, success=True, message="ok", target=FrictionParams(0.2, 1.0, 0.2, 0.2, 1.0, 40.0))
    write_params(tmp_path / "p.json", [fit], {"provenance": {"x": 1}}, {"knee": {"group": "knee"}})
    doc = json.loads((tmp_path / "p.json").read_text())
    assert list(doc) == ["provenance", "joints"] and doc["joints"]["knee"]["stderr"]["S"] is None
    assert doc["joints"]["knee"]["group"] == "knee" and doc["joints"]["knee"]["error_percent"]["F_v"] == 0.0
    back = read_params(tmp_path / "p.json")["knee"]
    assert back.params == fit.params and back.target == fit.target and back.stderr == fit.stderr
    assert fit_to_dict(back) == fit_to_dict(fit)


def test_malformed_parameters_name_the_file_and_the_joint(tmp_path):
    with pytest.raises(InputError, match="unknown friction parameter"):
        fit_from_dict("knee", {"params": {"F_x": 1.0}})
    (tmp_path / "p.json").write_text(json.dumps({"joints": {"knee": {"params": {"F_v": "fast"}}}}))
    with pytest.raises(InputError, match=r"p.json: joint 'knee'"):
        read_params(tmp_path / "p.json")
    (tmp_path / "q.json").write_text("[1, 2]")
    with pytest.raises(InputError, match="no 'joints' object"):
        read_params(tmp_path / "q.json")
    with pytest.raises(InputError, match="file not found"):
        read_params(tmp_path / "missing.json")


def test_each_model_with_its_bounds_and_choice_reads_back(tmp_path):
    """The model's name, its parameters, the at-bound flags and the model choice are written and read back."""
    selection = ModelSelection("stribeck", "stribeck: the reason", (
        HeldOutScore("coulomb-viscous", 0.31), HeldOutScore("stribeck", 0.2, ("F_c",)), HeldOutScore("thesis", 0.199)),
        0.02, 700, 300)
    fits = [FitResult("knee", 1000, params=StribeckParams(0.2, 0.0, 1.2, 0.15, 0.3),
                      stderr={"F_v": 0.01, "F_c": 0.02, "F_s": 0.03, "v_s": np.inf, "tau_os": 0.0},
                      at_bound={"F_v": False, "F_c": True, "F_s": False, "v_s": False, "tau_os": False},
                      selection=selection, target=FrictionParams(0.2, 1.0, 0.2, 0.2, 0.3, 40.0)),
            FitResult("hip", 900, params=CoulombViscousParams(0.5, 0.6, -0.1), at_bound={"F_v": True}),
            FitResult("ankle", 3, model="coulomb-viscous", message="only 3 valid samples")]
    write_params(tmp_path / "p.json", fits, {"model": "auto"})
    doc = json.loads((tmp_path / "p.json").read_text())
    knee = doc["joints"]["knee"]
    assert knee["model"] == "stribeck" and knee["at_bound"]["F_c"] is True and knee["params"]["F_s"] == 1.2
    assert knee["selection"]["chosen"] == "stribeck" and knee["selection"]["scores"][1]["at_bound"] == ["F_c"]
    assert knee["error_percent"]["F_s"] == pytest.approx(0.0)  # (1 + S) F_c of the target
    back = read_params(tmp_path / "p.json")
    for fit in fits:
        b = back[fit.joint]
        assert b.model == fit.model and b.params == fit.params and b.at_bound == fit.at_bound
        assert b.selection == fit.selection and fit_to_dict(b) == fit_to_dict(fit)
    assert back["knee"].bounded() == ("F_c",) and isinstance(back["hip"].params, CoulombViscousParams)


def test_parameter_files_of_the_previous_version_read_as_model_3_5(tmp_path):
    """A file written before the model choice (no 'model', no 'at_bound') holds (3.5)."""
    old = {"sign_convention": "tau_f = -f(qd); fit of f (eq. 3.5) to -tau_f", "joints": {"knee": {
        "n_samples": 120, "success": True, "message": "ok", "rms_residual": 0.05,
        "params": {"F_v": 0.2, "F_c": 1.0, "S": 0.2, "v_s": 0.2, "tau_os": 1.0, "a": 40.0, "delta_s": 2.0},
        "stderr": {"F_v": 0.01, "F_c": 0.02, "S": None, "v_s": None, "tau_os": 0.0, "a": 3.0}}}}
    (tmp_path / "old.json").write_text(json.dumps(old))
    knee = read_params(tmp_path / "old.json")["knee"]
    assert knee.model == "thesis" and knee.params == FrictionParams(0.2, 1.0, 0.2, 0.2, 1.0, 40.0)
    assert knee.at_bound == {} and knee.selection is None and knee.stderr["S"] == np.inf


def test_malformed_model_entries_name_the_file_and_the_joint(tmp_path):
    for entry, needle in (({"model": "lugre", "params": {"F_c": 1.0}}, "model must be one of"),
                          ({"model": "coulomb-viscous", "params": {"F_c": 1.0, "S": 0.2}}, "unknown friction param"),
                          ({"model": "coulomb-viscous", "params": {"F_c": 1.0, "F_v": 0.1, "tau_os": 0.0},
                            "at_bound": {"S": True}}, "at_bound"),
                          ({"model": "coulomb-viscous", "params": {"F_c": 1.0, "tau_os": 0.0}},
                           "params.F_v is missing: 'fit' writes every parameter of the coulomb-viscous model"),
                          ({"params": {"F_c": 1.0, "F_v": 0.1, "S": 0.0, "v_s": 0.1, "tau_os": 0.0, "a": 40.0,
                                       "delta_s": 2.0}, "selection": {"chosen": "thesis"}}, "selection: missing key"),
                          ({"selection": {"chosen": "x", "tolerance": 0.1}}, "selection.chosen")):
        (tmp_path / "p.json").write_text(json.dumps({"joints": {"knee": entry}}))
        with pytest.raises(InputError, match=rf"p.json: joint 'knee': .*{needle}"):
            read_params(tmp_path / "p.json")
