"""Progress on standard error (issue 67): one plain line per stage when it is piped, a bar with the share done and
the time left on a terminal (:mod:`wbfriction.cli.stages`); the results on standard output untouched."""

from __future__ import annotations

import io
import re
import time

import pytest
from rich.console import Console

from helpers import STAGE_LINE, assert_stages, run_cli_printed, stage_lines
from wbfriction.cli.stages import Stages, stage_line


def piped() -> tuple[Console, io.StringIO]:
    text = io.StringIO()
    return Console(file=text, force_terminal=False, width=100), text


def test_off_a_terminal_each_stage_is_one_line_with_its_items_and_time():
    console, text = piped()
    with Stages(console) as stages:
        stages("reading friction.parquet")
        advance = stages.steps("fit", 12, "joints")
        for _ in range(12):
            advance(1)
        stages("a stage whose label is far too long to fit on one line of a hundred characters, so it is cut "
               "short with three dots")
    lines = text.getvalue().splitlines()
    assert [STAGE_LINE.fullmatch(line)["label"] for line in lines][:2] == ["reading friction.parquet", "fit"]
    fit = STAGE_LINE.fullmatch(lines[1])
    assert (fit["items"], fit["unit"]) == ("12", "joints")  # the joints told, as many as there are
    assert len(lines) == 3 and all(len(line) <= 100 for line in lines) and lines[2].split(":")[0].endswith("...")
    assert "\r" not in text.getvalue() and "\x1b" not in text.getvalue()


def test_the_times_are_each_stages_own():
    console, text = piped()
    with Stages(console) as stages:
        stages("first")
        time.sleep(0.25)
        stages("second")
    first, second = (float(STAGE_LINE.fullmatch(line)["seconds"]) for line in text.getvalue().splitlines())
    assert 0.2 <= first < 1.0 and second < 0.2


def test_a_stage_that_fails_says_nothing():
    console, text = piped()
    with pytest.raises(RuntimeError), Stages(console) as stages:
        stages("done")
        stages("failing")
        raise RuntimeError("the error says what happened")
    assert [STAGE_LINE.fullmatch(line)["label"] for line in text.getvalue().splitlines()] == ["done"]


def test_stage_line_is_short():
    assert stage_line("fit", 81.24, 12, "joints") == "fit: 12 joints in 81.2 s"
    long = stage_line("x" * 300, 1.0)
    assert len(long) == 100 and long.endswith("x...: 1.0 s")


def test_on_a_terminal_a_bar_shows_the_share_done_and_the_time_left():
    text = io.StringIO()
    console = Console(file=text, force_terminal=True, width=100)
    with Stages(console) as stages:
        advance = stages.steps("simulate", 400, "samples")
        for _ in range(3):  # a rate measured: the time left is known
            time.sleep(0.05)
            advance(50)
        assert stages.bars is not None
        stages.bars.refresh()
        shown = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", text.getvalue())
    last = shown.replace("\r", "\n").splitlines()[-1]
    assert "simulate" in last and "38%" in last, last  # 150 of 400
    left = re.search(r"left (\d+):(\d\d):(\d\d)", last)
    assert left is not None, last  # 250 samples at about 1000 a second: a fraction of a second left
    assert int(left[1]) == int(left[2]) == 0 and int(left[3]) <= 2, last


def test_commands_print_a_line_per_stage_when_piped(capsys, tmp_path):
    """A short simulated Panda through the pipeline a user runs, each command in this process with its standard error
    captured (not a terminal): every stage says itself, the results stay on standard output."""
    log, friction, params = tmp_path / "arm.parquet", tmp_path / "friction.parquet", tmp_path / "params.json"
    code, out, err = run_cli_printed(capsys, "simulate", "--robot", "panda", "-o", log, "--duration", "2")
    assert code == 0, err
    found = assert_stages(err, "simulate")
    assert int(found["simulate"]["items"]) == 2000 and not stage_lines(out)  # 2 s at 1 kHz
    code, _, err = run_cli_printed(capsys, "estimate", log, "--robot", "panda", "-o", friction)
    assert code == 0, err
    assert int(assert_stages(err, "estimate")["estimate"]["items"]) == 2000
    code, out, err = run_cli_printed(capsys, "fit", friction, "-o", params, "--model", "coulomb-viscous",
                                     "--terms", "none", "--workers", "1")
    assert code == 0, err
    assert int(assert_stages(err, "reading friction.parquet", "fit")["fit"]["items"]) == 7  # the arm's joints
    assert not stage_lines(out)
    for args, labels in ((("predict", friction, "--params", params), ("predicting",)),
                         (("export", params, "--robot", "panda", "--include", "weak,does-not-predict", "-o",
                           tmp_path / "panda.xml"), ("exporting",))):
        code, _, err = run_cli_printed(capsys, *args)
        assert code == 0, err
        assert_stages(err, *labels)
