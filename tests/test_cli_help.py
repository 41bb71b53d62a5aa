"""What the command line shows a person (issue 24, item 1): help that keeps its units, the built-in robots and
the input formats named, ``--version``, and ``wbfriction`` alone an overview that exits 0."""

from __future__ import annotations

import re
from importlib.metadata import version

import pytest
import typer.main
import typer.testing

from wbfriction.cli import app
from wbfriction.model.robots import BUILTIN_ROBOTS

GROUP = typer.main.get_command(app)
COMMANDS = sorted(GROUP.commands)  # type: ignore[attr-defined]
BRACKETS = re.compile(r"\[[^\[\]]+\]")


def _help(*args: str) -> str:
    result = typer.testing.CliRunner().invoke(app, [*args, "--help"])
    assert result.exit_code == 0, result.output
    return " ".join(result.output.split())  # the wrapping undone


@pytest.mark.parametrize("name", COMMANDS)
def test_every_bracketed_unit_of_a_command_is_printed(name):
    """Every ``[...]`` in a command's help and in its options' help ([m], [rad/s], [friction.<group>], ...)
    appears in ``--help`` as written: the formatter does not take it for markup."""
    command = GROUP.commands[name]  # type: ignore[attr-defined]
    texts = [command.help or ""] + [getattr(p, "help", None) or "" for p in command.params]
    expected = {b for text in texts for b in BRACKETS.findall(" ".join(text.split()))}
    shown = _help(name)
    assert [b for b in sorted(expected) if b not in shown] == []


def test_units_that_markup_used_to_delete_are_there():
    assert "[m]" in _help("simulate") and "[rad]" in _help("simulate")
    assert "[friction.<group or joint>]" in _help("simulate")


def test_the_robots_and_the_formats_are_named():
    shown = _help("estimate")
    assert all(robot in shown for robot in BUILTIN_ROBOTS)
    assert all(fmt in shown for fmt in ("Parquet", "CSV", "HDF5", "ROS 2 bag"))


def test_wbfriction_alone_prints_its_overview_and_succeeds():
    result = typer.testing.CliRunner().invoke(app, [])
    assert result.exit_code == 0, result.output
    assert all(name in result.output for name in COMMANDS)


def test_version():
    result = typer.testing.CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0 and result.output.strip() == f"wbfriction {version('wbfriction')}"


ISSUE = re.compile(r"\bissues?\s*#?\s*\d+|#\d+", re.IGNORECASE)


@pytest.mark.parametrize("name", [None, *COMMANDS])
def test_no_help_names_an_issue_number(name):
    """No help names one of the project's issues ("(issue 23)"): a person reading it has no tracker to look them up
    in. Checked on the help as shown (the overview's one-line summaries too) and on the texts it is made of, so that
    neither a line's wrap nor markup hides one."""
    command = GROUP if name is None else GROUP.commands[name]  # type: ignore[attr-defined]
    texts = [command.help or "", command.short_help or ""] + [getattr(p, "help", None) or "" for p in command.params]
    shown = _help(*([] if name is None else [name]))
    assert [m.group(0) for text in (*texts, shown) for m in ISSUE.finditer(" ".join(text.split()))] == []
