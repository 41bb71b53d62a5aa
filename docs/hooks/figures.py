"""MkDocs hook: the figures a page shows, made by the page's own commands, never committed.

A page whose commands run in the suite (a tutorial, a how-to) shows a figure as
``![what it shows](../figures/<page>/<name>.png)``, ``<page>`` the page's file name without ``.md``. ``<name>.png``
is a file one of the page's commands writes (``--figure x.png``, ``-o x.png``, ``demo/fig6_1_support_phases.png`` in
a folder it writes, or a ``python`` block's), or
``<report>.<id>.png``: the image ``id="<id>"`` of the HTML report ``<report>.html`` a command writes (``overview``:
the friction clouds of every joint; ``fig-joint-<joint>``: a joint's four panels).
``tests/test_readme.py`` runs each page's commands and copies its figures into ``docs/figures/<page>/``
(``.gitignore``: generated, never committed); it fails when a page shows a figure its commands do not make.

At a build, a page whose figures are missing from ``docs/figures/`` has its commands run first, through that test
(``python -m pytest tests/test_readme.py``, the ``test`` extra: a minute or a few per page). With
``WBFRICTION_DOCS_FIGURES=placeholder`` (``tests/test_docs.py``, which checks the build and not the figures) a missing
figure is a small placeholder image instead, so the build does not run the pages twice.
"""

from __future__ import annotations

import logging
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files

log = logging.getLogger("mkdocs.hooks.figures")

FIGURE = re.compile(r"!\[[^\]]*\]\((?:\.\./)*figures/([\w.-]+)/([\w.-]+(?:/[\w.-]+)*\.png)\)")
"""A figure a page shows: its page folder and its file name."""

PLACEHOLDER = bytes.fromhex(  # a 1x1 grey PNG
    "89504e470d0a1a0a0000000d49484452000000010000000108000000003a7e9b550000000a49444154789c6338000000c200c1525e"
    "57510000000049454e44ae426082")


def missing(docs: Path) -> dict[str, list[str]]:
    """The pages (relative to the checkout) whose figures are not in ``docs/figures/``, with those figures."""
    out: dict[str, list[str]] = {}
    for page in sorted(docs.rglob("*.md")):
        names = [f"{stem}/{name}" for stem, name in FIGURE.findall(page.read_text())
                 if not (docs / "figures" / stem / name).is_file()]
        if names:
            out[str(page.relative_to(docs.parent))] = names
    return out


def on_pre_build(config: Any) -> None:
    if os.environ.get("WBFRICTION_DOCS_FIGURES") == "placeholder":
        return
    docs = Path(config["docs_dir"])
    for page, names in missing(docs).items():
        log.info("figures: %s: running its commands for %s", page, ", ".join(names))
        node = f"tests/test_readme.py::test_the_page_runs_as_written[{page}]"
        res = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider", node],
                             cwd=docs.parent, capture_output=True, text=True)
        if res.returncode != 0:
            log.warning("figures: %s: its commands failed or are not runnable here (pip install '.[test]'):\n%s",
                        page, res.stdout[-2000:])


def on_files(files: Files, config: Any) -> Files:
    if os.environ.get("WBFRICTION_DOCS_FIGURES") != "placeholder":
        return files
    for names in missing(Path(config["docs_dir"])).values():
        for name in names:
            files.append(File.generated(config, f"figures/{name}", content=PLACEHOLDER))
    return files
