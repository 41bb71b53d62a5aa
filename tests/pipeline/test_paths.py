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
