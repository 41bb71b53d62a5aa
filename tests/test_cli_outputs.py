"""Every file a command writes is named with a suffix of its kind of document, checked as the command line is parsed
(issue 81: ``excite -o x.txt`` wrote Parquet into a ``.txt``; ``refine -o x.urdf`` wrote an MJCF after the whole
refinement), and the help of each output lists the suffixes of the registry its writers are in (four helps listed
the table formats by hand)."""

from __future__ import annotations

import re

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers import run_cli_printed, run_with_toy_format
from wbfriction.pipeline.outputs import OUTPUT_OPTIONS, OutputSuffixError, check_output, output_kind

OUTPUTS = [(command, option, kind) for command, options in OUTPUT_OPTIONS.items() for option, kind in options.items()]
"""Every command's option that names a file it writes, and the kind of document it is."""

ARGUMENTS = {"estimate": ["LOG"], "convert": ["BAG"], "fit": ["FRICTION"], "export": ["PARAMS"],
             "predict": ["FRICTION", "--params", "PARAMS"], "report": ["FRICTION"], "rollout": ["LOG", "MODEL"],
             "refine": ["LOG", "MODEL"], "identify": ["LOG"], "sensitivity": ["LOG"], "spectrum": ["LOG"],
             "trends": ["RESULTS"], "simulate": [], "excite": []}
"""What each command needs besides its outputs (files that do not exist: a refusal before the work names no
missing file)."""
REQUIRED = {"refine": ["-o", "refined.xml"], "trends": ["-o", "trends.html"]}
"""A command's required ``-o``, of a good suffix, where the output tried is another."""

SUFFIXES = st.one_of(st.just(""), st.text("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_",
                                          min_size=1, max_size=7).map(lambda s: "." + s))
"""A file name's suffix: none, or a dot and a few letters or digits, in any case."""


def test_every_command_that_writes_a_file_is_listed():
    """Every command whose options name a file it writes (``-o``, ``--json``, ``--table``, ``--figure``,
    ``--config-output``; not a folder) is in :data:`OUTPUT_OPTIONS`, each such option with its kind."""
    from wbfriction.cli import app
    from wbfriction.pipeline.paths import OUTPUT_OPTIONS as NAMED

    group = __import__("typer").main.get_command(app)
    folders = {("batch", "-o"), ("batch", "--tables"), ("dataset", "-o"), ("demo", "-o")}
    found = {}
    for name, command in group.commands.items():  # type: ignore[attr-defined]
        for param in command.params:
            flags = [o for o in param.opts if o in NAMED]
            if flags and "--output-dir" not in param.opts and (name, flags[0]) not in folders:
                found.setdefault(name, set()).add(flags[0])
    assert found == {c: set(options) for c, options in OUTPUT_OPTIONS.items()}


@pytest.mark.parametrize(("command", "option", "kind"), OUTPUTS)
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(suffix=SUFFIXES)
def test_an_output_of_a_suffix_its_kind_is_not_written_as_is_refused_before_any_work(capsys, tmp_path, command,
                                                                                       option, kind, suffix):
    """``COMMAND OPTION out<suffix>`` with a suffix its kind of document is not written as: exit 2, one line naming
    the option, the suffix and the suffixes it is written as, before anything is read (the inputs do not exist) or
    written."""
    accepted = output_kind(kind).suffixes()
    if suffix.lower() in accepted:
        return
    path = tmp_path / f"out{suffix}"
    required = REQUIRED.get(command, []) if option != "-o" else []
    code, out, err = run_cli_printed(capsys, command, option, path, *ARGUMENTS[command], *required)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    said = f", not '{suffix.lower()}'" if suffix else f", and '{path.name}' has no suffix"
    assert lines[0].startswith(f"error: {option} {path}: ") and lines[0].endswith(said), err
    assert all(s in lines[0] for s in accepted)
    assert not path.exists() and out == ""


@given(kind=st.sampled_from(sorted({k for _, _, k in OUTPUTS})), data=st.data())
def test_a_suffix_of_its_kind_is_taken_in_any_case(kind, data):
    """Every suffix the kind is written as passes, in any case; any other is refused with the option, the suffix and
    the accepted ones as data."""
    accepted = output_kind(kind).suffixes()
    suffix = data.draw(st.sampled_from(accepted))
    check_output("-o", f"x{suffix.upper()}", kind)
    other = data.draw(SUFFIXES.filter(lambda s: s.lower() not in accepted))
    with pytest.raises(OutputSuffixError) as caught:
        check_output("--table", f"x{other}", kind)
    assert (caught.value.option, caught.value.suffix, caught.value.accepted) == ("--table", other.lower(), accepted)


def test_every_output_s_help_lists_its_registry_s_suffixes():
    """A format registered before the command line is loaded (the toy Feather, which writes whole tables, in a
    process of its own: the help is made as the command line loads) is in the help of every output written as a
    whole table, and the help of every output lists exactly the suffixes its kind is written as, as the check
    takes them (``excite -o``, ``rollout -o``, ``refine --table`` and ``trends --table`` listed them by hand)."""
    code = ("import json\nfrom toys.toy_format import Feather\n"
            "from wbfriction.logs import register_format\nregister_format(Feather())\n"
            "import typer\nfrom wbfriction.cli import app\nfrom wbfriction.pipeline.outputs import OUTPUT_OPTIONS, "
            "output_kind\nfrom wbfriction.export.catalog import KINDS\ngroup = typer.main.get_command(app)\nout = []\n"
            "for command, options in OUTPUT_OPTIONS.items():\n"
            "    for option, kind in options.items():\n"
            "        param = next(p for p in group.commands[command].params if option in p.opts)\n"
            "        accepted = output_kind(kind).suffixes()\n"
            "        if kind == 'export':  # each target named by its first suffix, and what it writes\n"
            "            accepted = tuple(k.suffixes[0] for k in KINDS.values())\n"
            "        out.append([command, option, kind, param.help, list(accepted)])\n"
            "print(json.dumps(out))")
    shown = run_with_toy_format(code)
    for command, option, kind, text, accepted in shown:
        listed = re.findall(r"(?<![\w<])\.[a-z0-9]+\b", text)
        if not listed:  # "Also write a PNG ...", "(JSON)": a kind of one suffix, named by it
            assert len(accepted) == 1 and accepted[0][1:].upper() in text, (command, option)
            continue
        assert listed == accepted, (command, option, text)
        assert (".feather" in listed) == (kind == "table"), (command, option)
