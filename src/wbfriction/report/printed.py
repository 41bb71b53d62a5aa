"""One thing a command prints on standard output, as an operation returns it for the command line to print: what
the operations of the rigs (:mod:`wbfriction.rigs`) give back."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Printed:
    """One thing printed on standard output.

    Attributes:
        item: a line (a string, printed without highlighting; escape what must not be read as markup) or a rich
            renderable (a table).
        whole: printed as wide as it takes, nothing cut (a table of a few rows whose numbers must not be cut).
        soft_wrap: a long line left to the terminal to wrap (a Markdown block).
    """

    item: Any
    whole: bool = False
    soft_wrap: bool = False
