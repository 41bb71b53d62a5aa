"""The command line: the main job end to end, and one-line errors with exit status 2."""

from __future__ import annotations

import json
import re

import numpy as np
import pyarrow.parquet as pq
import pytest

from helpers import assert_one_line_error, assert_stages, run, widest_line
from wbfriction.exceptions import InputError
from wbfriction.logs.log import write_log
from wbfriction.logs.source import read_log


@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory):
    """simulate -> estimate -> fit, the main job's steps, on a short walk."""
    out = tmp_path_factory.mktemp("demo")
    fr = out / "friction.toml"
    fr.write_text("[friction.knee]\nF_v = 0.2\nF_c = 1.0\nS = 0.2\nv_s = 0.2\ntau_os = 1.0\na = 40\n"
                  "[friction.leg_left_4_joint]\nF_c = 0.5\n")
    res = run("simulate", "-o", out / "log.parquet", "--gait", "forward", "--steps", "3", "--friction", fr)
    assert res.returncode == 0, res.stderr
    assert_stages(res.stderr, "planning 3 steps (forward)", "simulate")  # piped: a line per stage (issue 67)
    res = run("estimate", out / "log.parquet", "-o", out / "friction.parquet")
    assert res.returncode == 0, res.stderr
    assert_stages(res.stderr, "estimate")
    res = run("fit", out / "friction.parquet", "-o", out / "params.json")
    assert res.returncode == 0, res.stderr
    assert_stages(res.stderr, "reading friction.parquet", "fit", "terms")
    return out, res


def test_main_job_steps_write_log_friction_and_params(demo_dir):
    out, res = demo_dir
    params = json.loads((out / "params.json").read_text())
    knee = params["joints"]["leg_right_4_joint"]
    assert knee["n_samples"] > 1000
    assert abs(knee["params"]["F_c"] - 1.0) < 0.05 and abs(knee["params"]["tau_os"] - 1.0) < 0.05
    assert knee["error_percent"]["F_c"] < 5
    assert knee["status"] == "ok" and knee["status_reason"] == ""  # a verdict for every fit (issue 24)
    # the joint's own TOML table overrides its group's
    assert params["joints"]["leg_left_4_joint"]["target"]["F_c"] == 0.5
    assert params["joints"]["leg_left_4_joint"]["target"]["F_v"] == 0.0
    # by its name, as the log and the URDF name it (the report, not the terminal, names it by its label)
    assert "leg_right_4_joint " in res.stdout and "right knee" not in res.stdout
    assert "Against the simulator's friction: error [%]" in res.stdout
    table = pq.read_table(out / "friction.parquet")
    for col in ("time", "phase", "unique", "qd.leg_right_4_joint", "tau_f.leg_right_4_joint",
                "valid.leg_right_4_joint", "tau_f_true.leg_right_4_joint"):
        assert col in table.column_names


@pytest.mark.slow
def test_demo_prints_the_thesis_table_and_writes_figures(tmp_path):
    res = run("demo", "-o", tmp_path, "--steps", "2", columns=100)
    assert res.returncode == 0, res.stderr
    assert_stages(res.stderr, "planning a forward walk", "simulating the forward walk", "estimating with four",
                  "planning the combined walk", "simulating the combined walk", "estimating (central", "fit",
                  "writing the report")  # piped: a line per stage as it ends, with its time (issue 67)
    assert "T6.2 [%]" in res.stdout and "leg_right_4_joint " in res.stdout and "knee target" in res.stdout
    assert widest_line(res.stdout) <= 100, res.stdout
    # the 2-step walk hardly turns the hip yaws: said before the table, left out of the worst errors
    table = res.stdout.index("T6.2 [%]")
    assert res.stdout.index("not an ok fit: leg_right_1_joint (hip_yaw)") < table
    yaw = next(line for line in res.stdout.splitlines() if "leg_right_1_joint" in line and "not excited" in line
               and "not an ok fit" not in line)
    assert "—" in yaw and not re.search(r"\d\.\d{4}", yaw), yaw  # no value for a joint that did not move
    flat = " ".join(res.stdout.split())  # the line as said, however the terminal's width wrapped it
    worst = flat[flat.index("worst error over the"):flat.index("true accelerations")]
    errors = dict(re.findall(r"(\w+) ([\d.]+)", worst.split("[%]:")[1]))
    assert "leg joints with an ok fit" in worst and set(errors) == {"F_v", "F_c", "S", "v_s", "tau_os", "a"}
    assert all(float(v) < 50 for v in errors.values()), worst  # a hip yaw that did not turn: 19046 %
    assert "friction generating power (eq. 7.9), leg joints in swing: at most" in res.stdout
    for name in ("fig6_1_support_phases.png", "fig6_2_schemes_time.png", "fig6_3_schemes_velocity.png",
                 "friction_curves.png", "walk_params.json", "walk_friction.parquet", "report.html"):
        assert (tmp_path / name).stat().st_size > 1000, name
    assert not list(tmp_path.glob(".*.tmp*")), "temporary files left behind"


def test_estimate_and_fit_commands_with_options(demo_dir, tmp_path):
    out, _ = demo_dir
    res = run("estimate", out / "log.parquet", "--robot", "talos", "-o", tmp_path / "f.parquet", "--cond",
              "--mask", "single", "--diff", "backward")
    assert res.returncode == 0, res.stderr
    t = pq.read_table(tmp_path / "f.parquet")
    cond = t.column("cond").to_numpy()
    single = t.column("unique").to_numpy(zero_copy_only=False)
    assert np.isfinite(cond[single]).all() and (cond[single] > 1).all()
    res = run("fit", tmp_path / "f.parquet", "-o", tmp_path / "p.json")
    assert res.returncode == 0, res.stderr
    assert json.loads((tmp_path / "p.json").read_text())["joints"]["leg_left_4_joint"]["n_samples"] > 0


def test_bad_inputs_exit_2_with_one_line(talos, demo_dir, tmp_path):
    out, _ = demo_dir
    log = read_log(out / "log.parquet", talos)
    # NaN in a joint column
    bad = read_log(out / "log.parquet", talos)
    bad.q[5, 3] = np.nan
    write_log(bad, talos, tmp_path / "nan.parquet")
    assert_one_line_error(run("estimate", tmp_path / "nan.parquet", "-o", tmp_path / "x.parquet"),
                           f"column 'q.{talos.actuated[3]}' has a non-finite value (NaN or inf) at row 5")
    # no single-support sample
    log.contact[:] = True
    write_log(log, talos, tmp_path / "ds.parquet")
    assert_one_line_error(run("estimate", tmp_path / "ds.parquet", "-o", tmp_path / "x.parquet"),
                           "no single-support sample")
    assert not (tmp_path / "x.parquet").exists()
    # a URDF that does not load
    (tmp_path / "broken.urdf").write_text("<robot name='x'><link name='a'/><joint/></robot>")
    (tmp_path / "r.toml").write_text('contact_frames = ["a"]\n')
    assert_one_line_error(run("estimate", out / "log.parquet", "--urdf", tmp_path / "broken.urdf", "--config",
                               tmp_path / "r.toml", "-o", tmp_path / "x.parquet"), "URDF does not load")
    assert_one_line_error(run("estimate", out / "log.parquet", "--robot", "asimo", "-o", tmp_path / "x.parquet"),
                           "unknown robot 'asimo'")
    assert_one_line_error(run("fit", out / "log.parquet", "-o", tmp_path / "p.json"), "no 'tau_f.<joint>' column")


def test_the_filter_study_takes_its_noise_levels_or_says_why_not(tmp_path):
    from wbfriction.cli.studies import noise_levels

    assert noise_levels("exact, 0,1e-4") == (None, 0.0, 1e-4)  # in the order given, 'exact': no sensor model
    for bad in ("-1e-4", "1e-4,1e-4", ","):
        with pytest.raises(InputError, match="--levels must be"):
            noise_levels(bad)
    # refused in one line before the walk is simulated
    assert_one_line_error(run("study-filters", "--levels", "1e-4,loud", "-o", tmp_path / "f"), "--levels must be")
    assert not (tmp_path / "f").exists()


def test_any_robot_from_urdf_and_toml(talos, demo_dir, tmp_path):
    """TALOS given as a user robot (URDF + TOML) gives the built-in's result."""
    out, _ = demo_dir
    cfg = tmp_path / "talos.toml"
    cfg.write_text('name = "mine"\nposition_controlled = ["head_1_joint", "head_2_joint"]\n'
                   'contact_frames = ["left_sole_link", "right_sole_link"]\n')
    res = run("estimate", out / "log.parquet", "--urdf", talos.urdf, "--config", cfg, "-o", tmp_path / "f.parquet")
    assert res.returncode == 0, res.stderr
    a = pq.read_table(tmp_path / "f.parquet").column("tau_f.leg_right_4_joint").to_numpy()
    b = pq.read_table(out / "friction.parquet").column("tau_f.leg_right_4_joint").to_numpy()
    np.testing.assert_array_equal(a, b)
    # an unknown joint in the TOML is named
    cfg.write_text('position_controlled = ["neck_joint"]\ncontact_frames = ["left_sole_link"]\n')
    assert_one_line_error(run("estimate", out / "log.parquet", "--urdf", talos.urdf, "--config", cfg, "-o",
                               tmp_path / "g.parquet"), "unknown position-controlled joint 'neck_joint'")


@pytest.mark.slow
def test_filtering_schemes_from_the_command_line(demo_dir, tmp_path):
    """estimate --diff savgol/butterworth, then fit: the fit filters its model like the
    estimate (options read back from the table's metadata) and recovers the knee."""
    out, _ = demo_dir
    for args in (["--diff", "savgol", "--window", "51", "--poly-order", "4"],
                 ["--diff", "butterworth", "--cutoff", "25", "--butter-order", "4"]):
        res = run("estimate", out / "log.parquet", "-o", tmp_path / "f.parquet", *args)
        assert res.returncode == 0, res.stderr
        res = run("fit", tmp_path / "f.parquet", "-o", tmp_path / "p.json")
        assert res.returncode == 0, res.stderr
        knee = json.loads((tmp_path / "p.json").read_text())["joints"]["leg_right_4_joint"]
        assert knee["error_percent"]["F_c"] < 5 and knee["error_percent"]["tau_os"] < 5, (args, knee)
    assert_one_line_error(run("estimate", out / "log.parquet", "-o", tmp_path / "x.parquet", "--diff", "savgol",
                               "--window", "50"), "--window must be odd")
    assert_one_line_error(run("estimate", out / "log.parquet", "-o", tmp_path / "x.parquet", "--diff",
                               "butterworth", "--cutoff", "600"), "Nyquist")


def test_spectrum_command(demo_dir, tmp_path):
    out, _ = demo_dir
    res = run("spectrum", out / "log.parquet", "-o", tmp_path / "s.png", "--joints",
              "leg_right_4_joint,leg_right_3_joint")
    assert res.returncode == 0, res.stderr
    assert "suggested cutoff" in res.stdout and "leg_right_3_joint" in res.stdout
    assert (tmp_path / "s.png").stat().st_size > 1000
    assert_one_line_error(run("spectrum", out / "log.parquet", "--joints", "head_1_joint"),
                           "'head_1_joint' is not a torque-controlled joint")


@pytest.mark.slow
def test_report_and_sensitivity_commands(demo_dir, tmp_path):
    out, _ = demo_dir
    res = run("report", out / "friction.parquet", "--params", out / "params.json", "-o", tmp_path / "r.html")
    assert res.returncode == 0, res.stderr
    assert_stages(res.stderr, "building the report")
    text = (tmp_path / "r.html").read_text()
    assert "leg_right_4_joint" in text and "params.json (sha256" in text
    res = run("sensitivity", out / "log.parquet", "--factors", "0.9,1.1", "--part", "mass", "--joints",
              "leg_right_4_joint,leg_right_3_joint", "-o", tmp_path / "s.png")
    assert res.returncode == 0, res.stderr
    assert "x1.1 shift" in res.stdout and "leg_right_3_joint" in res.stdout
    assert (tmp_path / "s.png").stat().st_size > 1000
    assert_one_line_error(run("sensitivity", out / "log.parquet", "--part", "inertia"), "'--part'")
    assert_one_line_error(run("sensitivity", out / "log.parquet", "--factors", "0.9,big"), "--factors")
    assert_one_line_error(run("report", out / "friction.parquet", "--params", out / "log.parquet",
                               "-o", tmp_path / "x.html"), "not JSON")
    assert_one_line_error(run("report", out / "log.parquet", "-o", tmp_path / "x.html"), "no 'tau_f.<joint>' column")
    assert not (tmp_path / "x.html").exists()


def test_fit_warns_about_friction_that_generates_power(demo_dir, tmp_path):
    """A friction table whose knee estimate is turned against its velocity: fit says so, and
    records it in the parameters."""
    import pyarrow as pa

    out, _ = demo_dir
    table = pq.read_table(out / "friction.parquet")
    i = table.column_names.index("tau_f.leg_right_4_joint")
    flipped = table.set_column(i, "tau_f.leg_right_4_joint", pa.array(-table.column(i).to_numpy()))
    pq.write_table(flipped.replace_schema_metadata(table.schema.metadata), tmp_path / "f.parquet")
    res = run("fit", tmp_path / "f.parquet", "-o", tmp_path / "p.json")
    assert res.returncode == 0, res.stderr
    warnings = [line for line in res.stderr.splitlines() if line.startswith("warning: friction generates power")]
    assert len(warnings) == 1 and "leg_right_4_joint" in warnings[0], res.stderr  # one line, the joint by its name
    energy = json.loads((tmp_path / "p.json").read_text())["joints"]["leg_right_4_joint"]["energy"]
    assert energy["flagged"] and energy["generating_share"] > 0.5
    ok = json.loads((out / "params.json").read_text())["joints"]["leg_right_4_joint"]["energy"]
    assert not ok["flagged"] and ok["generating_share"] < 0.01


def test_simulate_on_mujoco_with_sensors_from_toml(talos, tmp_path):
    """``simulate --simulator mujoco`` writes the project's log with measured contact flags
    and the sensors of a TOML (the command line overriding it); bad sensor input is one
    line, exit 2, no output."""
    (tmp_path / "sensors.toml").write_text("[sensors]\nposition_std = 1e-4\nencoder_bits = 19\nseed = 3\n")
    log_path = tmp_path / "mj.parquet"
    res = run("simulate", "--simulator", "mujoco", "--gait", "forward", "--steps", "1", "-o", log_path,
              "--sensors", tmp_path / "sensors.toml", "--torque-noise", "0.05", "--delay", "1")
    assert res.returncode == 0, res.stderr
    log = read_log(log_path, talos)
    assert log.metadata["options"]["sensors"] == {"position_std": 1e-4, "encoder_bits": 19, "torque_std": 0.05,
                                                  "seed": 3}
    assert log.metadata["options"]["delay"] == pytest.approx(1e-3)
    assert log.metadata["contact_source"].startswith("sole normal force") and log.tau_f_true is not None
    (tmp_path / "bad.toml").write_text("[sensors]\nposition_noise = 1e-4\n")
    bad = tmp_path / "bad.parquet"
    assert_one_line_error(run("simulate", "--simulator", "mujoco", "--steps", "1", "-o", bad, "--sensors",
                               tmp_path / "bad.toml"), "[sensors] has unknown key(s) position_noise")
    assert_one_line_error(run("simulate", "--simulator", "mujoco", "--steps", "1", "-o", bad, "--delay", "0.5"),
                           "must be a multiple of the control period")
    assert_one_line_error(run("simulate", "--simulator", "mujoco", "--steps", "1", "-o", bad, "--mujoco-friction",
                               "coulomb"), "'--mujoco-friction'")
    assert not bad.exists()


def test_companion_scheme_only_on_request(talos, demo_dir, tmp_path):
    """estimate writes Fig. 7.4's companion difference only with --companion, then equal to the library's
    (estimate_log(companion=True)); a filter option that is not valid is refused even where the scheme would not
    use it (checked before any work), and one given with --diff auto is refused rather than dropped."""
    from wbfriction.friction.estimate import estimate_log
    from wbfriction.friction.options import EstimateOptions

    out, _ = demo_dir
    assert_one_line_error(run("estimate", out / "log.parquet", "-o", tmp_path / "plain.parquet", "--diff", "central",
                              "--window", "4"), "--window must be odd and at least 3, got 4")
    assert_one_line_error(run("estimate", out / "log.parquet", "-o", tmp_path / "plain.parquet", "--poly-order", "3"),
                          "--poly-order must be given with --diff savgol or butterworth")
    res = run("estimate", out / "log.parquet", "-o", tmp_path / "plain.parquet", "--diff", "central")
    assert res.returncode == 0, res.stderr
    assert not [c for c in pq.read_table(tmp_path / "plain.parquet").column_names if "companion" in c]
    res = run("estimate", out / "log.parquet", "-o", tmp_path / "both.parquet", "--diff", "central", "--companion")
    assert res.returncode == 0, res.stderr
    table = pq.read_table(tmp_path / "both.parquet")
    est = estimate_log(talos, read_log(out / "log.parquet", talos), EstimateOptions(diff="central"), companion=True)
    for i, j in enumerate(est.joints):
        np.testing.assert_allclose(table.column(f"delta_qdd_companion.{j}").to_numpy(), est.companion_delta_qdd[:, i],
                                   rtol=0, atol=1e-9, err_msg=j)


def test_api_and_cli_give_the_same_friction_table_and_fits_with_their_defaults(talos, demo_dir):
    """One log, one result, whatever the entry point (issue 39): ``estimate_log`` + ``fit_estimate`` with their
    defaults give the friction table (every column, every value) and the fitted parameters that ``wbfriction
    estimate`` and ``wbfriction fit`` wrote with theirs; only the provenance in the file's metadata differs."""
    from wbfriction.fit.joints import fit_estimate
    from wbfriction.fit.params_file import read_params
    from wbfriction.friction.estimate import estimate_log
    from wbfriction.friction.io import friction_table

    out, _ = demo_dir
    est = estimate_log(talos, read_log(out / "log.parquet", talos))
    api = friction_table(est).replace_schema_metadata(None)
    cli = pq.read_table(out / "friction.parquet").replace_schema_metadata(None)
    assert api.column_names == cli.column_names and api.schema == cli.schema
    for name in api.column_names:  # value for value, NaN where NaN
        np.testing.assert_array_equal(api.column(name).to_numpy(zero_copy_only=False),
                                      cli.column(name).to_numpy(zero_copy_only=False), err_msg=name)
    params = read_params(out / "params.json")
    fits = fit_estimate(est)
    assert [f.joint for f in fits] == list(params)
    for f in fits:
        back = params[f.joint]
        assert (f.model, f.params, f.verdict().status) == (back.model, back.params, back.verdict().status)


def test_fit_prints_tables_that_fit_a_100_column_terminal(demo_dir, tmp_path):
    """``COLUMNS=100 wbfriction fit``: no line over 100 columns, every joint that moved named whole by its name (as
    the log, the URDF, ``predict`` and ``export`` name it), each status shown, the joints that did not move (status
    ``not excited`` in the parameters written) folded into one line that names every one of them (issue 67);
    ``--wide`` every parameter in one table, every joint's row, as wide as it takes; ``--verbose`` each joint's
    reason (issue 39)."""
    import re

    out, _ = demo_dir
    res = run("fit", out / "friction.parquet", "-o", tmp_path / "p.json", columns=100)
    assert res.returncode == 0, res.stderr
    assert widest_line(res.stdout) <= 100, res.stdout
    params = json.loads((tmp_path / "p.json").read_text())["joints"]
    rows: dict[str, list[str]] = {}
    for joint in params:  # each joint's first row, the main table's: by its name, whole, never cut
        line = next((line for line in res.stdout.splitlines() if line.startswith(joint + " ")), None)
        if line is not None:
            rows[joint] = line[len(joint):].split()
    still = [j for j in params if params[j]["status"] == "not excited"]
    assert sorted(rows) == sorted(j for j in params if j not in still)  # a row for each joint that moved alone
    assert rows and all(rows[j][1] in ("ok", "weak", "at", "failed", "routes", "does") for j in rows)
    text = " ".join(res.stdout.split())  # the lines the terminal's width wrapped, whole again
    folded = re.search(r"(\d+) joints? not excited \([^)]*\): ", text)
    if still:  # one line, bash's braces (arm_left_{1..7}_joint) expanded here
        assert folded is not None and int(folded.group(1)) == len(still), res.stdout
        named: list[str] = []
        for item in text[folded.end():].split(", "):  # up to the next line's first word
            named += _braces(item.split(" ")[0])
            if " " in item:
                break
        assert sorted(named) == sorted(still), named
    else:
        assert folded is None
    assert "Against the simulator's friction" in res.stdout  # the walk's log carries the truth
    assert "F_c [N·m]" in res.stdout and "F_v [N·m·s/rad]" in res.stdout  # units in the headers
    wide = run("fit", out / "friction.parquet", "-o", tmp_path / "w.json", "--wide", columns=100)
    assert wide.returncode == 0 and widest_line(wide.stdout) > 100 and " N " in wide.stdout.splitlines()[1]
    assert all(any(line.startswith(j + " ") for line in wide.stdout.splitlines()) for j in params)
    verbose = run("fit", out / "friction.parquet", "-o", tmp_path / "v.json", "--verbose", columns=100)
    words = "".join(verbose.stdout.split())  # each reason once, however the terminal's width wrapped it
    scored = [j for j in params if (params[j].get("selection") or {}).get("scores")]  # not those that hardly moved
    assert words.count("held-outRMS[N·m]:") == len(scored) > 0
    assert words.count("nomodelcanbechosen") == len([j for j in params if params[j].get("selection")]) - len(scored)
    assert widest_line(verbose.stdout) <= 100


def _braces(word: str) -> list[str]:
    """Bash's brace expansion of one word (``arm_left_{1..3,5}_joint``), written apart from the code that folds."""
    m = re.fullmatch(r"(.*)\{(.*)\}(.*)", word)
    if m is None:
        return [word]
    numbers: list[int] = []
    for part in m.group(2).split(","):
        low, _, high = part.partition("..")
        numbers += list(range(int(low), int(high or low) + 1))
    return [f"{m.group(1)}{n}{m.group(3)}" for n in numbers]
