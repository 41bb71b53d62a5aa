"""Where a command writes, checked before any work (:mod:`wbfriction.pipeline.paths`)."""

from __future__ import annotations

import pytest

from helpers import run_cli


@pytest.mark.parametrize("args", [("dataset", "panda", "-o", ""), ("dataset", "panda", "--output-dir="),
                                  ("estimate", "x.parquet", "--output", " "), ("fit", "x.parquet", "-o", "")])
def test_an_empty_output_path_is_refused_naming_the_option(capsys, tmp_path, monkeypatch, args):
    """Issue 53: ``-o ""`` is Path(""), the working folder: a dataset was written into it. Refused in one line
    naming the option, nothing written."""
    monkeypatch.chdir(tmp_path)
    code, err = run_cli(capsys, *args)
    option = next(a.partition("=")[0] for a in args if a.startswith("-"))
    assert code == 2
    assert err.strip() == f"error: {option} must be a file or folder to write, not an empty path, got ''"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", ["study-quadruped", "study-filters", "demo"])
def test_an_output_folder_that_cannot_be_made_is_refused_before_the_work(tmp_path, capsys, command):
    """Issue 65, class 3: ``study-quadruped -o <a file>/study`` simulated, estimated and fitted, printed 34 lines,
    then failed. Every command that writes into a folder checks it first: under a file, a file itself, or in a
    read-only folder, one line and nothing else printed."""
    import os
    import time

    from helpers import run_cli

    a_file = tmp_path / "a_file"
    a_file.write_text("not a folder")
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        cases = [(a_file / "study", "[Errno 20] Not a directory"), (a_file, "[Errno 17] File exists")]
        if os.geteuid() != 0:  # root writes anywhere
            cases += [(locked / "study", "[Errno 13] Permission denied"), (locked, "[Errno 13] Permission denied")]
        for folder, reason in cases:
            began = time.perf_counter()
            code, err = run_cli(capsys, command, "-o", folder)
            assert code == 1 and err.strip() == f"error: {folder}: cannot be written: {reason} (nothing written)", err
            assert time.perf_counter() - began < 10.0  # the study takes minutes
    finally:
        locked.chmod(0o755)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file", "locked"] and not any(locked.iterdir())
