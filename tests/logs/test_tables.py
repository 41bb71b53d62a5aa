"""Table files read whole, by columns and by row ranges alike; documents written whole or not at all."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.formats.hdf5 import write_hdf5
from wbfriction.logs.tables import (
    TableFile,
    numeric_column,
    numeric_columns,
    read_metadata,
    with_metadata,
    write_json,
    write_table,
    write_tables,
)


@pytest.fixture(params=[".parquet", ".csv", ".h5"])
def table_file(request, tmp_path) -> tuple[TableFile, pa.Table]:
    rng = np.random.default_rng(0)
    table = with_metadata(pa.table({"time": np.arange(1000) * 1e-3, "a": rng.normal(size=1000),
                                    "b": rng.normal(size=1000)}), {"robot": "x"})
    path = tmp_path / f"t{request.param}"
    if request.param == ".h5":
        write_hdf5(table, path)
    else:
        write_table(table, path)
    return TableFile(path), table


def test_row_ranges_are_slices_of_the_whole(table_file):
    file, table = table_file
    whole = file.read()
    reader = file.row_reader(128)
    for start, stop in ((0, 10), (5, 300), (300, 301), (900, 1200)):
        part = reader.rows(start, stop)
        assert part.num_rows == min(stop, 1000) - start
        np.testing.assert_array_equal(part.column("a").to_numpy(), whole.column("a").to_numpy()[start:stop])
    assert sum(b.num_rows for b in file.blocks(300)) == 1000
    if file.format.name != "csv":  # CSV keeps no metadata
        assert read_metadata(whole) == {"robot": "x"}
        assert read_metadata(file.row_reader(10).rows(0, 5)) == {"robot": "x"}


def test_columns_read_alone(table_file):
    file, _ = table_file
    assert sorted(file.read(["b", "time", "missing"]).column_names) == ["b", "time"]
    assert file.row_count() == (1000 if file.format.name == "parquet" else 0)


def test_a_bad_column_names_its_file_column_and_row():
    table = pa.table({"x": [0.0, 1.0, np.nan], "s": ["a", "b", "c"]})
    with pytest.raises(ColumnError) as err:
        numeric_column(table, "x", "f.parquet", first_row=10)
    assert (err.value.source, err.value.column, err.value.row) == ("f.parquet", "x", 12)
    assert str(err.value) == "f.parquet: column 'x' has a non-finite value (NaN or inf) at row 12"
    with pytest.raises(ColumnError, match="column 's' is not numeric") as err:
        numeric_column(table, "s", "f.parquet")
    assert err.value.row is None and isinstance(err.value, InputError)


def test_json_documents_are_written_whole(tmp_path):
    write_json(tmp_path / "d.json", {"b": 1, "a": [1.5, None]})
    assert json.loads((tmp_path / "d.json").read_text()) == {"b": 1, "a": [1.5, None]}
    with pytest.raises(TypeError):
        write_json(tmp_path / "d.json", {"x": object()})  # not serialisable: the previous file is kept
    assert json.loads((tmp_path / "d.json").read_text()) == {"b": 1, "a": [1.5, None]}
    assert [p.name for p in tmp_path.iterdir()] == ["d.json"]


def test_float_columns_are_written_without_dictionary_and_read_back_bit_for_bit(tmp_path):
    """Floating-point columns skip Parquet's dictionary (signals rarely repeat a value), the others
    keep it; both writers give back the same table, bit for bit."""
    rng = np.random.default_rng(3)
    table = pa.table({"time": np.arange(500) * 1e-3, "x": rng.normal(size=500),
                      "phase": pa.array(["single", "double"] * 250), "flag": rng.random(500) > 0.5})
    for name, write in (("one.parquet", lambda p: write_table(table, p)),
                        ("streamed.parquet", lambda p: write_tables(p, [table.slice(0, 200), table.slice(200)]))):
        write(tmp_path / name)
        meta = pq.ParquetFile(tmp_path / name).metadata.row_group(0)
        encodings = {meta.column(i).path_in_schema: meta.column(i).encodings for i in range(meta.num_columns)}
        assert not any("DICTIONARY" in e for e in encodings["x"] + encodings["time"])
        assert any("DICTIONARY" in e for e in encodings["phase"])
        assert pq.read_table(tmp_path / name).equals(table)


def test_columns_read_as_one_array_are_the_columns_read_one_by_one():
    """Issue 41: :func:`numeric_columns` (Arrow casts and copies once) gives the bytes of the columns read one by
    one (integers, floats with a null, booleans; several chunks), and the same error: the first column at fault,
    its first bad row."""
    a = pa.chunked_array([pa.array([1, 2, 3], pa.int32()), pa.array([4], pa.int32())])
    b = pa.chunked_array([pa.array([0.5, None, 2.5, 3.5])])
    c = pa.chunked_array([pa.array([True, False]), pa.array([True, True])])
    table = pa.table({"a": a, "b": b, "c": c})
    names = ["c", "a", "b"]
    one_by_one = np.column_stack([numeric_column(table, n, "log", finite=False) for n in names])
    assert numeric_columns(table, names, "log", finite=False).tobytes() == one_by_one.tobytes()
    with pytest.raises(InputError) as many:
        numeric_columns(table, names, "log", first_row=10)
    with pytest.raises(InputError) as single:
        numeric_column(table, "b", "log", first_row=10)
    assert str(many.value) == str(single.value) and "row 11" in str(many.value)


def test_a_json_written_holds_no_nan_nor_infinity(tmp_path):
    """Issue 63: every number that is not finite, NumPy's and nested ones too, is written ``null``; finite numbers,
    booleans, integers and text as they were (NumPy's as plain numbers)."""
    from helpers import strict_json
    from wbfriction.logs.tables import write_json

    doc = {"a": float("nan"), "b": [1.5, float("inf"), -np.inf, np.float64("nan")], "c": {"d": np.float32(2.5)},
           "e": (np.int64(3), True, np.bool_(False), "x", None), "f": np.array([0.25, np.nan])}
    write_json(tmp_path / "d.json", doc)
    assert strict_json(tmp_path / "d.json") == {"a": None, "b": [1.5, None, None, None], "c": {"d": 2.5},
                                                 "e": [3, True, False, "x", None], "f": [0.25, None]}
    with pytest.raises(pytest.fail.Exception, match="NaN"):
        (tmp_path / "bad.json").write_text(json.dumps({"a": float("nan")}))
        strict_json(tmp_path / "bad.json")
