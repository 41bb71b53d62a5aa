"""NumPy archives (``.npz``): a log as one named array per column, or FloBaRoID's recordings.

**A log** (:class:`NpzFormat`) is an archive of 1-D arrays of one length N, each named as its column (``time``,
``q.<joint>``, ...: ``numpy.savez(path, **columns)``), read whole and written whole; its metadata is the JSON
object in the 0-d byte-string array ``wbfriction``.

**FloBaRoID** (https://github.com/kjyv/FloBaRoID) saves a robot's recording as one ``.npz`` archive of arrays, N
samples by the J joints in a fixed order:

* ``times`` (N,): the stamps [s] as the recorder wrote them (Unix epoch seconds for the KUKA LWR4+);
* ``positions`` (N, J) [rad], ``velocities`` (N, J) [rad/s] (filtered by the controller), ``torques``
  (N, J) [N·m] (the joint torque sensors);
* other arrays (``accelerations``, the controller's ``target_*``), which are not read.

:func:`read_npz_recordings` turns one or more of them into the log format's table (``time``,
``q.<joint>``, ``tau.<joint>``, ``qd.<joint>``). Nothing is changed: no filter, no resampling, the
stamps untouched (:mod:`wbfriction.logs.clock` decides how to read them). Recordings given together
are put one after the other; the time between them is a gap that splits the log into segments, which
are estimated apart.
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.exceptions import InputError
from wbfriction.logs.formats.base import LogFormat
from wbfriction.logs.formats.catalog import NPZ
from wbfriction.logs.metadata import META_KEY

TIME_KEY = "times"
"""The array of stamps [s], shape (N,)."""

JOINT_KEYS = (("q", "positions"), ("tau", "torques"), ("qd", "velocities"))
"""Column prefix of the log format -> array of the recording, shape (N, J), joints in order: positions
[rad], torques [N·m], velocities [rad/s]."""


def _load(path: Path) -> dict[str, np.ndarray]:
    """The arrays of ``path`` that are read (:data:`TIME_KEY`, :data:`JOINT_KEYS`), as float64."""
    wanted = (TIME_KEY, *(key for _, key in JOINT_KEYS))
    try:
        archive = np.load(path, allow_pickle=False)
        if not isinstance(archive, np.lib.npyio.NpzFile):
            raise InputError(f"{path}: a single array, not an .npz archive of named arrays")
        with archive:
            missing = [key for key in wanted if key not in archive.files]
            if missing:
                raise InputError(f"{path}: no array '{missing[0]}' (it holds {', '.join(archive.files) or 'none'}; "
                                 f"a recording holds {', '.join(wanted)})")
            arrays = {key: archive[key] for key in wanted}
    except InputError:
        raise
    except FileNotFoundError as exc:
        raise InputError(f"{path}: file not found") from exc
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise InputError(f"{path}: not a readable .npz archive ({reason})") from exc
    out = {}
    for key, values in arrays.items():
        if not (np.issubdtype(values.dtype, np.floating) or np.issubdtype(values.dtype, np.integer)):
            raise InputError(f"{path}: '{key}' holds {values.dtype} values, not numbers")
        out[key] = np.asarray(values, dtype=np.float64)
    return out


def _recording_table(path: Path, joints: Sequence[str]) -> pa.Table:
    """One recording as a log table, its arrays' shapes checked."""
    arrays = _load(path)
    time = arrays[TIME_KEY]
    if time.ndim != 1 or len(time) == 0:
        raise InputError(f"{path}: '{TIME_KEY}' has shape {time.shape}, expected (N,) with N > 0 samples")
    columns = {"time": time}
    for prefix, key in JOINT_KEYS:
        values = arrays[key]
        if values.shape != (len(time), len(joints)):
            raise InputError(f"{path}: '{key}' has shape {values.shape}, expected ({len(time)}, {len(joints)}): "
                             f"one row per stamp of '{TIME_KEY}', one column per joint")
        columns.update({f"{prefix}.{joint}": values[:, i] for i, joint in enumerate(joints)})
    return pa.table(columns)


def read_npz_recordings(paths: Sequence[str | Path], joints: Sequence[str]) -> pa.Table:
    """Recordings in FloBaRoID's ``.npz`` layout as one log table, one row per recorded sample.

    Args:
        paths: the recordings, in the order they were recorded (their stamps follow each other).
        joints: the names of the recordings' columns, in order (for the KUKA LWR4+ ``lwr_0_joint`` ...
            ``lwr_6_joint``, :data:`wbfriction.datasets.KUKA_LWR4_JOINTS`).

    Returns:
        The columns ``time`` [s] (the stamps as recorded), ``q.<joint>`` [rad], ``tau.<joint>`` [N·m] and
        ``qd.<joint>`` [rad/s], float64, the recordings' rows one after the other.

    Raises:
        InputError: one line naming the file and the array at fault: a file not found or not an ``.npz``
            archive, an array missing or not numeric, ``times`` not one-dimensional or empty, an array whose
            shape is not (samples, joints); a recording whose first stamp is not after the previous one's
            last; no recording or no joint given, or a joint named twice.
    """
    if not paths:
        raise InputError("no .npz recording given")
    if not joints or len(set(joints)) != len(joints):
        raise InputError(f"the recordings' joints must be named once each, got {list(joints)}")
    tables: list[pa.Table] = []
    previous: Path | None = None
    for path in map(Path, paths):
        table = _recording_table(path, joints)
        if tables:
            last, first = tables[-1]["time"][-1].as_py(), table["time"][0].as_py()
            if not first > last:
                raise InputError(f"{path}: '{TIME_KEY}' starts at {first!r} s, not after the end of {previous} "
                                 f"({last!r} s): give the recordings in the order they were recorded")
        tables.append(table)
        previous = path
    return pa.concat_tables(tables)


class NpzFormat(LogFormat, kind=NPZ):
    """NumPy archives holding a log, one named array per column (module docstring): ``.npz``, written whole."""

    def read(self, path: Path, columns: list[str] | None = None, text_columns: Sequence[str] = ()) -> pa.Table:
        """The log in ``path`` (or those of ``columns`` it has), its metadata in its schema.

        Raises:
            InputError: not an ``.npz`` archive of named arrays, a FloBaRoID recording (read by
                :func:`read_npz_recordings`, given its joints' names), an array that is not 1-D or of another length
                than the first, metadata that is not JSON.
        """
        key = META_KEY.decode()
        try:
            archive = np.load(path, allow_pickle=False)
            if not isinstance(archive, np.lib.npyio.NpzFile):
                raise InputError(f"{path}: a single array, not an .npz archive of named arrays")
            with archive:
                names = [n for n in archive.files if n != key]
                if TIME_KEY in names and "time" not in names:
                    raise InputError(f"{path}: a FloBaRoID recording (arrays {', '.join(names)}), not a log: read it "
                                     "with wbfriction.logs.read_npz_recordings, given its joints' names")
                arrays = {n: archive[n] for n in names if columns is None or n in columns}
                meta = archive[key] if key in archive.files else None
        except InputError:
            raise
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            reason = " ".join(str(exc).split()) or type(exc).__name__
            raise InputError(f"{path}: not a readable .npz archive ({reason})") from exc
        shapes = {name: values.shape for name, values in arrays.items()}
        first = next(iter(shapes.values()), (0,))
        odd = next((name for name, shape in shapes.items() if len(shape) != 1 or shape != first), None)
        if odd is not None:
            raise InputError(f"{path}: array '{odd}' has shape {shapes[odd]}, the first {first}: a log holds one "
                             "1-D array of one length per column")
        table = pa.table(arrays)
        if meta is None:
            return table
        text = meta.item() if meta.ndim == 0 and meta.dtype.kind == "S" else b""
        try:
            json.loads(text)
        except ValueError:
            raise InputError(f"{path}: the '{key}' array is not JSON") from None
        return table.replace_schema_metadata({META_KEY: text})

    def write(self, table: pa.Table, path: Path) -> None:
        arrays = {n: table.column(n).to_numpy(zero_copy_only=False) for n in table.column_names}
        meta = (table.schema.metadata or {}).get(META_KEY)
        if meta is not None:
            arrays[META_KEY.decode()] = np.bytes_(meta)
        with open(path, "wb") as handle:
            np.savez(handle, **arrays)
