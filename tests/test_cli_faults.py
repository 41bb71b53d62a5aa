"""The red team's classes of faults (issue 21), closed where they arise: each ends in the right
answer or in one line on stderr naming the fault, exit status 2, the input unchanged and no
output left. The silent-wrong classes assert the right answer.

Mechanisms: the time column's unit is read from its type or stated (:func:`~wbfriction.logs.clock.table_stamps`);
a log's schema is checked before any row is (:func:`~wbfriction.logs.log.check_schema`); continuous
joints are unwrapped where positions are read (:func:`~wbfriction.logs.angles.unwrap_positions`);
gross outliers are screened where a fit starts (:mod:`wbfriction.fit.screen`); every command
checks its paths before work (:func:`~wbfriction.pipeline.paths.check_paths`); option ranges are
the parser's, its errors one line; a parameters file is checked against the table it is used with
(:func:`~wbfriction.fit.params_file.check_params_source`); a CSV carries the metadata in its first line.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers import mapped_copy, run_cli, run_cli_printed, said
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import log_from_table
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.tables import write_table
from wbfriction.model import load_robot

ROWS = 3000


@pytest.fixture(scope="module")
def walk(talos, combined_walk, tmp_path_factory) -> Path:
    """3 s of the simulated walk (swing phases, true friction) as a Parquet log."""
    path = tmp_path_factory.mktemp("faults") / "walk.parquet"
    pq.write_table(combined_walk.log.to_table(talos).slice(0, ROWS), path)
    return path


@pytest.fixture(scope="module")
def walk_friction(talos, walk, tmp_path_factory) -> Path:
    """Its friction table, as ``wbfriction estimate --diff central`` writes it (with provenance)."""
    from wbfriction.pipeline.chunks import Chunking
    from wbfriction.pipeline.estimate_step import RobotSpec, estimate_file
    from wbfriction.pipeline.provenance import log_provenance

    out = tmp_path_factory.mktemp("faults_est") / "friction.parquet"
    estimate_file(RobotSpec("talos"), walk, out, EstimateOptions(diff="central"), chunking=Chunking(workers=1),
                  extra_metadata={"provenance": log_provenance(walk, talos)})
    return out


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _refused(capsys, tmp_path: Path, inputs: list[Path], args, needle: str) -> None:
    """The command fails with one line naming ``needle``, exit 2, its inputs unchanged, nothing written."""
    before = {p: _digest(p) for p in inputs if p.is_file()}
    listing = sorted(p.name for p in tmp_path.iterdir())
    code, err = run_cli(capsys, *args)
    lines = said(err)
    assert code == 2 and len(lines) == 1 and needle in lines[0], err
    assert "Traceback" not in err
    assert {p: _digest(p) for p in before} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == listing


def _with_time(table: pa.Table, values) -> pa.Table:
    return table.set_column(table.column_names.index("time"), "time", pa.array(values))


def _tau_f(path: Path, column: str = "tau_f.leg_right_4_joint") -> np.ndarray:
    return pq.read_table(path).column(column).to_numpy()


# ----------------------------------------------------------------- 1. silent wrong answers
@pytest.mark.parametrize("unit", ["ns", "ms", "float ms", "timestamp"])
def test_time_in_any_unit_gives_the_friction_of_seconds_or_a_refusal(walk, tmp_path, capsys, unit):
    """Integer stamps without a unit, and float milliseconds read as seconds, are refused; with
    the unit stated (a timestamp states its own), the friction equals that of the seconds."""
    table = pq.read_table(walk)
    seconds = table.column("time").to_numpy()
    values, option = {"ns": (np.round(seconds * 1e9).astype(np.int64) + 1_700_000_000_000_000_000, "ns"),
                      "ms": (np.round(seconds * 1e3).astype(np.int64), "ms"),
                      "float ms": (seconds * 1e3, "ms"),
                      "timestamp": (np.round(seconds * 1e9).astype("datetime64[ns]"), None)}[unit]
    log = tmp_path / "log.parquet"
    pq.write_table(_with_time(table, values), log)
    common = ("--diff", "central", "--workers", "1")
    if option is not None:
        _refused(capsys, tmp_path, [log], ("estimate", log, "-o", tmp_path / "f.parquet", *common), "--time-unit")
        common += ("--time-unit", option)
    assert run_cli(capsys, "estimate", log, "-o", tmp_path / "f.parquet", *common)[0] == 0
    assert run_cli(capsys, "estimate", walk, "-o", tmp_path / "s.parquet", *common[:4])[0] == 0
    a, b = _tau_f(tmp_path / "f.parquet"), _tau_f(tmp_path / "s.parquet")
    assert np.isfinite(b).sum() > 500
    np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-9)


def test_float32_columns_are_read_with_a_warning(walk, tmp_path, capsys):
    table = pq.read_table(walk)
    schema = pa.schema([pa.field(f.name, pa.float32() if f.name.startswith(("q.", "tau.")) else f.type)
                        for f in table.schema], metadata=table.schema.metadata)
    pq.write_table(table.cast(schema), tmp_path / "f32.parquet")
    code, err = run_cli(capsys, "estimate", tmp_path / "f32.parquet", "-o", tmp_path / "f.parquet", "--workers", "1")
    assert code == 0 and sum("float32" in line and "warning" in line for line in err.splitlines()) == 1, err


def test_a_continuous_joint_is_unwrapped(tmp_path):
    """The Panda with its last joint made continuous, logged wrapped in (-pi, pi] across the wrap:
    the friction equals that of the same motion logged unwrapped (the revolute original refuses the
    jump instead)."""
    import wbfriction
    from wbfriction.exceptions import ColumnError
    from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm

    panda = load_robot("panda")
    urdf = tmp_path / "panda_continuous.urdf"
    urdf.write_text(Path(panda.urdf).read_text().replace('<joint name="panda_joint7" type="revolute">',
                                                         '<joint name="panda_joint7" type="continuous">'))
    continuous = load_robot(urdf=urdf, config=Path(wbfriction.__file__).parent / "model/robots/panda.toml")
    assert list(continuous.layout.q2_joint) == [6]
    table = simulate_arm(panda, default_arm_friction(panda), options=ArmOptions(duration=2.0)).table
    q7 = table.column("q.panda_joint7").to_numpy()
    q7 = q7 + np.pi - 0.5 * (q7.min() + q7.max())  # the motion centred on pi: it crosses the wrap
    wrapped = np.angle(np.exp(1j * q7))
    assert np.abs(np.diff(wrapped)).max() > 6.0
    col = table.column_names.index("q.panda_joint7")
    options = EstimateOptions(diff="central")
    a = estimate_log(continuous, log_from_table(table.set_column(col, "q.panda_joint7", pa.array(q7)), continuous),
                     options)
    b = estimate_log(continuous, log_from_table(table.set_column(col, "q.panda_joint7", pa.array(wrapped)),
                                                continuous), options)
    assert np.nanmax(np.abs(a.tau_f)) > 1.0
    np.testing.assert_allclose(b.tau_f, a.tau_f, rtol=0, atol=1e-8)
    with pytest.raises(ColumnError, match="q.panda_joint7' jumps by"):
        log_from_table(table.set_column(col, "q.panda_joint7", pa.array(wrapped - np.pi / 2)), panda,
                       read=ReadOptions(limit_margin=10.0))


@pytest.mark.parametrize("value", [1e6, 1e300])
def test_a_gross_torque_outlier_does_not_steer_the_fit(walk, walk_friction, tmp_path, capsys, value):
    """One sample of 1e6 (or 1e300) N·m on a valid row: screened, counted, and the fit is the clean one."""
    table = pq.read_table(walk_friction)
    joint = "leg_right_4_joint"
    valid = np.flatnonzero(table.column(f"valid.{joint}").to_numpy())
    tau_f = table.column(f"tau_f.{joint}").to_numpy().copy()
    tau_f[valid[len(valid) // 2]] = value
    bad = tmp_path / "spiked.parquet"
    pq.write_table(table.set_column(table.column_names.index(f"tau_f.{joint}"), f"tau_f.{joint}", pa.array(tau_f)),
                   bad)
    for source, out in ((walk_friction, "clean.json"), (bad, "spiked.json")):
        code, err = run_cli(capsys, "fit", source, "-o", tmp_path / out, "--model", "thesis", "--workers", "1")
        assert code == 0, err
    clean, spiked = (json.loads((tmp_path / n).read_text())["joints"][joint] for n in ("clean.json", "spiked.json"))
    assert clean["n_screened"] == 0 and spiked["n_screened"] == 1
    assert spiked["n_samples"] == clean["n_samples"] - 1
    for name, x in clean["params"].items():
        assert spiked["params"][name] == pytest.approx(x, rel=1e-2, abs=1e-3), name


def test_a_csv_log_gives_the_friction_of_its_parquet_copy(walk, tmp_path, capsys):
    """The metadata (the simulator's torque alignment) travels in the CSV's first line."""
    write_table(pq.read_table(walk), tmp_path / "walk.csv")
    for log, out in ((walk, "p.parquet"), (tmp_path / "walk.csv", "c.parquet")):
        assert run_cli(capsys, "estimate", log, "-o", tmp_path / out, "--diff", "central", "--workers", "1")[0] == 0
    np.testing.assert_allclose(_tau_f(tmp_path / "c.parquet"), _tau_f(tmp_path / "p.parquet"), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("command", ["estimate", "convert"])
def test_a_nan_force_read_through_a_map_is_not_no_contact(talos, walk, tmp_path, capsys, command):
    """Issue 37: a NaN in a force column that a --map [[contacts]] entry reads was "no contact" (an all-NaN
    column turned double support into swing samples, then fitted). Sporadic or all NaN: one line naming the
    log, the column and the first row, exit 2, nothing written."""
    mapped, toml = mapped_copy(pq.read_table(walk), talos.contact_frames)
    (tmp_path / "map.toml").write_text(toml)
    force = mapped.column("foot0.fz").to_numpy()
    for name, nan_rows, first in (("sporadic", [777, 1500], 777), ("all", slice(None), 0)):
        values = force.copy()
        values[nan_rows] = np.nan
        log = tmp_path / f"{name}.parquet"
        pq.write_table(mapped.set_column(mapped.column_names.index("foot0.fz"), "foot0.fz", pa.array(values)), log)
        _refused(capsys, tmp_path, [log, tmp_path / "map.toml"],
                 (command, log, "--map", tmp_path / "map.toml", "-o", tmp_path / "out.parquet"),
                 f"{log}: column 'foot0.fz' has a non-finite value (NaN or inf) at row {first}")


# ----------------------------------------------------------------- 2. data destroyed
@pytest.mark.parametrize("command", ["estimate", "fit", "report"])
def test_an_output_that_is_the_input_is_refused(walk, walk_friction, tmp_path, capsys, command):
    source = tmp_path / ("log.parquet" if command == "estimate" else "friction.parquet")
    source.write_bytes((walk if command == "estimate" else walk_friction).read_bytes())
    # fit's and report's outputs are no table: the friction table's name is refused by its suffix, before the paths
    _refused(capsys, tmp_path, [source], (command, source, "-o", tmp_path / ".." / tmp_path.name / source.name),
             "is the input" if command == "estimate" else "not '.parquet'")


# ----------------------------------------------------------------- 4./5./8. hangs, tracebacks, misleading messages
def test_bad_tables_and_paths_get_one_line(walk, tmp_path, capsys):
    table = pq.read_table(walk)
    out = tmp_path / "out.parquet"
    cases = []
    strings = table.set_column(table.column_names.index("contact.left_sole_link"), "contact.left_sole_link",
                               pa.array(np.where(table.column("contact.left_sole_link").to_numpy() > 0, "on", "off")))
    pq.write_table(strings, tmp_path / "strings.parquet")
    cases.append(((tmp_path / "strings.parquet", "-o", out), "contact.left_sole_link' holds string"))
    write_table(table.slice(0, 50), tmp_path / "short.csv")
    text = (tmp_path / "short.csv").read_text().splitlines()
    names = text[1].split(",")
    names[2] = names[1]
    (tmp_path / "dup.csv").write_text("\n".join([text[0], ",".join(names), *text[2:]]) + "\n")
    cases.append(((tmp_path / "dup.csv", "-o", out), f"column '{names[1].strip(chr(34))}' appears 2 times"))
    (tmp_path / "folder").mkdir()
    cases.append(((tmp_path / "folder", "-o", out), "is a folder, not a table file"))
    (tmp_path / "folder.parquet").mkdir()  # a folder named as a table
    named = tmp_path / "folder.parquet"
    cases.append(((walk, "-o", named), f"-o {named}: is a folder"))
    cases.append(((walk, "-o", tmp_path / "none" / "x.parquet"), "does not exist"))
    for option, value in (("--chunk-rows", "0"), ("--chunk-rows", "-5"), ("--workers", "-1"), ("--lift-off", "nan"),
                          ("--max-gap", "0"), ("--ds-regularization", "-1"), ("--limit-margin", "-1")):
        cases.append(((walk, "-o", out, option, value), f"'{option}'"))
    cases.append(((walk, "-o", out, "--diff", "savgol", "--window", "4"), "--window"))
    # a response longer than the log: refused by the option before the work (issue 53), not "no single-support sample"
    cases.append(((walk, "-o", out, "--diff", "butterworth", "--cutoff", "0.001"), "--cutoff must be high enough"))
    for args, needle in cases:
        _refused(capsys, tmp_path, [walk, tmp_path / "strings.parquet", tmp_path / "dup.csv"], ("estimate", *args),
                 needle)


def test_small_chunks_after_a_contact_cut_read_forwards(walk, tmp_path, capsys):
    """--chunk-rows below the forced cut's overlap, after a cut at a contact change (an IndexError
    before): the chunks are read forwards and the table equals the one-chunk table."""
    for rows, out in (("200", "small.parquet"), ("100000", "whole.parquet")):
        code, err = run_cli(capsys, "estimate", walk, "-o", tmp_path / out, "--diff", "central", "--workers", "1",
                            "--chunk-rows", rows)
        assert code == 0, err
    np.testing.assert_allclose(_tau_f(tmp_path / "small.parquet"), _tau_f(tmp_path / "whole.parquet"), rtol=1e-10,
                               atol=1e-10)


# ----------------------------------------------------------------- 6. nothing in, nothing out
def test_a_fit_that_fits_nothing_is_an_error(walk_friction, tmp_path, capsys):
    _refused(capsys, tmp_path, [walk_friction], ("fit", walk_friction, "-o", tmp_path / "p.json", "--min-samples",
                                                 "100000000"), "no joint could be fitted")


def test_a_joint_not_fitted_says_so(walk_friction, tmp_path, capsys):
    table = pq.read_table(walk_friction)
    joint = "leg_right_4_joint"
    col = table.column_names.index(f"valid.{joint}")
    pq.write_table(table.set_column(col, f"valid.{joint}", pa.array(np.zeros(table.num_rows, dtype=bool))),
                   tmp_path / "t.parquet")
    code, _ = run_cli(capsys, "fit", tmp_path / "t.parquet", "-o", tmp_path / "p.json", "--workers", "1")
    assert code == 0
    entry = json.loads((tmp_path / "p.json").read_text())["joints"][joint]
    assert entry["fitted"] is False and entry["params"] is None and not entry["success"]
    # issue 65, class 5: a leg joint without a valid sample on a humanoid is its stance leg's under --mask swing,
    # however far it moved: said so, not "only 0 valid samples"
    assert entry["message"].startswith("no valid sample: the estimate's --mask swing counts a joint only while its "
                                       "leg swings"), entry["message"]


# ----------------------------------------------------------------- 7. wrong pairing
def test_parameters_of_another_table_are_refused(walk_friction, tmp_path, capsys):
    assert run_cli(capsys, "fit", walk_friction, "-o", tmp_path / "p.json", "--workers", "1")[0] == 0
    other = tmp_path / "other.parquet"
    table = pq.read_table(walk_friction)
    pq.write_table(table.slice(0, table.num_rows - 100), other)
    _refused(capsys, tmp_path, [other], ("report", other, "--params", tmp_path / "p.json", "-o",
                                         tmp_path / "r.html"), "not on")
    doc = json.loads((tmp_path / "p.json").read_text())
    doc["provenance"]["robot"] = "another_robot"
    (tmp_path / "q.json").write_text(json.dumps(doc))  # the same model file under another name: the same robot
    assert run_cli(capsys, "predict", walk_friction, "--params", tmp_path / "q.json")[0] == 0
    doc["provenance"]["urdf"] = str(tmp_path / "another_robot.urdf")  # another robot: name and model file
    (tmp_path / "q.json").write_text(json.dumps(doc))
    _refused(capsys, tmp_path, [walk_friction], ("predict", walk_friction, "--params", tmp_path / "q.json"),
             "not of the table's robot 'talos'")


# ----------------------------------------------------------------- 9. outputs honour the umask
def test_outputs_are_readable_by_the_group(walk_friction, tmp_path, capsys):
    import os

    old = os.umask(0o022)
    try:
        assert run_cli(capsys, "fit", walk_friction, "-o", tmp_path / "p.json", "--workers", "1")[0] == 0
    finally:
        os.umask(old)
    assert (tmp_path / "p.json").stat().st_mode & 0o777 == 0o644


# ----------------------------------------------------------------- property: any one fault, never a traceback
FAULTS = ("int time", "ms time", "nan torque", "string flags", "duplicate stamp", "degrees", "missing column",
          "output is input", "missing folder", "bad option")


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(fault=st.sampled_from(FAULTS), row=st.integers(10, 590), start=st.integers(0, 2000))
def test_one_fault_anywhere_ends_in_one_line(walk, tmp_path_factory, capsys, fault, row, start):
    """A random stretch of a valid log with one fault of each class: one clear line, exit 2, the
    input unchanged, nothing written, never a traceback."""
    tmp = tmp_path_factory.mktemp("fault")
    table = pq.read_table(walk).slice(start, 600)
    cols = {n: table.column(n).to_numpy().copy() for n in table.column_names}
    out = tmp / "out.parquet"
    extra: tuple = ()
    if fault == "int time":
        cols["time"] = np.round(cols["time"] * 1e9).astype(np.int64)
    elif fault == "ms time":
        cols["time"] = cols["time"] * 1e3
    elif fault == "nan torque":
        cols["tau.leg_left_4_joint"][row] = np.nan
    elif fault == "string flags":
        cols["contact.right_sole_link"] = np.where(cols["contact.right_sole_link"] > 0, "true", "false")
    elif fault == "duplicate stamp":
        cols["time"][row] = cols["time"][row - 1]
    elif fault == "degrees":
        cols["q.leg_left_4_joint"] = np.degrees(cols["q.leg_left_4_joint"]) + 10.0
    elif fault == "missing column":
        del cols["q.arm_left_2_joint"]
    elif fault == "missing folder":
        out = tmp / "none" / "out.parquet"
    elif fault == "bad option":
        extra = ("--workers", "0")
    log = tmp / "log.parquet"
    pq.write_table(pa.table(cols).replace_schema_metadata(table.schema.metadata), log)
    if fault == "output is input":
        out = log
    import time

    start_time = time.perf_counter()
    _refused(capsys, tmp, [log], ("estimate", log, "-o", out, "--diff", "central", *extra), "")
    assert time.perf_counter() - start_time < 30.0  # refused before any long work: never a hang


def test_predict_names_each_fit_s_status(walk_friction, tmp_path, capsys):
    """A prediction is no better than the fit behind it: ``predict`` prints each joint's fit status beside its RMS
    and says so below the table when one is not ok (the same RMS either way)."""
    def predict(params: Path) -> tuple[str, str]:
        code, out, err = run_cli_printed(capsys, "predict", walk_friction, "--params", params)
        assert code == 0, err
        return out, err

    params = tmp_path / "p.json"
    code, err = run_cli(capsys, "fit", walk_friction, "-o", params, "--model", "coulomb-viscous", "--workers", "1")
    assert code == 0, err
    doc = json.loads(params.read_text())
    joint = next(j for j, d in doc["joints"].items() if d["status"] == "ok")
    out, err = predict(params)
    row = next(line for line in out.splitlines() if line.split()[:1] == [joint])
    assert row.split()[-1] == "ok"
    doc["joints"][joint]["stderr"]["F_v"] = 3.0 * doc["joints"][joint]["params"]["F_v"]  # weak by its standard error
    weak = tmp_path / "weak.json"
    weak.write_text(json.dumps(doc))
    out, err = predict(weak)
    weak_row = next(line for line in out.splitlines() if line.split()[:1] == [joint])
    assert weak_row.split()[-1] == "weak" and weak_row.split()[:-1] == row.split()[:-1]
    assert "a prediction by a fit that is not ok is no better than that fit" in err
    # every joint together: the root of the pooled mean square, each joint weighted by its samples
    rows = [line.split() for line in out.splitlines() if line.split()[:1] in ([j] for j in doc["joints"])]
    samples = np.array([int(r[1]) for r in rows])
    rigid = np.array([float(r[2]) for r in rows])
    total = next(line.split() for line in out.splitlines() if line.split()[:2] == ["all", "joints"])
    assert int(total[2]) == samples.sum()
    assert float(total[3]) == pytest.approx(np.sqrt(np.sum(samples * rigid**2) / samples.sum()), rel=2e-3)
