"""Provenance records: which inputs, robot and version an output was made from.

Each output of the command line records where it came from, so that a table, a parameter
file or a report can be traced to the bytes of its inputs (SHA-256) and the package version.
"""

from __future__ import annotations

import os
import platform
import time
from importlib import metadata
from pathlib import Path
from typing import Any

from wbfriction.logs.tables import file_sha256
from wbfriction.model.robot import Robot
from wbfriction.version import __version__


def log_provenance(log: str | Path, robot: Robot) -> dict[str, Any]:
    """The provenance of an output made from a log with a robot model: the log and its SHA-256
    (of a bag: over its files), the robot's name and URDF, the package version.

    Raises:
        InputError: a missing log.
    """
    return {"log": str(log), "log_sha256": file_sha256(log), "robot": robot.name, "urdf": str(robot.urdf),
            "wbfriction": __version__}


def file_provenance(key: str, path: str | Path) -> dict[str, Any]:
    """The provenance of an output made from one file: ``{key: path, key_sha256: ..., wbfriction: version}``.

    Raises:
        InputError: a missing file.
    """
    return {key: str(path), f"{key}_sha256": file_sha256(path), "wbfriction": __version__}


DEPENDENCIES = ("pin", "mujoco", "numpy", "scipy", "pyarrow", "matplotlib", "example-robot-data", "typer")
"""The distributions whose versions an output's provenance names (PyPI names)."""


def dependency_versions() -> list[tuple[str, str]]:
    """(name, version) of wbfriction, Python and every distribution of :data:`DEPENDENCIES` as installed
    ("not installed" for one that is not), read from the installed metadata without importing them."""
    versions = [("wbfriction", __version__), ("Python", platform.python_version())]
    for name in DEPENDENCIES:
        try:
            versions.append((name, metadata.version(name)))
        except metadata.PackageNotFoundError:
            versions.append((name, "not installed"))
    return versions


def output_date() -> str:
    """The date an output is made, ISO 8601 (UTC): that of ``SOURCE_DATE_EPOCH`` when set (the reproducible-builds
    convention: the same inputs then give the same bytes on any day), else today's."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    seconds = float(epoch) if epoch.isdigit() else time.time()
    return time.strftime("%Y-%m-%d", time.gmtime(seconds))
