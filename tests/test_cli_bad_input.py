"""Every kind of bad input, through the command line and every log format: one line naming
the file, column and row, exit status 2, and nothing written (a previous output is left
byte for byte, no temporary file stays behind).

The command runs in this process (``wbfriction.cli.main``, as the console script does);
the logs are short, so the estimate runs as a single chunk without worker processes.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from helpers import run_cli, said, write_bag
from wbfriction.logs.formats.hdf5 import write_hdf5
from wbfriction.logs.log import Log, log_from_table, write_log
from wbfriction.logs.options import ReadOptions
from wbfriction.logs.source import read_log
from wbfriction.logs.tables import write_table

PREVIOUS = b"the previous output"
FORMATS = ("parquet", "csv", "h5")


@pytest.fixture(scope="module")
def good(talos) -> Log:
    """A short single-support log inside the joint limits (left foot down)."""
    n = 60
    rng = np.random.default_rng(1)
    contact = np.zeros((n, 2), dtype=bool)
    contact[:, 0] = True
    lo, hi = talos.angle_limits
    q = lo + (hi - lo) * rng.uniform(0.3, 0.7, talos.n_act) + rng.normal(0, 1e-3, (n, talos.n_act))
    return Log(time=np.arange(n) * 1e-3, q=q, tau=rng.normal(0, 1, (n, len(talos.torque_controlled))),
               contact=contact)


def _columns(log: Log, robot) -> dict[str, np.ndarray]:
    table = log.to_table(robot)
    return {n: table.column(n).to_numpy().copy() for n in table.column_names}


def _write(cols: dict[str, np.ndarray], path) -> None:
    table = pa.table(cols)
    if path.suffix == ".h5":
        write_hdf5(table, path)  # write_table's atomic wrapper is not needed for a test input
    else:
        write_table(table, path)


def _set(col: str, row: int, value):
    return lambda c: c[col].__setitem__(row, value)


CASES = {  # case: (edit of the columns, what the line must say)
    "nan": (_set("q.leg_left_4_joint", 7, np.nan),
            "column 'q.leg_left_4_joint' has a non-finite value (NaN or inf) at row 7"),
    "inf": (_set("tau.arm_right_2_joint", 11, np.inf),
            "column 'tau.arm_right_2_joint' has a non-finite value (NaN or inf) at row 11"),
    "duplicated stamp": (lambda c: c["time"].__setitem__(10, c["time"][9]), "duplicated stamp at row 10"),
    "decreasing stamp": (lambda c: c["time"].__setitem__(10, c["time"][9] - 1e-4), "decreasing stamp at row 10"),
    "missing joint": (lambda c: c.pop("q.leg_right_2_joint"), "missing column 'q.leg_right_2_joint'"),
    "missing torque": (lambda c: c.pop("tau.leg_right_2_joint"), "missing column 'tau.leg_right_2_joint'"),
    "unknown joint": (lambda c: c.__setitem__("q.leg_middle_1_joint", c["time"]), "unknown joint 'leg_middle_1_joint'"),
    "unknown contact": (lambda c: c.__setitem__("contact.nose", c["contact.left_sole_link"]),
                        "unknown contact frame 'nose'"),
    "degrees for radians": (lambda c: c.__setitem__("q.leg_left_4_joint", np.degrees(c["q.leg_left_4_joint"])),
                            "column 'q.leg_left_4_joint' is "),
    "no single support": (lambda c: c.__setitem__("contact.right_sole_link", np.ones_like(c["time"], dtype=np.int8)),
                          "no single-support sample"),
}


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("case", list(CASES))
def test_estimate_refuses_bad_logs_and_writes_nothing(talos, good, tmp_path, capsys, case, fmt):
    edit, needle = CASES[case]
    cols = _columns(good, talos)
    edit(cols)
    log = tmp_path / f"log.{fmt}"
    _write(cols, log)
    output = tmp_path / "friction.parquet"
    output.write_bytes(PREVIOUS)
    before = sorted(p.name for p in tmp_path.iterdir())
    code, err = run_cli(capsys, "estimate", log, "-o", output)
    lines = said(err)
    assert code == 2 and len(lines) == 1, err
    assert str(log) in lines[0] and needle in lines[0], lines[0]
    assert output.read_bytes() == PREVIOUS
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_the_good_log_is_estimated_in_every_format(talos, good, tmp_path, capsys):
    """The control: the unedited log passes, and every format gives the same table."""
    tables = []
    for fmt in FORMATS:
        log = tmp_path / f"log.{fmt}"
        _write(_columns(good, talos), log)
        np.testing.assert_array_equal(read_log(log, talos).q, good.q)
        code, err = run_cli(capsys, "estimate", log, "-o", tmp_path / f"f_{fmt}.parquet")
        assert code == 0, err
        tables.append(pq.read_table(tmp_path / f"f_{fmt}.parquet"))
    assert np.isfinite(tables[0].column("tau_f.leg_left_4_joint").to_numpy()).sum() > 20
    for t in tables[1:]:
        assert t.column_names == tables[0].column_names
        for name in t.column_names:
            np.testing.assert_array_equal(t.column(name).to_numpy(zero_copy_only=False),
                                          tables[0].column(name).to_numpy(zero_copy_only=False), err_msg=name)


@pytest.mark.parametrize("command", ["estimate", "convert", "fit", "report"])
def test_damaged_and_missing_files_write_nothing(talos, good, tmp_path, capsys, command):
    """A truncated file, a missing one and an unknown type: one line each, nothing written."""
    write_log(good, talos, tmp_path / "whole.parquet")
    damaged = tmp_path / "damaged.parquet"
    damaged.write_bytes((tmp_path / "whole.parquet").read_bytes()[:-100])
    (tmp_path / "notes.txt").write_text("time,q\n")
    output = tmp_path / ("out.html" if command == "report" else "out.json" if command == "fit" else "out.parquet")
    output.write_bytes(PREVIOUS)
    extra = ["--map", tmp_path / "map.toml"] if command == "convert" else []
    (tmp_path / "map.toml").write_text('[joint_states]\ntopic = "/joint_states"\n'
                                       '[[contacts]]\nframe = "left_sole_link"\ntopic = "/l"\n')
    before = sorted(p.name for p in tmp_path.iterdir())
    for bad, needle in ((damaged, "cannot be read"),
                        (tmp_path / "none.parquet", "not found"),
                        (tmp_path / "notes.txt", "unknown file type")):
        code, err = run_cli(capsys, command, bad, "-o", output, *extra)
        lines = said(err)
        assert code == 2 and len(lines) == 1 and needle in lines[0] and bad.name in lines[0], (bad, err)
        assert output.read_bytes() == PREVIOUS
        assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_usage_errors_exit_2_with_the_usage(capsys, tmp_path):
    code, err = run_cli(capsys, "estimate", tmp_path / "log.parquet")
    assert code == 2 and "Missing option" in err and "--output" in err
    code, err = run_cli(capsys, "estimate", tmp_path / "log.parquet", "-o", tmp_path / "f.parquet", "--diff-x", "1")
    assert code == 2 and "No such option" in err
    assert list(tmp_path.iterdir()) == []


def test_a_time_gap_splits_the_log_instead_of_failing(talos, good, tmp_path, capsys):
    """A dropped stretch (12 ms) is no error: the two sides are estimated apart, exactly as the
    two halves written as logs of their own, except that the lift-off and touch-down margins
    apply at the gap (what the feet did during it is not known): the rows within them are
    dropped from the gapped log and kept in the halves, which have no gap."""
    cols = _columns(good, talos)
    cols["time"][30:] += 0.012
    _write(cols, tmp_path / "gap.parquet")
    for half, rows in (("a", slice(0, 30)), ("b", slice(30, None))):
        _write({k: v[rows] for k, v in cols.items()}, tmp_path / f"{half}.parquet")
    for margins in (("0", "0"), ("0.01", "0.005")):
        results = {}
        for name in ("gap", "a", "b"):
            code, err = run_cli(capsys, "estimate", tmp_path / f"{name}.parquet", "-o", tmp_path / f"f_{name}.parquet",
                                "--lift-off", margins[0], "--touch-down", margins[1])
            assert code == 0, err
            table = pq.read_table(tmp_path / f"f_{name}.parquet")
            results[name] = (table.column("tau_f.leg_right_4_joint").to_numpy(),  # the swinging leg
                             table.column("valid.leg_right_4_joint").to_numpy())
        tau_f = np.concatenate([results["a"][0], results["b"][0]])
        valid = np.concatenate([results["a"][1], results["b"][1]])
        assert results["a"][1].sum() > 10 and results["b"][1].sum() > 10
        dropped = np.zeros(len(tau_f), dtype=bool)
        if margins != ("0", "0"):
            dropped[25:30] = dropped[30:40] = True  # 5 ms before the gap, 10 ms after it
        inner = ~np.isin(np.arange(60), (0, 29, 30, 59))  # the stencils at the ends of each half
        assert not results["gap"][1][dropped].any() and valid[dropped & inner].all()
        np.testing.assert_array_equal(results["gap"][1][~dropped], valid[~dropped])
        # equal up to the rounding of the sampling period (each log's median time step)
        np.testing.assert_allclose(results["gap"][0], tau_f, rtol=1e-12)


@pytest.mark.parametrize("command", ["convert", "estimate"])
def test_bad_bags_write_nothing(talos, combined_walk, tmp_path, capsys, command):
    """A bag streamed into a temporary log and checked: its faults name the bag, the previous
    output stays, and neither the temporary log nor its folder is left behind."""

    walk = combined_walk.log.to_table(talos).slice(0, 1500)
    degrees = walk.set_column(walk.column_names.index("q.leg_left_4_joint"), "q.leg_left_4_joint",
                              pa.array(np.degrees(walk.column("q.leg_left_4_joint").to_numpy())))
    write_bag(tmp_path / "bag", log_from_table(degrees, talos, "walk", ReadOptions(limit_margin=np.inf)), talos)
    left, right = talos.contact_frames
    topics = (f'[joint_states]\ntopic = "/joint_states"\n[[contacts]]\nframe = "{left}"\ntopic = "/left_ft"\n'
              f'threshold = 50\n')
    (tmp_path / "map.toml").write_text(topics + f'[[contacts]]\nframe = "{right}"\ntopic = "/right_contact"\n')
    (tmp_path / "one_foot.toml").write_text(topics)
    output = tmp_path / "out.parquet"
    output.write_bytes(PREVIOUS)
    before = sorted(p.name for p in tmp_path.iterdir())
    for map_file, needle in (("map.toml", "column 'q.leg_left_4_joint' is "),
                             ("one_foot.toml", f"missing column 'contact.{right}'")):
        code, err = run_cli(capsys, command, tmp_path / "bag", "--map", tmp_path / map_file, "-o", output)
        lines = said(err)
        assert code == 2 and len(lines) == 1, err
        assert f"{tmp_path / 'bag'}: " in lines[0] and needle in lines[0], lines[0]
        assert output.read_bytes() == PREVIOUS
        assert sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize("option", ["--cond", "--companion"])
def test_an_acceleration_route_output_asked_of_the_momentum_route_is_refused(good, talos, tmp_path, capsys, option):
    """Issue 53: ``estimate --route momentum --cond`` (or ``--companion``) ran and left the column out without a
    word."""
    log = tmp_path / "log.parquet"
    write_log(good, talos, log)
    code, err = run_cli(capsys, "estimate", log, "--robot", "talos", "--route", "momentum", option,
                        "-o", tmp_path / "f.parquet")
    assert code == 2 and len(said(err)) == 1 and f"{option} must be left out with --route momentum" \
        in err, err
    assert not (tmp_path / "f.parquet").exists()
