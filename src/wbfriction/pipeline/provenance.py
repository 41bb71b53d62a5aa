"""Provenance records: which inputs, robot and version an output was made from.

Each output of the command line records where it came from, so that a table, a parameter
file or a report can be traced to the bytes of its inputs (SHA-256) and the package version.
"""

from __future__ import annotations

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
