"""Checks of an option's value where its options class is defined (its ``__post_init__``), in a module that
imports only the standard library: the options modules stay light enough for the command line's help."""

from __future__ import annotations

from collections.abc import Iterable

from wbfriction.exceptions import OptionError


def spoken(items: tuple[str, ...]) -> str:
    """``a, b or c`` (a message's or a help's list of choices)."""
    return items[0] if len(items) == 1 else f"{', '.join(items[:-1])} or {items[-1]}"


def flag(field: str) -> str:
    """The command-line spelling of an options field: ``poly_order`` -> ``--poly-order``."""
    return "--" + field.replace("_", "-")


def check_choice(field: str, value: object, choices: Iterable[str]) -> None:
    """Refuse a ``value`` of the options field ``field`` that is not one of ``choices``.

    Raises:
        OptionError: naming the option (:func:`flag`) and its choices.
    """
    choices = tuple(choices)
    if value not in choices:
        raise OptionError(flag(field), value, f"one of {', '.join(choices)}")


def check_range(field: str, value: float | int, *, low: float | None = None, high: float | None = None,
                strict: bool = False) -> None:
    """Refuse a ``value`` of the options field ``field`` below ``low`` or above ``high`` (``strict``: also equal
    to either).

    Raises:
        OptionError: naming the option (:func:`flag`) and its range.
    """
    below = low is not None and (value <= low if strict else value < low)
    above = high is not None and (value >= high if strict else value > high)
    if below or above:
        lo = "" if low is None else (f"> {low:g}" if strict else f">= {low:g}")
        hi = "" if high is None else (f"< {high:g}" if strict else f"<= {high:g}")
        raise OptionError(flag(field), value, " and ".join(x for x in (lo, hi) if x))
