"""Typed options read by name: the frozen dataclasses whose fields are the options a kind reads (a rig's, an
engine's), built from the values a user gave, each number checked against its quantity's range
(:mod:`wbfriction.quantities`).

A field is an option of the command line of the same name (``excitation_seed`` is ``--excitation-seed``) or, for an
option no command spells, ``--rig-option excitation_seed=3``. Its default is the one place the option's default is
written; its metadata names the quantity whose range a given value must lie in::

    @dataclass(frozen=True)
    class ArmSimulation:
        duration: float = option(10.0, quantity="duration")
        excitation_seed: int = option(0, quantity="seed")

This module imports only the standard library: the command line reads the fields as it is loaded.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

from wbfriction.exceptions import InputError
from wbfriction.quantities import check_option

T = TypeVar("T")

__all__ = ["option", "option_names", "motion_names", "read_options", "parse_option", "flag_of"]


def option(default: Any = dataclasses.MISSING, *, quantity: str | None = None, motion: bool = False) -> Any:
    """A field of an options dataclass: its ``default`` (a tuple, not a list: the dataclass is frozen), the
    ``quantity`` of :data:`~wbfriction.quantities.RANGES` a given value must lie in (None: not a physical number),
    and whether it shapes the motion (``motion``: what a played set-points table fixes, refused beside it)."""
    return dataclasses.field(default=default, metadata={"quantity": quantity, "motion": motion})


def motion_names(cls: type | None) -> tuple[str, ...]:
    """The options of ``cls`` that shape the motion (:func:`option`'s ``motion``)."""
    return () if cls is None else tuple(f.name for f in dataclasses.fields(cls) if f.metadata.get("motion"))


def option_names(cls: type | None) -> tuple[str, ...]:
    """The options ``cls`` (a dataclass, or None: none) reads: its fields' names, in order."""
    return () if cls is None else tuple(f.name for f in dataclasses.fields(cls))


def flag_of(name: str) -> str:
    """The command line's spelling of the option ``name``: ``--excitation-seed``."""
    return "--" + name.replace("_", "-")


def read_options(cls: type[T], given: Mapping[str, Any]) -> T:
    """``cls`` built from the values ``given`` by option name: the fields given take their value, the others their
    default; a value of a field with a quantity is checked against its range first. Names that are not fields are
    not read (the caller refused them).

    Raises:
        OptionError: a value outside its quantity's range, naming the option (:func:`flag_of`).
        InputError: what ``cls`` raises of the values together.
    """
    values = {}
    for f in dataclasses.fields(cls):  # type: ignore[arg-type]
        if f.name in given:
            if f.metadata.get("quantity") is not None:
                check_option(flag_of(f.name), f.metadata["quantity"], given[f.name])
            values[f.name] = given[f.name]
    return cls(**values)


def parse_option(classes: tuple[type, ...], text: str) -> tuple[str, Any]:
    """``--rig-option NAME=VALUE``: the option's name and its value read as its field's type, among the fields of
    ``classes`` (``bool``: true/false/1/0/yes/no; a path; a number; a tuple: comma-separated; a choice: one of its
    values).

    Raises:
        InputError: not ``NAME=VALUE``; a name none of ``classes`` has (listing theirs); a value not of the type.
    """
    name, sep, raw = text.partition("=")
    name = name.strip().replace("-", "_")
    if not sep or not name:
        raise InputError(f"--rig-option {text!r}: NAME=VALUE")
    for cls in classes:
        hints = typing.get_type_hints(cls)
        if name in hints:
            try:
                return name, _typed(hints[name], raw.strip())
            except (TypeError, ValueError):
                raise InputError(f"--rig-option {name}={raw}: not a {_type_name(hints[name])}") from None
    listed = ", ".join(n for cls in classes for n in option_names(cls))
    raise InputError(f"--rig-option {name}: not an option here (the options: {listed})")


def _typed(kind: Any, raw: str) -> Any:
    """``raw`` read as the type ``kind``."""
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin in (typing.Union, types.UnionType):
        if raw.lower() == "none" and type(None) in args:
            return None
        return _typed(next(a for a in args if a is not type(None)), raw)
    if origin is typing.Literal:
        if raw not in args:
            raise ValueError(raw)
        return raw
    if origin is tuple:
        parts = [p.strip() for p in raw.split(",") if p.strip()]
        items = args[:1] * len(parts) if len(args) == 2 and args[1] is Ellipsis else args
        if len(items) != len(parts):
            raise ValueError(raw)
        return tuple(_typed(a, p) for a, p in zip(items, parts, strict=True))
    if kind is bool:
        if raw.lower() not in ("true", "false", "1", "0", "yes", "no"):
            raise ValueError(raw)
        return raw.lower() in ("true", "1", "yes")
    if kind in (int, float, str, Path):
        return kind(raw)
    raise TypeError(kind)


def _type_name(kind: Any) -> str:
    """A type as a refusal names it."""
    return getattr(kind, "__name__", None) or str(kind).replace("typing.", "")
