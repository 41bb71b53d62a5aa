"""Where a command reads and writes, checked before any work: inputs exist, outputs can be
written whole and never replace an input.

Every output is written whole or not at all (:func:`~wbfriction.logs.tables.write_atomic`),
but a run that can only fail at its end (an output folder that does not exist, or that cannot
be written) wastes the user's time, and one whose output is its own input destroys the data.
:func:`check_paths` refuses both before anything is read.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Mapping
from pathlib import Path

from wbfriction.exceptions import InputError, OptionError


def _same(a: Path, b: Path) -> bool:
    """``a`` and ``b`` are one file (the same path, or two names of one existing file)."""
    if a.resolve() == b.resolve():
        return True
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_paths(inputs: Mapping[str, Path | None], outputs: Mapping[str, Path | None],
                folders: Mapping[str, Path | None] | None = None) -> None:
    """Refuse, before any work, a missing input, an output that cannot be written whole, and an
    output that is an input or another output.

    Args:
        inputs: the files read, by the argument or option that names them (e.g.
            ``{"LOG": log, "--params": params}``; None: not given).
        outputs: the files written, likewise (e.g. ``{"-o": output, "--json": json}``).
        folders: the folders written into, made with their parents where missing (``{"-o": output_dir}``).

    Raises:
        InputError: naming the option and the path: an input that does not exist; an output
            that is a folder, in a folder that does not exist or cannot be written, equal to an
            input (inputs are never overwritten) or to another output.
        OutputError: a folder that is a file, under a file, or that cannot be made or written.
    """
    for folder in (folders or {}).values():
        if folder is not None:
            _check_folder(Path(folder))
    given_in = {k: Path(v) for k, v in inputs.items() if v is not None}
    given_out = {k: Path(v) for k, v in outputs.items() if v is not None}
    for label, path in given_in.items():
        if not path.exists():
            raise InputError(f"{path}: file not found ({label})")
    seen: dict[str, Path] = {}
    for label, path in given_out.items():
        if path.is_dir():
            raise InputError(f"{label} {path}: is a folder; give the file to write")
        folder = path.parent
        if not folder.is_dir():
            raise InputError(f"{label} {path}: folder '{folder}' does not exist")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise InputError(f"{label} {path}: folder '{folder}' cannot be written")
        for in_label, source in given_in.items():
            if _same(path, source):
                raise InputError(f"{label} {path}: is the input {in_label}; write to another file "
                                 "(inputs are never overwritten)")
        for other_label, other in seen.items():
            if _same(path, other):
                raise InputError(f"{label} {path}: is also the output {other_label}")
        seen[label] = path


def _check_folder(folder: Path) -> None:
    """Refuse an output folder that is a file, lies under one, or cannot be made or written (the nearest folder
    that exists is the one written into), as making it would (:func:`~wbfriction.logs.tables.make_folder`: the
    same :class:`~wbfriction.exceptions.OutputError`), before the work."""
    existing = folder
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        number = errno.EEXIST if existing == folder else errno.ENOTDIR
    elif not os.access(existing, os.W_OK | os.X_OK):
        number = errno.EACCES
    else:
        return
    from wbfriction.logs.tables import output_error  # the command line loads this module: pyarrow only on a refusal

    raise output_error(folder, OSError(number, os.strerror(number)))


OUTPUT_OPTIONS = ("-o", "--output", "--output-dir", "--json", "--table", "--tables", "--config-output", "--figure")
"""The options that name what a command writes."""


def refuse_empty_outputs(argv: list[str]) -> None:
    """Refuse an output option given an empty path (``-o ""``: it would write into the working folder, as
    ``Path("")`` is ``.``), before the command line is parsed.

    Raises:
        OptionError: naming the option.
    """
    for k, arg in enumerate(argv):
        name, eq, value = arg.partition("=")
        if name in OUTPUT_OPTIONS and ((eq and not value.strip()) or (not eq and k + 1 < len(argv)
                                                                      and not argv[k + 1].strip())):
            raise OptionError(name, "", "a file or folder to write, not an empty path")
