"""HDF5 (``.h5``, ``.hdf5``, ``.he5``; ``h5py``): the log format's columns in an HDF5 file, read by row ranges
(its datasets sliced), written whole.

Two layouts are read (the first that applies):

1. **One 2-D dataset with a names attribute**: a dataset of shape (N, C) whose attribute
   ``names`` (or ``columns``) lists the C column names of the log format (``time``,
   ``q.<joint>``, ...).
2. **One 1-D dataset per column**: every 1-D dataset of length N in the file is a column;
   its path names it, with ``/`` read as ``.`` (so ``q/leg_left_1_joint`` and a dataset
   named ``q.leg_left_1_joint`` are the same column).

A JSON string is the log's metadata: the scalar dataset ``wbfriction`` (a fixed-length byte string,
what :func:`write_hdf5` writes), else the file attribute ``wbfriction`` (older files, other writers).
:func:`write_hdf5` writes layout 2, one dataset per column.

Why a fixed-length string in a dataset: a variable-length string lives in the file's global heap, and
HDF5 reading one from a damaged heap can loop for ever (seen with h5py 3 on a file with bytes flipped
in its heap: ``f.attrs["wbfriction"]`` never returned); a fixed-length one is read as its bytes, and a
dataset has no 64 KiB limit as an attribute does.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.logs.formats.base import LogFormat, RowReader
from wbfriction.logs.formats.catalog import HDF5
from wbfriction.logs.metadata import META_KEY

NAMES_ATTRS = ("names", "columns")
META = "wbfriction"
"""Name of the metadata's scalar dataset (and of the attribute older files carry)."""


def _names(attr) -> list[str]:
    return [n.decode() if isinstance(n, bytes) else str(n) for n in np.atleast_1d(attr)]


def _layout(f, path: Path) -> tuple[dict[str, tuple[Any, int | None]], str | None]:
    """Column name -> (dataset, column index in a 2-D dataset or None), and the metadata."""
    import h5py

    stored = f.get(META)
    meta = stored[()] if isinstance(stored, h5py.Dataset) and stored.ndim == 0 else f.attrs.get(META)
    datasets: list[tuple[str, Any]] = []  # h5py.Dataset (h5py has no type hints)
    f.visititems(lambda name, obj: datasets.append((name, obj)) if isinstance(obj, h5py.Dataset) else None)
    cols: dict[str, tuple[Any, int | None]] = {}
    for name, ds in datasets:
        attr = next((ds.attrs[a] for a in NAMES_ATTRS if a in ds.attrs), None)
        if attr is not None and ds.ndim == 2:
            names = _names(attr)
            if len(names) != ds.shape[1]:
                raise InputError(f"{path}: dataset '{name}' has {ds.shape[1]} columns but its names "
                                 f"attribute lists {len(names)}")
            cols = {n: (ds, i) for i, n in enumerate(names)}
            break
    else:
        for name, ds in datasets:
            if ds.ndim != 1 or ds.dtype.kind not in "biuf":
                continue
            col = name.replace("/", ".")
            if col in cols:
                raise InputError(f"{path}: column '{col}' is given twice")
            cols[col] = (ds, None)
    if not cols:
        raise InputError(f"{path}: no 1-D numeric dataset and no 2-D dataset with a 'names' attribute")
    lengths = {n: ds.shape[0] for n, (ds, _) in cols.items()}
    first = next(iter(lengths))
    odd = next((n for n, k in lengths.items() if k != lengths[first]), None)
    if odd is not None:
        raise InputError(f"{path}: column '{odd}' has {lengths[odd]} rows, column '{first}' {lengths[first]}")
    return cols, (meta.decode() if isinstance(meta, bytes) else meta) if meta is not None else None


def read_hdf5(path: str | Path, columns: list[str] | None = None, start: int = 0, stop: int | None = None) -> pa.Table:
    """An HDF5 log as an Arrow table (module docstring for the layouts), or a part of it.

    Args:
        path: the file.
        columns: the columns to read (those present; default all).
        start, stop: the rows to read, ``[start, stop)`` (default all): a long log is read in
            chunks without loading the rest.

    Raises:
        InputError: unreadable file, no usable dataset, a names attribute that does not
            match its dataset, columns of different lengths, or a column named twice.
    """
    import h5py

    path = Path(path)
    try:
        with h5py.File(path, "r") as f:
            layout, metadata = _layout(f, path)
            wanted = [c for c in layout if columns is None or c in columns]
            rows = slice(start, stop)
            blocks: dict[int, np.ndarray] = {}  # a 2-D dataset is read once per call
            cols: dict[str, np.ndarray] = {}
            for c in wanted:
                ds, i = layout[c]
                if i is None:
                    cols[c] = np.asarray(ds[rows], dtype=float)
                else:
                    if id(ds) not in blocks:
                        blocks[id(ds)] = np.asarray(ds[rows], dtype=float)
                    cols[c] = blocks[id(ds)][:, i]
    except InputError:
        raise
    except (OSError, ValueError, TypeError, KeyError, RuntimeError) as exc:
        raise InputError(f"{path}: not a readable HDF5 log: "
                         f"{str(exc).splitlines()[0] if str(exc) else exc!r}") from None
    table = pa.table(cols)
    if metadata:
        try:
            json.loads(metadata)
        except (json.JSONDecodeError, TypeError):
            raise InputError(f"{path}: the 'wbfriction' attribute is not JSON") from None
        table = table.replace_schema_metadata({META_KEY: metadata.encode()})
    return table


def write_hdf5(table: pa.Table, path: str | Path) -> None:
    """Write a table as HDF5, one dataset per column (layout 2), metadata as the file
    attribute ``wbfriction``. Not atomic by itself: use
    :func:`~wbfriction.logs.tables.write_table`.

    Raises:
        OSError: the system refused the write, with the OS's error number (HDF5 raises a RuntimeError
            or an OSError without one, the number in its message).
    """
    import h5py

    try:
        with h5py.File(path, "w") as f:
            for name in table.column_names:
                data = table.column(name).to_numpy(zero_copy_only=False)
                if data.dtype == object:  # strings (a friction table's phase): fixed-length bytes
                    data = data.astype(str).astype("S")
                f.create_dataset(name, data=data, track_times=False)  # no timestamps: same input, same bytes
            meta = (table.schema.metadata or {}).get(META_KEY)
            if meta is not None:
                f.create_dataset(META, data=np.bytes_(meta), track_times=False)
    except (OSError, RuntimeError) as exc:  # HDF5 words the OS's error in its message: "errno = 28"
        number = getattr(exc, "errno", None)
        found = re.search(r"errno = (\d+)", str(exc))
        if not isinstance(number, int) and found:
            number = int(found[1])
            raise OSError(number, os.strerror(number)) from exc
        raise


class Hdf5Rows:
    """Row ranges of an HDF5 file, each read by slicing its datasets (:func:`read_hdf5`)."""

    def __init__(self, path: Path):
        self.path = path
        self.metadata: dict[bytes, bytes] | None = read_hdf5(path, columns=[], stop=0).schema.metadata

    def rows(self, start: int, stop: int) -> pa.Table:
        return read_hdf5(self.path, start=start, stop=stop)


class Hdf5Format(LogFormat, kind=HDF5):
    """HDF5 files (module docstring): ``.h5``, ``.hdf5``, ``.he5``, written whole."""

    def read(self, path: Path, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        return read_hdf5(path, columns=columns)

    def schema(self, path: Path) -> pa.Schema:
        return read_hdf5(path, stop=0).schema

    def row_reader(self, path: Path, batch_rows: int) -> RowReader:
        return Hdf5Rows(path)

    def write(self, table: pa.Table, path: Path) -> None:
        write_hdf5(table, path)
