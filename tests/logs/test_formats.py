"""A log format is one class registered with one call (issue 54): a JSON-lines format defined here is read and
written wherever a log is, and a log written in it is estimated to the very numbers of the same log in Parquet, in
memory (``estimate_log``) and chunk by chunk (``estimate_file``)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs import LogFormat, UnknownFormatError, format_of, log_formats, register_format, unregister_format
from wbfriction.logs.metadata import read_metadata, with_metadata
from wbfriction.logs.source import open_log, read_log
from wbfriction.logs.tables import TableFile, read_table, write_table, write_tables
from wbfriction.model.loading import load_robot
from wbfriction.pipeline.chunks import Chunking
from wbfriction.pipeline.estimate_step import RobotSpec, estimate_file
from wbfriction.sim.arm import ArmOptions, default_arm_friction, simulate_arm


class JsonLines(LogFormat):
    """One JSON object per row (a float written as its shortest repr, read back to the same bits); the first line
    ``{"wbfriction": {...}}`` holds the metadata."""

    name = "jsonl"
    label = "JSON lines"
    suffixes = (".jsonl",)
    writable = True

    def read(self, path: Path, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        header, *lines = Path(path).read_text().splitlines()
        rows = [json.loads(line) for line in lines]
        names = [n for n in rows[0] if columns is None or n in columns]
        return with_metadata(pa.table({n: [r[n] for r in rows] for n in names}), json.loads(header)["wbfriction"])

    def write(self, table: pa.Table, path: Path) -> None:
        with open(path, "w") as handle:
            handle.write(json.dumps({"wbfriction": read_metadata(table)}) + "\n")
            handle.writelines(json.dumps(row) + "\n" for row in table.to_pylist())


@pytest.fixture
def jsonl():
    fmt = register_format(JsonLines())
    yield fmt
    unregister_format(fmt.name)


@pytest.fixture(scope="module")
def panda_log(tmp_path_factory) -> Path:
    """A simulated Panda log of 3 s in Parquet (as ``tests/fleet/conftest.py``'s ``arm_log``)."""
    robot = load_robot("panda")
    sim = simulate_arm(robot, default_arm_friction(robot), options=ArmOptions(duration=3.0, seed=1, torque_std=0.01))
    path = tmp_path_factory.mktemp("formats") / "arm.parquet"
    write_table(sim.table, path)
    return path


def _without(meta: dict, *keys: str) -> dict:
    return {k: v for k, v in meta.items() if k not in keys}


def test_a_format_registered_with_one_call_is_estimated_as_parquet(jsonl, panda_log, tmp_path):
    robot = load_robot("panda")
    log = tmp_path / "arm.jsonl"
    write_table(pq.read_table(panda_log), log)  # written by the format that claims the name
    assert log.read_text().startswith('{"wbfriction": ') and format_of(log) is jsonl
    assert open_log(log).format is jsonl and TableFile(log).read().equals(pq.read_table(panda_log))

    options = EstimateOptions()
    ref, got = (estimate_log(robot, read_log(p, robot), options) for p in (panda_log, log))
    for name in ("tau_f", "qd", "qdd", "valid", "delta_qdd"):
        np.testing.assert_array_equal(getattr(got, name), getattr(ref, name), err_msg=name)
    assert _without(got.metadata, "source") == _without(ref.metadata, "source")

    chunking = Chunking(rows=1000, workers=1)  # the chunks read by row ranges of the table read whole once
    for p, out in ((panda_log, tmp_path / "ref.parquet"), (log, tmp_path / "got.parquet")):
        estimate_file(RobotSpec("panda"), p, out, options, chunking=chunking)
    ref_table, got_table = pq.read_table(tmp_path / "ref.parquet"), pq.read_table(tmp_path / "got.parquet")
    assert got_table.schema.remove_metadata() == ref_table.schema.remove_metadata()
    for name in ref_table.column_names:  # NaN where nothing is estimated: equal as arrays, not as Arrow values
        got_column, ref_column = (t.column(name).to_numpy(zero_copy_only=False) for t in (got_table, ref_table))
        np.testing.assert_array_equal(got_column, ref_column, err_msg=name)
    assert _without(read_metadata(got_table), "source") == _without(read_metadata(ref_table), "source")


def test_the_registry_names_the_file_and_the_formats_it_knows(jsonl, tmp_path):
    (tmp_path / "log.txt").write_text("time\n0\n")
    with pytest.raises(UnknownFormatError) as err:
        format_of(tmp_path / "log.txt")
    assert (err.value.path, err.value.suffix) == (str(tmp_path / "log.txt"), ".txt")
    assert "JSON lines .jsonl" in err.value.known and str(err.value).startswith(
        f"{tmp_path / 'log.txt'}: unknown file type '.txt' (known formats: Parquet .parquet .pq; CSV .csv; ")
    assert [f.name for f in log_formats()] == ["parquet", "csv", "hdf5", "npz", "bag", "jsonl"]
    with pytest.raises(ValueError, match="named 'jsonl' is registered already"):
        register_format(JsonLines())

    class Other(JsonLines):
        name = "other"

    with pytest.raises(ValueError, match="claims .jsonl, which format 'jsonl' reads already"):
        register_format(Other())
    with pytest.raises(InputError, match="tables are streamed as .parquet, .pq, .csv"):
        write_tables(tmp_path / "x.jsonl", [pa.table({"x": [1.0]})])  # it writes whole tables only


def test_an_unregistered_format_is_unknown_again(tmp_path):
    fmt = register_format(JsonLines())
    write_table(pa.table({"time": [0.0, 0.001]}), tmp_path / "t.jsonl")
    assert unregister_format(fmt.name) is fmt
    with pytest.raises(InputError, match="unknown file type '.jsonl'"):
        read_table(tmp_path / "t.jsonl")


def test_numpy_archives_hold_a_log_one_array_per_column(tmp_path):
    table = with_metadata(pa.table({"time": np.arange(5) * 1e-3, "q.j": np.linspace(0, 1, 5),
                                    "contact.f": np.ones(5, dtype=np.int8)}), {"torque_alignment": "sample"})
    write_table(table, tmp_path / "log.npz")
    back = TableFile(tmp_path / "log.npz")
    assert back.format.name == "npz" and back.read().equals(table) and back.metadata() == {"torque_alignment": "sample"}
    assert back.read(["q.j", "missing"]).column_names == ["q.j"]
    assert [b.num_rows for b in back.blocks(2)] == [2, 2, 1]
    np.savez(tmp_path / "odd.npz", time=np.arange(5.0), q=np.zeros((5, 2)))
    with pytest.raises(InputError, match="array 'q' has shape"):
        read_table(tmp_path / "odd.npz")
    np.savez(tmp_path / "rec.npz", times=np.arange(5.0), positions=np.zeros((5, 2)))
    with pytest.raises(InputError, match="a FloBaRoID recording .*read_npz_recordings"):
        read_table(tmp_path / "rec.npz")


def test_a_bag_is_no_table_file_and_is_never_written(tmp_path):
    (tmp_path / "bag").mkdir()
    (tmp_path / "bag" / "metadata.yaml").write_text("")
    assert format_of(tmp_path / "bag").name == "bag"
    with pytest.raises(InputError, match="is not a table file: convert it first"):
        TableFile(tmp_path / "bag")
    with pytest.raises(InputError, match="ROS 2 bag files are read, not written"):
        write_table(pa.table({"x": [1.0]}), tmp_path / "x.mcap")
    (tmp_path / "folder").mkdir()
    with pytest.raises(InputError, match="is a folder, not a table file"):
        format_of(tmp_path / "folder")


def test_the_catalogue_the_help_reads_is_the_registrys(jsonl):
    """The command line's help names the formats from their catalogue (:mod:`wbfriction.logs.formats.catalog`),
    which loads no format and no pyarrow: what it holds before the registry is imported is what the registry's
    formats are after (a fresh process), so a built-in format cannot be missing from the help; a format registered
    or unregistered joins or leaves it (here)."""
    import subprocess
    import sys

    from wbfriction.logs.formats.catalog import FormatKind, format_kinds

    code = ("import sys\nfrom wbfriction.logs.formats.catalog import FormatKind, format_kinds\n"
            "before = format_kinds()\nassert 'pyarrow' not in sys.modules\n"
            "from wbfriction.logs.formats.registry import log_formats\n"
            "assert before == format_kinds() == tuple(FormatKind.of(f) for f in log_formats()), before\n"
            "print(' '.join(k.name for k in before))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["parquet", "csv", "hdf5", "npz", "bag"]
    assert format_kinds()[-1] == FormatKind.of(jsonl) and FormatKind.of(jsonl).words() == "JSON lines (.jsonl)"
    unregister_format(jsonl.name)
    assert jsonl.name not in [k.name for k in format_kinds()]
    register_format(jsonl)  # as the fixture left it
