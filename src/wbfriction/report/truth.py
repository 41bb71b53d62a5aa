"""What a demo prints of values found against the truth a simulation injected: per joint a row of each value with its
standard error (dim where one is not ``ok``) and a row of the truth below it, then a line naming those not ``ok``
(:mod:`wbfriction.rigs`' demos)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from rich.table import Table
from rich.text import Text

Found = tuple[float, float, float, str]
"""One value found: its value, its standard error, the truth, its status."""
Column = tuple[str, str, float]
"""A column: the value's name, its unit, the scale it is shown at (1e3: g·m² of kg·m²)."""


def number(x: float) -> str:
    """``x`` in three significant digits, never in exponent form above 1000 (``1234``, ``0.0123``, ``inf``)."""
    return ("inf" if x > 0 else "-inf") if math.isinf(x) else f"{x:.0f}" if abs(x) >= 1000 else f"{x:.3g}"


def found_text(value: float, se: float, scale: float = 1.0) -> str:
    """``value ± se`` scaled by ``scale``, the error to one significant digit (:func:`number` above 10)."""
    se_text = number(se * scale) if not math.isfinite(se) or se * scale >= 10 else f"{se * scale:.1g}"
    return f"{number(value * scale)} ± {se_text}"


def truth_table(title: str, columns: Sequence[Column], rows: Mapping[str, Sequence[Found]]) -> Table:
    """A table of ``rows`` (joint -> one :data:`Found` per column of ``columns``), a row dim where a value is not
    ``ok``; under each joint's row, the truth's."""
    table = Table(title=title, box=None)
    table.add_column("joint")
    for name, unit, _ in columns:  # Text: a unit in brackets is no markup
        table.add_column(Text(f"{name} [{unit}]"), justify="right")
    for joint, found in rows.items():
        pairs = list(zip(found, columns, strict=True))
        table.add_row(joint, *(found_text(f[0], f[1], scale) for f, (_, _, scale) in pairs),
                      style="dim" if any(f[3] != "ok" for f in found) else None)
        table.add_row("  true", *(number(f[2] * scale) for f, (_, _, scale) in pairs), style="dim")
    return table


def not_ok_line(columns: Sequence[Column], rows: Mapping[str, Sequence[Found]]) -> str:
    """``not ok: FL_calf_joint offset (weak), ...``, or ``every value ok``."""
    named = [f"{joint} {name} ({f[3]})" for joint, found in rows.items()
             for f, (name, _, _) in zip(found, columns, strict=True) if f[3] != "ok"]
    return "not ok: " + ", ".join(named) if named else "every value ok"
