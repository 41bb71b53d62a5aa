"""TOML files the user gives (robot configuration, friction, sensors): read with one error type."""

from __future__ import annotations

import tomllib
from pathlib import Path

from wbfriction.exceptions import InputError


def read_toml(path: str | Path) -> dict:
    """The parsed document of a TOML file.

    Raises:
        InputError: the file cannot be read or is not valid TOML (the message names it).
    """
    path = Path(path)
    try:
        return tomllib.loads(path.read_text())
    except FileNotFoundError as exc:
        raise InputError(f"{path}: file not found") from exc
    except OSError as exc:
        raise InputError(f"{path}: {exc.strerror or exc}") from exc
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML: {exc}") from exc


def toml_table(path: str | Path, name: str, document: dict | None = None) -> dict:
    """The ``[name]`` table of a TOML file (of its ``document``, when already read).

    Raises:
        InputError: unreadable file, invalid TOML, or no such table.
    """
    table = (read_toml(path) if document is None else document).get(name)
    if not isinstance(table, dict):
        raise InputError(f"{path}: no [{name}] table")
    return table
