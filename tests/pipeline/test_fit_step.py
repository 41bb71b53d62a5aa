"""``fit_file``: a friction table in, the parameters JSON out, with the model chosen per joint
(``auto``, the default) or named."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pytest

from wbfriction.exceptions import InputError
from wbfriction.fit.options import FitOptions
from wbfriction.fit.params_file import read_params
from wbfriction.fit.selection import fit_friction
from wbfriction.fit.solve import STICK_FLOOR
from wbfriction.friction.models import CoulombViscousParams, StribeckParams
from wbfriction.logs.tables import write_table
from wbfriction.pipeline.fit_step import fit_file

TRUTHS = {"hip": CoulombViscousParams(F_v=0.3, F_c=0.8, tau_os=0.2),
          "knee": StribeckParams(F_v=0.4, F_c=0.0, F_s=1.0, v_s=0.15, tau_os=0.3)}
"""The knee's static friction decays to no Coulomb level: (3.5) writes it only with S at its bound."""


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    """A friction table of two joints made by known models, with noise, and one joint with 5 valid samples."""
    rng = np.random.default_rng(0)
    t = np.arange(3000) * 2e-3
    qd = 1.2 * np.sin(2 * np.pi * 0.31 * t) + 0.4 * np.sin(2 * np.pi * 1.7 * t + 0.5)
    cols: dict[str, np.ndarray] = {"time": t}
    for joint, truth in TRUTHS.items():
        cols |= {f"qd.{joint}": qd, f"tau_f.{joint}": truth.torque(qd) + rng.normal(0, 0.03, qd.size),
                 f"valid.{joint}": np.ones(qd.size, dtype=bool)}
    cols |= {"qd.ankle": qd, "tau_f.ankle": -qd, "valid.ankle": np.arange(qd.size) < 5}
    path = tmp_path_factory.mktemp("fit") / "friction.parquet"
    write_table(pa.table(cols), path)
    return path, qd, cols


def test_auto_is_the_default_and_records_its_choice(table, tmp_path):
    path, _, _ = table
    fitted = fit_file(path, tmp_path / "p.json")
    doc = json.loads((tmp_path / "p.json").read_text())
    assert doc["model"] == "auto" and doc["selection_tolerance"] == 0.02
    joints = doc["joints"]
    for joint, truth in TRUTHS.items():
        entry = joints[joint]
        assert entry["model"] == truth.model and entry["selection"]["chosen"] == truth.model
        assert entry["selection"]["reason"].startswith(f"{truth.model}:") and "energy" in entry
        assert [s["model"] for s in entry["selection"]["scores"]] == ["coulomb-viscous", "stribeck", "thesis"]
        for name in ("F_v", "tau_os"):
            assert abs(entry["params"][name] - getattr(truth, name)) < 0.05, (joint, name)
    assert joints["ankle"]["params"] is None
    back = read_params(tmp_path / "p.json")
    for fit in fitted.fits:
        assert back[fit.joint].params == fit.params and back[fit.joint].at_bound == fit.at_bound


def test_named_thesis_model_reports_its_bounds_as_the_library_fit_does(table, tmp_path):
    path, qd, cols = table
    fit_file(path, tmp_path / "p.json", FitOptions(model="thesis"))
    doc = json.loads((tmp_path / "p.json").read_text())
    knee = doc["joints"]["knee"]
    assert doc["model"] == "thesis" and "selection_tolerance" not in doc and "selection" not in knee
    assert knee["model"] == "thesis" and knee["at_bound"]["S"] and knee["params"]["S"] == pytest.approx(50.0)
    direct = fit_friction(qd, cols["tau_f.knee"], model="thesis", stick=STICK_FLOOR, stick_margin=1)
    assert knee["params"] == direct.params.to_dict() and knee["at_bound"] == direct.at_bound


def test_bad_model_options_are_one_line_errors_and_write_nothing(table, tmp_path):
    path, _, _ = table
    with pytest.raises(InputError, match="--model must be one of auto, coulomb-viscous, stribeck, thesis"):
        fit_file(path, tmp_path / "p.json", FitOptions(model="lugre"))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="--selection-tolerance"):
        fit_file(path, tmp_path / "p.json", FitOptions(selection_tolerance=-0.1))
    assert not (tmp_path / "p.json").exists()
