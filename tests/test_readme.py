"""The README's and the manual's commands run as written (issue 24, item 5; issue 54, items 4 and 5).

Every ``bash`` and ``python`` block of the README, of the manual's Getting started, tutorials, how-to guides and
guide to extending (:data:`PAGES`) runs as written, in the order of its page, from a fresh folder per page that
holds ``examples/`` beside the outputs (a copy of the checkout's layout): each command line exits 0 and writes what
its ``-o`` names, no two lines of a page write the same file, and a command waits only for the earlier ones whose
outputs it reads (two run at a time: the machine's two cores). A ``python`` block runs once everything before it
has, and whatever follows waits for it. Marks, an HTML comment on the line before a fenced block:

* ``<!-- not run: REASON -->``: the block is not run (an install, ``mkdocs serve``);
* ``<!-- write: FILE -->``: the block's text is written to ``FILE`` in the page's folder first (a TOML a command
  reads), so that what the page shows is what runs;
* ``<!-- output of: COMMAND -->``: the (``text``) block shows what COMMAND, a command line of the page (a prefix of
  exactly one), printed: every number in it is one the run printed, within the rounding it is written with.

A paragraph that quotes numbers a command printed is followed by ``<!-- quoted from COMMAND: 0.401 0.602 -->``: each
number is in the paragraph and in what COMMAND printed, within its rounding (``python``: the page's ``python``
blocks; another page, ``docs/how-to/x.md``: numbers that page quotes so). A figure a page shows,
``![...](../figures/<page>/<name>.png)``, is made by its commands: a PNG they write, or ``<report>.<id>.png``, an image
of an HTML report they write; the run copies it into ``docs/figures/<page>/`` (not committed: the manual's build
shows it, ``docs/hooks/figures.py``) and fails without it. A command line that writes only what it names
(:data:`SHARED`) runs once per session on the same inputs, whichever pages show it.

The manual's other pages (reference, explanation, measurements: the full-size commands that measured its numbers,
minutes to hours each) are not run here. A page whose commands fetch a real dataset (``wbfriction dataset``) reads
it from ``WBFRICTION_DATA`` (else ``../shared/real-data``) and is skipped without it.
"""

from __future__ import annotations

import base64
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sys
import threading
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path

import pytest

from helpers import REAL_DATA

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs"

PAGES = ["README.md", "docs/index.md", "docs/getting-started.md",
         *sorted(str(p.relative_to(REPO)) for p in (DOCS / "tutorials").glob("*.md")),
         *sorted(str(p.relative_to(REPO)) for p in (DOCS / "how-to").glob("*.md")), "docs/extending.md"]
"""The pages whose blocks run, relative to the checkout."""

QUICK: set[str] = set()
"""Pages that run in about 20 s or less, not marked ``slow``: none (the README's tour alone simulates, estimates, fits
and reports a walk: about a minute)."""

FENCE = re.compile(r"(?:^<!-- (not run|write|output of): *(.*?) -->\n)?^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)
"""A fenced block and the mark on the line before it, if any."""

QUOTED = re.compile(r"^<!-- quoted from (.+): ([^:]+?) -->$", re.M)
"""A paragraph's numbers taken from a command's output: the mark on the line after it (:func:`quotes`)."""

NUMBER = re.compile(r"(?<![\w.])[-+−]?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?!\.?\w)")
"""A number as printed or quoted: ``0.401``, ``-2.93``, ``7.1e-07`` (not ``lwr_6``'s ``6``, not a version)."""

FIGURE = re.compile(r"!\[[^\]]*\]\((?:\.\./)*figures/([\w.-]+)/([\w.-]+(?:/[\w.-]+)*\.png)\)")
"""A figure a page shows, ``![...](../figures/<page>/<name>.png)``: made by the page's commands
(``docs/hooks/figures.py`` says how; :func:`make_figures`)."""

FIGURES = DOCS / "figures"
"""Where the pages' figures are written (``.gitignore``: generated, never committed)."""


@dataclass(frozen=True)
class Step:
    """One thing a page runs: a ``command`` line, a ``python`` block, or a ``file`` it writes first."""

    kind: str
    text: str
    name: str = ""


def command_lines(block: str) -> list[str]:
    """The lines of a bash block, comments dropped (``  #`` starts a line's comment)."""
    lines = [line.split("  #")[0].strip() for line in block.splitlines()]
    return [line for line in lines if line and not line.startswith("#")]


def page_steps(page: str) -> list[Step]:
    """What a page runs, in its order."""
    steps: list[Step] = []
    for mark, arg, lang, body in FENCE.findall((REPO / page).read_text()):
        if mark == "not run":
            assert arg.strip(), f"{page}: a '<!-- not run: -->' mark gives its reason"
        elif mark == "write":
            steps.append(Step("file", body, arg.strip()))
        elif lang == "bash":
            steps += [Step("command", line) for line in command_lines(body)]
        elif lang == "python":
            steps.append(Step("python", body))
    return steps


def page_commands(page: str) -> list[str]:
    return [s.text for s in page_steps(page) if s.kind == "command"]


def numbers(text: str) -> list[str]:
    """The numbers in ``text`` as written (:data:`NUMBER`)."""
    return NUMBER.findall(text)


def within_rounding(quoted: str, printed: list[str]) -> bool:
    """``quoted`` is one of ``printed`` rounded as it is written (``0.401`` for ``0.4012``, ``10`` for ``10.2``);
    signs aside (a page says "an offset of 2.3 below")."""
    mantissa, _, exponent = quoted.lstrip("+-−").partition("e")
    decimals = len(mantissa.partition(".")[2])
    half = 0.5 * 10.0 ** (int(exponent or 0) - decimals) * (1 + 1e-9)
    value = abs(float(mantissa) * 10.0 ** int(exponent or 0))
    return any(abs(abs(float(p.replace("−", "-"))) - value) <= half for p in printed)


@dataclass(frozen=True)
class Quote:
    """Numbers a page quotes from what a command printed: ``source`` a prefix of one of the page's command lines,
    ``python`` (its ``python`` blocks, together) or another page (``docs/how-to/x.md``: numbers that page quotes);
    ``numbers`` as written; ``text`` the paragraph or ``text`` block they are in."""

    source: str
    numbers: tuple[str, ...]
    text: str


def quotes(page: str) -> list[Quote]:
    """What a page quotes from its commands' output, by two marks:

    * ``<!-- output of: COMMAND -->`` on the line before a fenced block: the block is what COMMAND printed (some
      lines left out), and every number in it is one it printed;
    * ``<!-- quoted from COMMAND: 0.401 0.602 -->`` on the line after a paragraph: the paragraph quotes those
      numbers of what COMMAND printed (each must be in the paragraph as written)."""
    text = (REPO / page).read_text()
    found = [Quote(arg.strip(), tuple(numbers(body)), body) for mark, arg, _, body in FENCE.findall(text)
             if mark == "output of"]
    for match in QUOTED.finditer(text):
        before = text[:match.start()].rstrip("\n")
        paragraph = before[before.rfind("\n\n") + 2:]
        found.append(Quote(match[1].strip(), tuple(match[2].replace(",", " ").split()), paragraph))
    return found


def outputs(command: str) -> list[str]:
    """What a command line says it writes: the values of its ``-o`` options and of ``--json``/``--write``/
    ``--config-output``/``--table``/``--figure``."""
    words = shlex.split(command)
    return [words[i + 1] for i, w in enumerate(words[:-1]) if w in ("-o", "--output", "--output-dir", "--json",
                                                                     "--write", "--config-output", "--table",
                                                                     "--figure")]


def step_outputs(step: Step) -> list[str]:
    return [step.name] if step.kind == "file" else outputs(step.text) if step.kind == "command" else []


def needs(steps: list[Step]) -> list[set[int]]:
    """For each step, the earlier ones it waits for: a command whose argument is an earlier step's output, or a
    path inside one (``fleet/manifest.csv`` inside ``fleet``); every earlier step for a ``python`` block, and a
    ``python`` block for every later step. The page's order is kept between a step and what it reads; the others
    may run side by side."""
    made = [step_outputs(s) for s in steps]
    deps: list[set[int]] = []
    for i, step in enumerate(steps):
        if step.kind == "python":
            deps.append(set(range(i)))
            continue
        words = shlex.split(step.text) if step.kind == "command" else []
        deps.append({j for j in range(i) for out in made[j]
                     if any(w == out or w.startswith(out.rstrip("/") + "/") for w in words)}
                    | {j for j in range(i) if steps[j].kind == "python"})
    return deps


EXPECTED = {
    # issue 66: the Go2's design predicts every parameter ok, the worst a calf's offset at its noise's floor
    "wbfriction excite --robot go2 -o go2_excite.parquet -o go2_excite.csv --json go2_excite.json --figure "
    "go2_excite.png --amplitude 0.95": [
        r"^worst: \w+_calf_joint offset, 0\.2\d of its limit \(below 1: predicted ok\)$"],
    # TALOS on one foot: the ZMP of the designed stance well inside the stance sole (its edges 10 mm at the least)
    "wbfriction excite --robot talos --stance left -o talos_stance.parquet --json talos_stance.json --figure "
    "talos_stance.png": [r"^ZMP [2-9]\d\.\d mm inside the left sole's edges \(at least 10\)"],
    # the Go2 on three feet: its centre of mass and ZMP near the stance triangle's inradius (104 mm) from its edges
    "wbfriction excite --robot go2_walking --swing FR -o go2_tripod.parquet --json go2_tripod.json --figure "
    "go2_tripod.png": [r"^centre of mass 10\d\.\d mm \(at least 50\) and ZMP \d{2,3}\.\d mm \(at least 30\)"],
    # what to record next after the real Aliengo's log: every parameter predicted ok under its model
    "wbfriction excite --config aliengo_identified.toml --after aliengo_params.json -o aliengo_next.parquet --json "
    "aliengo_next.json --figure aliengo_next.png --amplitude 0.95": [r"^worst: \w+ \w+, [01]\.\d\d of its limit",
                                                   r"^held at their posture \(their fits ok\): none"],
    # what to record next after a Panda's log whose wrist held still: the wrist alone moves, predicted ok
    "wbfriction excite --robot panda --after panda_wrist_still_params.json --duration 10 --period 10 -o "
    "panda_next.parquet --json panda_next.json": [r"worst: panda_joint[567] F_[cv], 0\.0\d\d of its limit",
                                                r"^ panda_joint[567]\s+not excited\s", r"^held at their posture "
                                                r"\(their fits ok\): panda_joint1, panda_joint2, panda_joint3,"
                                                r"\s+panda_joint4;"],
    "python examples/fleet_trends.py --output fleet": [  # arm 1's joint 4 alone, from the day its wear began
        r"^24 logs processed on Dask, 0 already done$",
        r"^drift: arm-1 panda_joint4 \S+ \+\d+ % from 2026-01-1[0-4]$",  # worn from the 8th log, Jan 12
        r"1 of 14 tested robot joints drifted.*; wrote fleet/trends\.html$",  # that joint alone
    ],
    # the real Aliengo's drivers: a delay near the peer's 2.64 steps of 5 ms (13.2 ms), whole steps apart from it
    "wbfriction identify aliengo/train.parquet --config aliengo/aliengo.toml --actuator pd --config-output "
    "aliengo_identified.toml --json aliengo_actuator.json": [r"^delay 1[0-3]\.\d\d ms ±0\.\d\d"],
    # the hung Go2's 12 ms recovered within one 1 ms physics step
    "wbfriction identify hung.parquet --robot go2 --actuator pd --json hung_actuator.json": [r"^delay 1[12]\.\d\d ms"],
}
"""What a command must print (regular expressions, each found in its output, multi-line): the examples the
pages run are checked here, once (``tests/test_examples.py`` runs the others)."""

PRINTS = {
    # the Go2's design played with another noise: every parameter ok, its standard errors as predicted
    "docs/how-to/excitation.md": [r"^48 of 48 parameters ok; 4[3-8] of 48 standard errors within 2x of the "
                                  r"prediction$",
                                  # the Panda's design played: every joint ok, its errors near those predicted
                                  r"^7 of 7 joints ok; F_c and F_v: ([7-9]|1[0-4]) of 14 standard errors within "
                                  r"1\.5x of the prediction$",
                                  # TALOS on one foot, its swing leg's friction recovered (issue 66: within 2 %)
                                  r"^swing leg: 6 joints, F_c and F_v within [01]\.\d\d % of the truth$",
                                  # the Go2 on three feet, played from the table excite wrote, its front right leg's
                                  # friction recovered (within 2 %)
                                  r"^swing leg FR: 3 joints, F_c and F_v within [01]\.\d\d % of the truth$"],
    "docs/how-to/library.md": [r"leg_right_4_joint: F_c"],  # the API block's fits of the walk
    "docs/extending.md": [r"^arm\.tsv: 10000 samples, tau_f of 7 joints$",  # a log format registered, read
                          # a torque source registered: a log written through it, read back as its own
                          r"^arm_effort\.parquet: effort: the drives' effort in mN·m \(effort\.<joint>\)$",
                          r"^wrote panda_friction\.csv \(csv\)$",  # an export target, beside a built-in one
                          r"^wrote panda_extended\.xml \(mjcf\)$",
                          r"^panda_joint1: quadratic: F_v ",  # a family fitted alone, then scored by --model auto
                          r"^panda_joint1: thesis: .*held-out RMS.*quadratic",
                          # a contact model registered: a Go2's trot read with it, the point feet's friction
                          r"^trot\.parquet on local points: [1-9]\d?% of the samples' friction determined, "
                          r"(0e\+00|\de-1[2-9]) N·m from the point feet's$",
                          # a rig registered, run by simulate with its own option, its injected friction fitted back
                          r"^sine_arm\.parquet: panda_joint1: F_c 0\.(59|60|61) N·m, F_v 0\.(29|30|31) N·m·s/rad$",
                          # an engine registered, a biped's walk simulated in it
                          r"^fine_walk\.parquet: \d{4,} samples, \d\.\d s$"],
    # a trot without foot forces: the two swinging legs determined, the stance pair not (the rank of [S^T J^T])
    "docs/how-to/quadrupeds.md": [r"^FL_foot\+RR_foot down: determined on every sample: FR_hip_joint, FR_thigh_joint, "
                                  r"FR_calf_joint, RL_hip_joint, RL_thigh_joint, RL_calf_joint$",
                                  r"^FR_foot\+RL_foot down: determined on every sample: FL_hip_joint, FL_thigh_joint, "
                                  r"FL_calf_joint, RR_hip_joint, RR_thigh_joint, RR_calf_joint$",
                                  r"^FL_foot\+FR_foot\+RL_foot\+RR_foot down: determined on every sample: none$"],
    "docs/how-to/pd-robots.md": [r"^FL_hip_joint: tracking error \d+\.\d mrad, the peer's",  # the rollout check
                                 # the exported MJCF against the peer as PACE simulates it: a lower mean
                                 r"^ours tracks better on ([89]|1[0-2]) of 12 joints: mean [3-5]\.\d\d mrad, the "
                                 r"peer's [6-8]\.\d\d$",
                                 # the export refined on the training log's replay tracks the held-out log better
                                 r"^the refined file tracks the held-out stretch better than the export: mean "
                                 r"[2-4]\.\d\d against [4-5]\.\d\d mrad",
                                 r"^delay 1[12]\.\d\d ms, truth 12 ms$",  # the hung Go2: within a physics step
                                 # its armature and friction within 5 % with a real driver's noise
                                 r"^armature within [0-4]\.\d %, F_v within [0-4]\.\d %, F_c within [0-4]\.\d % of "
                                 r"the truth$"],
}
"""What a page's ``python`` blocks must print, together (regular expressions)."""

WRITES = {
    "docs/how-to/quadrupeds.md": ["trot_determined.png"],
    "docs/how-to/library.md": ["api_params.json"],
    "docs/extending.md": ["arm.tsv", "arm_effort.parquet", "panda_friction.csv", "panda_extended.xml",
                          "sine_arm.parquet", "fine_walk.parquet"],
}
"""Files a page's ``python`` blocks must write."""


def test_the_pages_are_found():
    assert {"docs/tutorials/simulated-walk.md", "docs/tutorials/real-arm.md", "docs/tutorials/fleet.md",
            "docs/how-to/library.md"} <= set(PAGES)
    for page in PAGES:
        assert (REPO / page).is_file(), page


@pytest.mark.parametrize("page", PAGES)
def test_every_output_is_its_own(page):
    written = [o for s in page_steps(page) for o in step_outputs(s)]
    assert len(written) == len(set(written)), sorted(w for w in written if written.count(w) > 1)


@pytest.mark.parametrize("page", PAGES)
def test_a_page_runs_only_what_it_can(page):
    """Its command lines are ``wbfriction`` or ``python`` (run without a shell: no variables, no pipes)."""
    for command in page_commands(page):
        assert command.split()[0] in ("wbfriction", "python"), f"{page}: {command}"
        assert not set("$|;&<>`") & set(command.replace("->", "")), f"{page}: a shell's syntax in {command}"


def test_a_command_waits_for_what_it_reads():
    steps = page_steps("docs/tutorials/simulated-walk.md")
    deps = needs(steps)
    index = {s.text.split(" -o ")[0]: i for i, s in enumerate(steps)}
    fit = index["wbfriction fit walk_friction.parquet"]
    assert deps[fit] == {index["wbfriction estimate walk.parquet --robot talos"]}
    predict = next(i for i, s in enumerate(steps) if s.text.startswith("wbfriction predict"))
    assert {steps[j].text.split()[-1] for j in deps[predict]} == {"turn_friction.parquet", "walk_params.json"}
    steps = page_steps("docs/tutorials/fleet.md")
    batch = next(i for i, s in enumerate(steps) if s.text.startswith("wbfriction batch"))
    assert [steps[j].text for j in needs(steps)[batch]] == ["python examples/fleet_trends.py --output fleet"]
    steps = page_steps("docs/how-to/terms.md")  # a TOML the page writes, then the command that reads it
    simulate = next(i for i, s in enumerate(steps) if s.text.startswith("wbfriction simulate"))
    assert [steps[j].name for j in needs(steps)[simulate]] == ["knee_terms.toml"]
    steps = page_steps("docs/how-to/library.md")  # the API block after the walk it reads
    assert [s.kind for s in steps] == ["command", "python"] and needs(steps)[1] == {0}


def test_the_marks_are_read():
    text = ("```bash\nwbfriction a -o x  # note\n```\n<!-- not run: an install -->\n```bash\npip install .\n```\n"
            "<!-- write: f.toml -->\n```toml\nk = 1\n```\n```text\nnot run\n```\n```python\nprint(1)\n```\n")
    found = FENCE.findall(text)
    assert [(m, a, lang) for m, a, lang, _ in found] == [("", "", "bash"), ("not run", "an install", "bash"),
                                                         ("write", "f.toml", "toml"), ("", "", "text"),
                                                         ("", "", "python")]


def quote_source(page: str, quote: Quote) -> list[int]:
    """The steps of ``page`` whose output ``quote`` quotes: the command line it names, or every ``python`` block."""
    steps = page_steps(page)
    if quote.source == "python":
        return [i for i, s in enumerate(steps) if s.kind == "python"]
    return [i for i, s in enumerate(steps) if s.kind == "command" and s.text.startswith(quote.source)]


def check_quotes(page: str, printed: dict[int, str]) -> None:
    """Every number ``page`` quotes from a command's output is one it printed, within the quote's rounding."""
    for quote in quotes(page):
        if quote.source.endswith(".md"):
            continue  # another page's quotes: test_a_quote_names_what_it_quotes
        out = numbers("".join(printed[i] for i in quote_source(page, quote)))
        wrong = [n for n in quote.numbers if not within_rounding(n, out)]
        assert not wrong, f"{page}: {wrong} quoted from {quote.source!r}, which printed no such numbers:\n{quote.text}"


def page_figures(page: str) -> list[str]:
    """The figures a page shows (:data:`FIGURE`), by file name."""
    return [name for _, name in FIGURE.findall((REPO / page).read_text())]


def figure_png(folder: Path, name: str) -> bytes | None:
    """Figure ``name`` as a page's commands made it in ``folder``: the file itself (``demo/fig6_1.png``: in a folder
    a command writes), or ``<report>.<id>.png``, the image ``id="<id>"`` of the HTML report ``<report>.html``; None
    if neither is there."""
    if (folder / name).is_file():
        return (folder / name).read_bytes()
    report, _, image = name.removesuffix(".png").rpartition(".")
    html = folder / f"{report}.html"
    if not report or not html.is_file():
        return None
    found = re.search(rf'<img id="{re.escape(image)}"[^>]*src="data:image/png;base64,([^"]+)"', html.read_text())
    return base64.b64decode(found[1]) if found else None


def make_figures(page: str, folder: Path) -> None:
    """Each figure ``page`` shows, copied from what its commands wrote in ``folder`` into ``docs/figures/<page>/``
    (written whole: a temporary file renamed)."""
    for name in page_figures(page):
        png = figure_png(folder, name)
        assert png is not None, f"{page} shows figures/{Path(page).stem}/{name}: its commands wrote no such figure"
        target = FIGURES / Path(page).stem / name
        target.parent.mkdir(parents=True, exist_ok=True)
        part = target.with_name(target.name + ".part")
        part.write_bytes(png)
        part.replace(target)


MANUAL = sorted({*PAGES, *(str(p.relative_to(REPO)) for p in DOCS.rglob("*.md"))})
"""Every page: the measurements' may quote what a page that runs quotes (``<!-- quoted from docs/tutorials/x.md``)."""


@pytest.mark.parametrize("page", MANUAL)
def test_a_quote_names_what_it_quotes(page):
    """A quote's source is one of the page's command lines (a prefix of exactly one), its ``python`` blocks, or
    another page that quotes the same numbers (within the rounding of this one); a paragraph's marked numbers are
    in the paragraph. A page whose commands do not run quotes only other pages."""
    for quote in quotes(page):
        assert page in PAGES or quote.source.endswith(".md"), f"{page} does not run: it quotes only pages that do"
        assert quote.numbers, f"{page}: a quote of {quote.source!r} with no number"
        assert all(n in numbers(quote.text) for n in quote.numbers), f"{page}: {quote.numbers} not all in\n{quote.text}"
        if quote.source.endswith(".md"):
            assert quote.source in PAGES, f"{page}: quotes {quote.source}, whose commands the suite does not run"
            theirs = [n for q in quotes(quote.source) if not q.source.endswith(".md") for n in q.numbers]
            wrong = [n for n in quote.numbers if not within_rounding(n, theirs)]
            assert not wrong, f"{page}: {wrong} are not among the numbers {quote.source} quotes from its commands"
        elif quote.source == "python":
            assert quote_source(page, quote), f"{page}: quotes its python blocks, and has none"
        else:
            assert len(quote_source(page, quote)) == 1, f"{page}: {quote.source!r} names no one command of the page"


def test_quoted_numbers_are_read_within_their_rounding():
    assert numbers("lwr_6 at 0.401 N·m, 7.1e-07 rad/s², F_v 10.2 %, -2.93 ± 4.3; v1.2.3") == \
        ["0.401", "7.1e-07", "10.2", "-2.93", "4.3"] and within_rounding("0.401", ["0.4012"])
    assert within_rounding("10", ["10.2"]) and within_rounding("0.42", ["-0.4249"])
    assert within_rounding("7e-07", ["7.1e-07"])
    assert not within_rounding("0.42", ["0.401"]) and not within_rounding("0.401", ["0.4"])
    text = ("Runs:\n\n```bash\nwbfriction fit a -o b.json\n```\n\nF_v 38 against 0.2.\n"
            "<!-- quoted from wbfriction fit a: 38 0.2 -->\n")
    match = QUOTED.search(text)
    assert match and match[1] == "wbfriction fit a" and match[2].split() == ["38", "0.2"]


def test_a_figure_is_taken_from_a_file_or_a_report(tmp_path):
    png = b"\x89PNG\r\n\x1a\n-the-bytes"
    (tmp_path / "demo").mkdir()
    (tmp_path / "demo" / "fig.png").write_bytes(png)
    (tmp_path / "walk_report.html").write_text(f'<p><img id="fig-joint-knee" class="joint-figure" alt="a knee" '
                                               f'src="data:image/png;base64,{base64.b64encode(png).decode()}"></p>')
    assert figure_png(tmp_path, "demo/fig.png") == png
    assert figure_png(tmp_path, "walk_report.fig-joint-knee.png") == png
    assert figure_png(tmp_path, "walk_report.overview.png") is None and figure_png(tmp_path, "other.png") is None
    found = FIGURE.findall("![a](../figures/simulated-walk/walk_report.overview.png) ![b](figures/x/demo/f.png)")
    assert found == [("simulated-walk", "walk_report.overview.png"), ("x", "demo/f.png")]


@pytest.mark.parametrize("page", MANUAL)
def test_a_figure_is_made_by_its_page(page):
    """A page shows only figures its own commands write (a file, or an image of an HTML report), in its own folder
    of ``docs/figures/``; ``test_the_page_runs_as_written`` makes them and fails if one is not."""
    shown = FIGURE.findall((REPO / page).read_text())
    if not shown:
        return
    assert page in PAGES and page != "README.md", f"{page} shows figures, and its commands do not run in the suite"
    written = {o for s in page_steps(page) for o in step_outputs(s)} | set(WRITES.get(page, []))
    for stem, name in shown:
        assert stem == Path(page).stem, f"{page}: figures/{stem}/{name} is not in figures/{Path(page).stem}/"
        report = name.removesuffix(".png").rpartition(".")[0]
        folders = {w.rstrip("/") for w in written}
        assert name in written or f"{report}.html" in written or name.partition("/")[0] in folders and "/" in name, \
            f"{page}: no command of it writes {name}"


SHARED = ("simulate", "estimate", "fit", "report", "export", "predict")
"""The commands that write only the files they name (:func:`outputs`): one command line on the same inputs runs once
per session, whichever pages show it (:func:`shared_key`); the others take its files and output. The tour's walk is on
four pages, its estimate, fit, report and export on two."""


def shared_key(step: Step, cwd: Path) -> str | None:
    """The SHA-256 of a :data:`SHARED` command line and of every file it reads (its words that name a file or a
    folder in ``cwd``), or None for another step. Same inputs, same output bytes: the project's rule."""
    words = shlex.split(step.text) if step.kind == "command" else []
    if words[:1] != ["wbfriction"] or len(words) < 2 or words[1] not in SHARED:
        return None
    digest = hashlib.sha256(step.text.encode())
    for word in words[2:]:
        path = cwd / word
        for file in sorted([path] if path.is_file() else path.rglob("*") if path.is_dir() else []):
            if file.is_file():
                digest.update(f"\0{file.relative_to(cwd)}\0".encode() + hashlib.sha256(file.read_bytes()).digest())
    return digest.hexdigest()


def _copy(source: Path, target: Path) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    if source.is_dir():
        shutil.copytree(source, target, dirs_exist_ok=True)
    else:
        shutil.copy2(source, target)


def _run(step: Step, cwd: Path, env: dict[str, str], shared: Path | None = None) -> subprocess.CompletedProcess:
    """Run one step in ``cwd``; a :data:`SHARED` command already run on the same inputs this session (its files and
    output kept in ``shared``) is not run again: its files are copied and its output returned."""
    if step.kind == "file":
        (cwd / step.name).write_text(step.text)
        return subprocess.CompletedProcess([], 0, "", "")
    key = shared_key(step, cwd) if shared is not None else None
    kept = shared / key if shared is not None and key is not None else None
    if kept is not None and (kept / "stdout").is_file():
        for out in outputs(step.text):
            _copy(kept / "files" / out, cwd / out)
        return subprocess.CompletedProcess([], 0, (kept / "stdout").read_text(), (kept / "stderr").read_text())
    if step.kind == "python":
        argv = [sys.executable, "-c", step.text]
    else:
        argv = shlex.split(step.text)
        argv[0] = os.path.join(str(Path(sys.executable).parent), "wbfriction") if argv[0] == "wbfriction" \
            else sys.executable
    res = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)
    if kept is not None and res.returncode == 0 and all((cwd / o).exists() for o in outputs(step.text)):
        part = kept.with_name(f"{key}.{os.getpid()}.{threading.get_ident()}")
        part.mkdir()
        for out in outputs(step.text):
            _copy(cwd / out, part / "files" / out)
        (part / "stdout").write_text(res.stdout)
        (part / "stderr").write_text(res.stderr)
        try:
            part.rename(kept)  # whole or not at all; another page's run of it may have been first
        except OSError:
            shutil.rmtree(part, ignore_errors=True)
    return res


def run_page(page: str, folder: Path, shared: Path | None = None) -> dict[int, str]:
    """Every step of ``page`` in ``folder``, each once what it reads is written, two at a time; what each step
    printed (its standard output and error), by its index in :func:`page_steps`. ``shared``: a folder where the
    :data:`SHARED` commands' files and output are kept for the other pages of the session (:func:`_run`)."""
    (folder / "examples").symlink_to(REPO / "examples")
    bin_dir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""), MPLBACKEND="Agg")
    if REAL_DATA.is_dir():  # 'wbfriction dataset' offline: the local copy, checked against the same SHA-256
        env.setdefault("WBFRICTION_DATA", str(REAL_DATA))
    steps = page_steps(page)
    deps = needs(steps)
    done: set[int] = set()
    printed: dict[int, str] = {}
    python = ""
    with ThreadPoolExecutor(2) as pool:
        running: dict[Future, int] = {}
        while len(done) < len(steps):
            for i in range(len(steps)):
                if i not in done and i not in running.values() and deps[i] <= done and len(running) < 2:
                    running[pool.submit(_run, steps[i], folder, env, shared)] = i
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                i = running.pop(future)
                step, res = steps[i], future.result()
                what = step.text if step.kind == "command" else f"{step.kind} block {i}"
                assert res.returncode == 0, f"{page}: {what}\n{res.stderr[-2000:]}"
                for out in step_outputs(step):
                    assert (folder / out).exists(), f"{page}: {what}: wrote no {out}"
                for pattern in EXPECTED.get(step.text, []):
                    assert re.search(pattern, res.stdout, re.M), f"{what}: {pattern!r} not in\n{res.stdout}"
                printed[i] = res.stdout + res.stderr
                if step.kind == "python":
                    python += res.stdout
                done.add(i)
    for pattern in PRINTS.get(page, []):
        assert re.search(pattern, python, re.M), f"{page}: {pattern!r} not in\n{python}"
    for name in WRITES.get(page, []):
        assert (folder / name).exists(), f"{page}: its python blocks wrote no {name}"
    return printed


def _params() -> list:
    out = []
    for page in PAGES:
        commands = page_commands(page)
        marks = [] if page in QUICK else [pytest.mark.slow]
        if any(c.startswith("wbfriction dataset") for c in commands):
            marks.append(pytest.mark.skipif(not REAL_DATA.is_dir(), reason=f"{page} reads the real datasets: "
                                            f"not at {REAL_DATA} (set WBFRICTION_DATA)"))
        out.append(pytest.param(page, marks=marks, id=page))
    return out


@pytest.fixture(scope="session")
def shared_runs(tmp_path_factory) -> Path:
    """Where the :data:`SHARED` commands' files are kept: one folder for the session, the workers of ``-n 2`` too
    (their temporary folders' parent)."""
    base = tmp_path_factory.getbasetemp()
    folder = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "page-commands"
    folder.mkdir(exist_ok=True)
    return folder


@pytest.mark.parametrize("page", _params())
def test_the_page_runs_as_written(page, tmp_path, shared_runs):
    if not page_steps(page):
        pytest.skip(f"{page} runs nothing")
    printed = run_page(page, tmp_path, shared_runs)
    check_quotes(page, printed)
    make_figures(page, tmp_path)
