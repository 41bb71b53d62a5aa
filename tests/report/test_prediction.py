"""``wbfriction predict --table --figure`` (issue 67, item 2): what the prediction writes, sample by sample.

A toy friction table of one joint whose friction is a known Coulomb-viscous law plus noise, recorded in two runs
ten minutes apart at Unix-epoch stamps, and the parameters of that law: the table written holds the time from the
log's first sample, the friction table's own estimate as the measured friction, the law evaluated at the samples as
the predicted one, and the residual whose RMS is what ``predict`` prints; its metadata gives every column's unit and
the two runs; the figure draws each run in its own panel; a bad output is refused before any work; a rerun writes
the same bytes.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pyarrow.parquet as pq
import pytest

from helpers import run_cli, run_cli_printed
from term_params import JOINT, VELOCITY, motion, motion_estimate, params_file
from wbfriction.friction.io import friction_table
from wbfriction.logs.tables import write_table
from wbfriction.pipeline.predict_step import predict_file
from wbfriction.pipeline.prediction_table import KIND, UNITS
from wbfriction.report.prediction import prediction_figure

N = 2000
EPOCH = 1.7e9
"""The toy's first stamp [s] (a Unix time, as the KUKA's receive-time stamps)."""
GAP = 600.0
"""The pause between its two runs [s]."""


def _stamps() -> np.ndarray:
    """The toy's stamps from their definition: 100 Hz from :data:`EPOCH`, the second half :data:`GAP` later."""
    t = EPOCH + 0.01 * np.arange(N)
    t[N // 2:] += GAP
    return t


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The toy's friction table and parameters, and ``predict`` run on them with both outputs."""
    folder = tmp_path_factory.mktemp("prediction")
    est = dataclasses.replace(motion_estimate(np.full(N, 40.0)), time=_stamps())
    friction = folder / "toy_friction.parquet"
    write_table(friction_table(est), friction)
    params = params_file(folder / "params.json")
    out = folder / "a"
    out.mkdir()
    return friction, params, out, _predict(friction, params, out)


def _predict(friction, params, out):
    import sys

    from wbfriction import cli

    argv = sys.argv
    sys.argv = ["wbfriction", "predict", str(friction), "--params", str(params), "--table",
                str(out / "prediction.parquet"), "--figure", str(out / "prediction.png")]
    try:
        cli.main()
    except SystemExit as exc:
        assert exc.code == 0
    finally:
        sys.argv = argv
    return pq.read_table(out / "prediction.parquet")


def test_the_table_holds_the_estimate_and_the_law_at_the_samples(written):
    friction, params, _, table = written
    source = pq.read_table(friction)
    col = lambda name: table.column(f"{name}.{JOINT}").to_numpy()  # noqa: E731
    np.testing.assert_allclose(table.column("time").to_numpy(), _stamps() - EPOCH, rtol=0, atol=1e-6)
    qd = motion(N)[1]
    np.testing.assert_allclose(col("qd"), qd, rtol=0, atol=1e-12)
    law = -(VELOCITY.F_c * np.sign(qd) + VELOCITY.F_v * qd)  # tau_f = -f(qd), f of its definition
    np.testing.assert_allclose(col("tau_f_pred"), law, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(col("tau_f"), source.column(f"tau_f.{JOINT}").to_numpy())
    np.testing.assert_array_equal(col("tau"), source.column(f"tau.{JOINT}").to_numpy())
    np.testing.assert_allclose(col("tau") - col("tau_pred"), col("residual"), rtol=0, atol=1e-9)
    np.testing.assert_allclose(col("residual"), law - col("tau_f"), rtol=0, atol=1e-12)
    valid = col("valid")
    assert valid.all()
    rms = float(np.sqrt(np.mean(col("residual")[valid] ** 2)))
    assert rms == pytest.approx(float(predict_file(friction, params).rms[0]), rel=1e-12)  # what predict prints
    meta = json.loads(table.schema.metadata[b"wbfriction"])
    assert meta["joints"][JOINT]["rms"] == pytest.approx(rms, rel=1e-12)
    assert meta["joints"][JOINT]["model"] == "coulomb-viscous" and meta["joints"][JOINT]["status"] == "ok"


def test_the_metadata_says_every_columns_unit_and_the_runs(written):
    _, _, _, table = written
    meta = json.loads(table.schema.metadata[b"wbfriction"])
    assert meta["kind"] == KIND and meta["units"] == UNITS
    for name in table.column_names:  # every column's unit, by its pattern
        pattern = name if name == "time" else name.rsplit(f".{JOINT}", 1)[0] + ".<j>"
        assert pattern in meta["units"] and pattern in meta["columns"], name
    assert meta["units"]["time"] == "s" and meta["units"]["residual.<j>"] == "N·m"
    assert meta["time_origin"] == EPOCH
    assert meta["runs"] == [[0, N // 2], [N // 2, N]]
    assert set(meta["sources"]) == {"friction", "params"} and meta["order"] == [JOINT]


def test_the_figure_draws_each_run_in_its_own_panel(written):
    _, _, out, table = written
    assert (out / "prediction.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    fig = prediction_figure(table)
    first, second = (ax for ax in fig.axes if ax.get_label().startswith("time"))  # the report's time panels
    assert sorted(ax.get_xlabel() for ax in fig.axes if ax not in (first, second)) == ["qd [rad/s]"]
    assert first.get_title(loc="left").endswith("run 1, from 0.0 s")
    assert second.get_title(loc="left") == f"run 2, from {(GAP + 10.0) / 60:.1f} min"
    for ax in (first, second):  # each run from its own start [s], not the epoch
        assert ax.get_xlim()[0] == 0.0 and 9.0 < ax.get_xlim()[1] < 10.5


def test_a_rerun_writes_the_same_bytes(written, tmp_path):
    friction, params, out, _ = written
    _predict(friction, params, tmp_path)
    for name in ("prediction.parquet", "prediction.png"):
        assert (tmp_path / name).read_bytes() == (out / name).read_bytes(), name


def test_a_bad_output_is_refused_before_any_work(written, tmp_path, capsys, monkeypatch):
    friction, params, _, _ = written

    def no_work(*args, **kwargs):
        raise AssertionError("the prediction ran")

    monkeypatch.setattr("wbfriction.report.prediction.predict_table", no_work)
    for option, path, said in (("--table", tmp_path / "missing" / "p.parquet", "does not exist"),
                               ("--figure", tmp_path / "p.svg", "a figure is written as .png, not '.svg'"),
                               ("--table", friction, "is the input")):
        code, err = run_cli(capsys, "predict", friction, "--params", params, option, path)
        assert code == 2 and option in err and said in " ".join(err.split()), err
        assert not path.exists() or path == friction
    code, printed, _ = run_cli_printed(capsys, "predict", friction, "--params", params, "--figure", "")
    assert code == 2
