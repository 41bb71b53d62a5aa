"""The README's and the manual's commands run as written (issue 24, item 5; issue 54, items 4 and 5).

Every ``bash`` and ``python`` block of the README, of the manual's Getting started, tutorials, how-to guides and
guide to extending (:data:`PAGES`) runs as written, in the order of its page, from a fresh folder per page that
holds ``examples/`` beside the outputs (a copy of the checkout's layout): each command line exits 0 and writes what
its ``-o`` names, no two lines of a page write the same file, and a command waits only for the earlier ones whose
outputs it reads (two run at a time: the machine's two cores). A ``python`` block runs once everything before it
has, and whatever follows waits for it. Marks, an HTML comment on the line before a fenced block:

* ``<!-- not run: REASON -->``: the block is not run (an install, ``mkdocs serve``);
* ``<!-- write: FILE -->``: the block's text is written to ``FILE`` in the page's folder first (a TOML a command
  reads), so that what the page shows is what runs.

The manual's other pages (reference, explanation, measurements: the full-size commands that measured its numbers,
minutes to hours each) are not run here. A page whose commands fetch a real dataset (``wbfriction dataset``) reads
it from ``WBFRICTION_DATA`` (else ``../shared/real-data``) and is skipped without it.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
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

FENCE = re.compile(r"(?:^<!-- (not run|write): *(.*?) -->\n)?^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)
"""A fenced block and the mark on the line before it, if any."""


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
    "go2_excite.png": [r"^worst: \w+_calf_joint offset, 0\.2\d of its limit \(below 1: predicted ok\)$"],
    # TALOS on one foot: the ZMP of the designed stance well inside the stance sole (its edges 10 mm at the least)
    "wbfriction excite --robot talos --stance left -o talos_stance.parquet --json talos_stance.json --figure "
    "talos_stance.png": [r"^ZMP [2-9]\d\.\d mm inside the left sole's edges \(at least 10\)"],
    # the Go2 on three feet: its centre of mass and ZMP near the stance triangle's inradius (104 mm) from its edges
    "wbfriction excite --robot go2_walking --swing FR -o go2_tripod.parquet --json go2_tripod.json --figure "
    "go2_tripod.png": [r"^centre of mass 10\d\.\d mm \(at least 50\) and ZMP \d{2,3}\.\d mm \(at least 30\)"],
    # what to record next after the real Aliengo's log: every parameter predicted ok under its model
    "wbfriction excite --config aliengo_identified.toml --after aliengo_params.json -o aliengo_next.parquet --json "
    "aliengo_next.json --figure aliengo_next.png": [r"^worst: \w+ \w+, 0\.[0-5]\d of its limit",
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
    "docs/how-to/excitation.md": [r"^48 of 48 parameters ok; 4[3-8] of 48 standard errors within 1\.5x of the "
                                  r"prediction$",
                                  # the Panda's design played: every joint ok, its errors near those predicted
                                  r"^7 of 7 joints ok; F_c and F_v: 1[0-4] of 14 standard errors within 1\.5x of "
                                  r"the prediction$",
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
                          # a simulator registered, run by simulate, its injected friction fitted back
                          r"^sine_arm\.parquet: panda_joint1: F_c 0\.(59|60|61) N·m, F_v 0\.(29|30|31) N·m·s/rad$"],
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
    "docs/how-to/library.md": ["api_params.json"],
    "docs/extending.md": ["arm.tsv", "arm_effort.parquet", "panda_friction.csv", "panda_extended.xml",
                          "sine_arm.parquet"],
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


def _run(step: Step, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess:
    if step.kind == "file":
        (cwd / step.name).write_text(step.text)
        return subprocess.CompletedProcess([], 0, "", "")
    if step.kind == "python":
        argv = [sys.executable, "-c", step.text]
    else:
        argv = shlex.split(step.text)
        argv[0] = os.path.join(str(Path(sys.executable).parent), "wbfriction") if argv[0] == "wbfriction" \
            else sys.executable
    return subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)


def run_page(page: str, folder: Path) -> None:
    """Every step of ``page`` in ``folder``, each once what it reads is written, two at a time."""
    (folder / "examples").symlink_to(REPO / "examples")
    bin_dir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""), MPLBACKEND="Agg")
    if REAL_DATA.is_dir():  # 'wbfriction dataset' offline: the local copy, checked against the same SHA-256
        env.setdefault("WBFRICTION_DATA", str(REAL_DATA))
    steps = page_steps(page)
    deps = needs(steps)
    done: set[int] = set()
    printed = ""
    with ThreadPoolExecutor(2) as pool:
        running: dict[Future, int] = {}
        while len(done) < len(steps):
            for i in range(len(steps)):
                if i not in done and i not in running.values() and deps[i] <= done and len(running) < 2:
                    running[pool.submit(_run, steps[i], folder, env)] = i
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
                if step.kind == "python":
                    printed += res.stdout
                done.add(i)
    for pattern in PRINTS.get(page, []):
        assert re.search(pattern, printed, re.M), f"{page}: {pattern!r} not in\n{printed}"
    for name in WRITES.get(page, []):
        assert (folder / name).exists(), f"{page}: its python blocks wrote no {name}"


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


@pytest.mark.parametrize("page", _params())
def test_the_page_runs_as_written(page, tmp_path):
    if not page_steps(page):
        pytest.skip(f"{page} runs nothing")
    run_page(page, tmp_path)
