"""MkDocs hook: the package's docstrings, written for Sphinx-style reading (``x``, :func:`y`, ``.. math::``), shown
as they mean in the API reference, without editing them.

A Markdown preprocessor, added to the manual's Markdown (and so to mkdocstrings', which renders every docstring
with the same extensions):

* a cross-reference role, ``:func:`~wbfriction.fit.joints.fit_estimate``` (also ``:mod:``, ``:class:``,
  ``:meth:``, ``:attr:``, ``:data:``, ``:math:``), becomes inline code: the last name with ``~``, as Sphinx shows it,
  else the name as written;
* two bracketed phrases in a row, ``([on, off] [N]: ...)``, prose about units, are not read as a Markdown
  reference link (the second pair escaped);
* a ``.. math::`` directive (on one line, or its indented block) becomes a code block of the formula, as written.

Everything else is left alone, fenced code included.
"""

from __future__ import annotations

import re
from typing import Any

from markdown import Extension
from markdown.preprocessors import Preprocessor
from mkdocs.plugins import event_priority

ROLE = re.compile(r":(?:py:)?(?:func|meth|class|mod|attr|data|obj|exc|const|math):`(~?)([^`]+)`")
UNITS = re.compile(r"\] \[")
MATH = re.compile(r"^(\s*)\.\. math::\s*(.*)$")
FENCE = re.compile(r"^\s*(```|~~~)")


def _role(match: re.Match) -> str:
    tilde, target = match.groups()
    return f"`{target.rsplit('.', 1)[-1] if tilde else target}`"


def rewrite(lines: list[str]) -> list[str]:
    out: list[str] = []
    fenced = False
    i = 0
    while i < len(lines):
        line = lines[i]
        if FENCE.match(line):
            fenced = not fenced
        if fenced:
            out.append(line)
            i += 1
            continue
        math = MATH.match(line)
        if not math:
            out.append(UNITS.sub(r"] \\[", ROLE.sub(_role, line)))
            i += 1
            continue
        indent, inline = math.groups()
        formula = [inline] if inline.strip() else []
        i += 1
        while i < len(lines) and (not lines[i].strip() or len(lines[i]) - len(lines[i].lstrip()) > len(indent)):
            formula.append(lines[i].strip())
            i += 1
        while formula and not formula[-1]:
            formula.pop()
        formula = [f for f in formula if f] if len(formula) > 1 else formula
        out += ["", *(f"{indent}    {f}" for f in formula), ""]
    return out


class _RestRoles(Preprocessor):
    def run(self, lines: list[str]) -> list[str]:
        return rewrite(lines)


class RestDocstrings(Extension):
    def extendMarkdown(self, md: Any) -> None:  # noqa: N802 (Markdown's name)
        md.preprocessors.register(_RestRoles(md), "wbfriction_rest_roles", 40)


@event_priority(100)  # before mkdocstrings reads the extensions
def on_config(config: Any) -> Any:
    config.markdown_extensions.append(RestDocstrings())
    return config
