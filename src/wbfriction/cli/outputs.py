"""Every file a command writes, checked by its suffix as the command line is parsed (before any work, before the
robot is loaded), and listed in the help from the same registry (:mod:`wbfriction.pipeline.outputs`): an option
declared ``callback=written_as("table")`` refuses ``-o x.txt`` in one line naming the option, the suffix and the
suffixes a table is written as, and its help says :func:`suffixes` of the same kind."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import typer

from wbfriction.pipeline.outputs import check_output, output_kind


def written_as(kind: str) -> Callable[..., Any]:
    """The option callback that refuses each file the option names (one, or a list: ``excite -o A -o B``) whose
    suffix the kind of document ``kind`` is not written as (:func:`~wbfriction.pipeline.outputs.check_output`); an
    option not given (None) passes.

    Raises:
        OutputSuffixError: as the option is parsed, naming it as the command line spells it first (``-o``).
    """
    def check(param: typer.CallbackParam, value: Any) -> Any:
        if value is not None:
            option = param.opts[0] if param.opts else str(param.name)
            for path in value if isinstance(value, (list, tuple)) else (value,):
                check_output(option, path, kind)
        return value

    return check


def suffixes(kind: str) -> str:
    """The suffixes the kind of document ``kind`` is written as, as the help lists them (``.parquet, .pq or .csv``):
    read from its writers' registry as the command line is loaded."""
    return output_kind(kind).words()
