"""How ``wbfriction --help`` lays out its commands: in sections (what a user runs on a log, the whole robot's
commands, the studies, the fleets), each command's summary whole or cut at the end of a phrase, as wide as the
terminal up to :data:`MAX_WIDTH` columns.

The sections are the commands' ``rich_help_panel`` (typer's own attribute, which its plain help, without Rich
markup, does not read): :class:`SectionedGroup` prints them in the order of :data:`SECTIONS`.
"""

from __future__ import annotations

import re

from typer.core import TyperGroup

MAX_WIDTH = 120
"""The widest help [columns]: the terminal's width up to this (lines longer are hard to read)."""

LOGS = "Logs in"
FRICTION = "Friction from a log (the pipeline)"
ROBOT = "The whole robot: inertia, actuators, excitation, replay"
STUDIES = "Studies (the thesis's and this project's)"
FLEETS = "Fleets"
SECTIONS = (LOGS, FRICTION, ROBOT, STUDIES, FLEETS)
"""The sections of ``wbfriction --help``, in their order; a command without one is listed under ``Commands``."""

_SENTENCE_END = re.compile(r"(\S+)\.(?=\s|$)")
_ABBREVIATIONS = ("Fig", "eq", "ch", "e.g", "i.e", "vs", "cf", "etc")
_PHRASE_ENDS = ("; ", ": ", " (", ", ")
"""Where a summary may be cut, the strongest end of a phrase first."""


def summary(text: str, limit: int) -> str:
    """A command's one-line summary of its help ``text``: the first sentence, whole when it fits ``limit``
    characters, else cut at the last end of a phrase that fits, the strongest first (``;``, ``:``, an opening
    bracket, ``,``); where none fits, its first phrase, wrapped; a sentence with none is given whole (wrapped)."""
    words = " ".join(text.split("\n\n")[0].split())
    ends = [m.end() - 1 for m in _SENTENCE_END.finditer(words) if m.group(1) not in _ABBREVIATIONS]
    first = words[:ends[0]] if ends else words
    if len(first) <= limit:
        return first
    cuts = {end: [m.start() for m in re.finditer(re.escape(end), first)] for end in _PHRASE_ENDS}
    for end in _PHRASE_ENDS:
        fit = [c for c in cuts[end] if c <= limit]
        if fit:
            return first[:fit[-1]]
    every = [c for found in cuts.values() for c in found]
    return first[:min(every)] if every else first  # none fits: the shortest phrase, wrapped


class SectionedGroup(TyperGroup):
    """The app's command group: its commands in the sections of :data:`SECTIONS` (each command's
    ``rich_help_panel``), one summary line each (:func:`summary`)."""

    def format_commands(self, ctx, formatter) -> None:
        commands = [(name, cmd) for name in self.list_commands(ctx)
                    if (cmd := self.get_command(ctx, name)) is not None and not cmd.hidden]
        if not commands:
            return
        widest = max(len(name) for name, _ in commands)
        # the summary's column: after the section's indent, the names and write_dl's 2 spaces
        limit = formatter.width - formatter.current_indent - formatter.indent_increment - widest - 2
        sections: dict[str, list[tuple[str, str]]] = {s: [] for s in SECTIONS}
        for name, cmd in commands:
            text = cmd.short_help or summary(cmd.help or "", limit)
            # the names padded to the widest: every section's summaries start in the same column
            sections.setdefault(getattr(cmd, "rich_help_panel", None) or "Commands", []).append(
                (name.ljust(widest), text))
        for title, rows in sections.items():
            if rows:
                with formatter.section(title):
                    formatter.write_dl(rows, col_max=widest)
