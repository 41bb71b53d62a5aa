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
    assert "\\[" not in shown  # no markup escape shown ("Physics step \\[s]")


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


def test_every_help_that_lists_the_formats_lists_the_registrys():
    """Issue 65: the help listed the formats by hand (the friction table's ``-o`` offered ``.h5``, which is not
    streamed; ``convert``'s log left out ``.npz``; ``simulate -o`` ``.npz``, ``.pq``): every list is the registry's
    now. A format registered before the command line is loaded (the toy Feather, in a process of its own: the help
    is made as the command line loads, and reads the formats' catalogue, not their modules) is in every help that
    lists the logs read, and in ``simulate -o`` (it writes whole tables), not in the streamed outputs' (it does not
    stream); ``.npz`` wherever a log is read."""
    from helpers import run_with_toy_format

    code = ("import json\nimport typer.testing\nfrom toys.toy_format import Feather\n"
            "from wbfriction.logs import register_format\nregister_format(Feather())\n"
            "from wbfriction.cli import app\nout = {}\n"
            "for c in ('estimate', 'convert', 'simulate', 'batch', 'sensitivity', 'spectrum', 'identify', 'refine', "
            "'rollout'):\n"
            "    r = typer.testing.CliRunner().invoke(app, [c, '--help'], terminal_width=10000)\n"
            "    assert r.exit_code == 0, r.output\n    out[c] = ' '.join(r.output.split())\n"
            "print(json.dumps(out))")
    shown = run_with_toy_format(code)
    table_formats = ("Parquet (.parquet, .pq)", "CSV (.csv)", "HDF5 (.h5, .hdf5, .he5)", "NumPy (.npz)",
                     "Feather (.feather)")
    for command, text in shown.items():  # every command that reads a log names every table format
        assert command == "simulate" or all(f in text for f in table_formats), command
    assert "ROS 2 bag (.mcap, .db3" in shown["estimate"] and "ROS 2 bag (.mcap, .db3" in shown["convert"]
    assert "Friction table to write: .parquet, .pq or .csv." in shown["estimate"]
    assert "Log to write: .parquet, .pq or .csv." in shown["convert"]
    assert "Log to write: .parquet, .pq, .csv, .h5, .hdf5, .he5, .npz or .feather." in shown["simulate"]


def _shown(*args: str, columns: int = 100) -> str:
    """``wbfriction ARGS --help`` in a terminal ``columns`` wide (the runner's width: it does not read $COLUMNS,
    :func:`test_the_help_reads_the_terminals_width_up_to_120` does)."""
    result = typer.testing.CliRunner().invoke(app, [*args, "--help"], terminal_width=columns)
    assert result.exit_code == 0, result.output
    return result.output


@pytest.mark.parametrize("name", [None, *COMMANDS])
def test_help_fits_a_100_column_terminal_and_uses_it(name):
    """Issue 67: the help stayed 80 columns wide in a 100-column terminal; it uses the width now (its widest line
    beyond 80) and stays within it."""
    lines = _shown(*([] if name is None else [name])).splitlines()
    widest = max(len(line) for line in lines)
    assert 80 < widest <= 100, (widest, [line for line in lines if len(line) > 100])


@pytest.mark.parametrize(("columns", "least", "most"), [(100, 81, 100), (200, 101, 120)])
def test_the_help_reads_the_terminals_width_up_to_120(columns, least, most):
    """As a shell runs it ($COLUMNS, no runner): 100 columns used, and no more than 120 however wide the terminal."""
    import os
    import subprocess
    import sys

    run = subprocess.run([sys.executable, "-m", "wbfriction", "--help"], capture_output=True, text=True,
                         env=dict(os.environ, COLUMNS=str(columns)))
    assert run.returncode == 0, run.stderr
    assert least <= max(len(line) for line in run.stdout.splitlines()) <= most


SECTIONS = {  # the sections of 'wbfriction --help' and the commands a user finds under each, in this order
    "Logs in": ["simulate", "convert", "dataset"],
    "Friction from a log (the pipeline)": ["estimate", "fit", "export", "predict", "report"],
    "The whole robot: inertia, actuators, excitation, replay": ["rollout", "refine", "identify", "excite"],
    "Studies (the thesis's and this project's)": ["sensitivity", "spectrum", "demo", "study-sensors", "study-noise",
                                                  "study-fleet", "study-filters", "study-quadruped"],
    "Fleets": ["batch", "trends"],
}


def test_the_overview_groups_the_commands():
    """The pipeline a user runs apart from the studies and the fleets: each section's heading, then its commands,
    one line each, every command in one section."""
    lines = _shown().splitlines()
    found: dict[str, list[str]] = {}
    section = None
    for line in lines:
        if line.endswith(":") and not line.startswith(" "):
            section = line[:-1]
            found[section] = []
        elif section in SECTIONS and line.startswith("  ") and not line.startswith("   "):
            found[section].append(line.split()[0])
    assert {s: c for s, c in found.items() if s in SECTIONS} == SECTIONS
    assert sorted(c for cs in SECTIONS.values() for c in cs) == COMMANDS


@pytest.mark.parametrize("columns", [80, 100])
def test_each_summary_is_whole_or_ends_a_phrase(columns):
    """A command's summary in the overview is never cut mid-phrase ("Estimate the friction torque of every..."):
    it is the command's own short help, or its help's first words up to the end of a sentence or a phrase
    (``;``, ``:``, ``,``, an opening bracket)."""
    text = _shown(columns=columns).split("\n", 1)[1]  # after the usage line ("[ARGS]...")
    assert "..." not in text
    rows = re.findall(r"^  (\S+) +(.+(?:\n {10,}\S.*)*)", text.split("Commands:")[-1] if "Commands:" in text
                      else text.split("Options:")[1], re.M)
    summaries = {name: " ".join(s.split()) for name, s in rows if name in GROUP.commands}  # type: ignore[attr-defined]
    assert sorted(summaries) == COMMANDS
    for name, summary in summaries.items():
        command = GROUP.commands[name]  # type: ignore[attr-defined]
        if command.short_help:
            assert summary == " ".join(command.short_help.split()), name
            continue
        whole = " ".join((command.help or "").split())
        assert whole.startswith(summary), name
        assert whole[len(summary):][:2] in (". ", "; ", ": ", ", ", " (") or whole[len(summary):] in ("", "."), name


def test_the_demo_names_the_figures_it_writes():
    """The ideal study writes Fig. 6.1-6.3 (and the mujoco study 6.4-6.5, not the ideal one): the help says which."""
    import inspect

    from wbfriction.studies import realistic, simulation

    shown = " ".join(_shown("demo").split())
    assert "Fig. 6.1-6.3" in shown and "Fig. 6.1-6.5" not in shown
    assert all(f"fig6_{k}_" in inspect.getsource(simulation) for k in (1, 2, 3))
    assert all(f"fig6_{k}_" in inspect.getsource(realistic) for k in (4, 5))
    assert "mujoco" in shown.split("Fig. 6.4-6.5")[0].split("Fig. 6.1-6.3")[-1]
