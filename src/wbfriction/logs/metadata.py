"""A table's own metadata: one JSON object stored under the schema key ``wbfriction``.

Every log format keeps it (:mod:`wbfriction.logs.formats`): a Parquet file in its schema, a CSV file on its first
line, an HDF5 or NumPy file in a ``wbfriction`` entry. It carries what the numbers alone do not say: a simulator's
torque alignment and true friction, a friction table's smoother and provenance.
"""

from __future__ import annotations

import json

import pyarrow as pa

from wbfriction.exceptions import InputError

META_KEY = b"wbfriction"
"""The schema metadata key the JSON object is stored under."""


def with_metadata(table: pa.Table, metadata: dict) -> pa.Table:
    """``table`` with ``metadata`` (JSON-serialisable, keys sorted) under the ``wbfriction`` key."""
    return table.replace_schema_metadata({META_KEY: json.dumps(metadata, sort_keys=True).encode()})


def read_metadata(table: pa.Table, source: str = "<table>") -> dict:
    """The ``wbfriction`` metadata of a table ({} if none).

    Raises:
        InputError: metadata that is not a JSON object, naming ``source``.
    """
    meta = table.schema.metadata or {}
    if META_KEY not in meta:
        return {}
    try:
        doc = json.loads(meta[META_KEY])
    except ValueError:
        raise InputError(f"{source}: the 'wbfriction' metadata is not JSON") from None
    if not isinstance(doc, dict):
        raise InputError(f"{source}: the 'wbfriction' metadata is not a JSON object")
    return doc
