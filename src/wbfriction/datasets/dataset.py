"""A real robot's public dataset: its files, how they become wbfriction logs, its published reference; the registry.

A dataset is one :class:`Dataset` subclass in a module of its own (:mod:`~wbfriction.datasets.kuka`,
:mod:`~wbfriction.datasets.ur10e`, :mod:`~wbfriction.datasets.panda`), registered under the name
``wbfriction dataset NAME`` takes (:func:`register`). It names its files (:class:`~wbfriction.datasets.store.
RemoteFile`: repository, commit, path, SHA-256), converts them into the log format with the robot's configuration
beside them (:meth:`Dataset.write`: the logs as recorded, nothing filtered or resampled), and says what a user
runs next and what the published reference is (:mod:`~wbfriction.datasets.reference`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from wbfriction.datasets.store import RemoteFile, fetch_files
from wbfriction.exceptions import InputError


@dataclass(frozen=True)
class WrittenDataset:
    """What :meth:`Dataset.write` wrote.

    Attributes:
        name: the dataset (``wbfriction dataset NAME``).
        logs: each log written, by its role (e.g. ``"train"``, ``"held_out"``), in the order a user meets them.
        rows: the samples of each log, by the same roles.
        config: the robot's configuration (TOML) written beside the logs; it names the robot's URDF (copied beside
            it, or from the installed ``example-robot-data``), so ``--config <config>`` is the whole robot.
        commands: what a user runs next, one command a line (paths as written, quoted for a POSIX shell).
        described: one phrase per log for the terminal (``"runs 1 and 2"``), by role.
    """

    name: str
    logs: dict[str, Path]
    rows: dict[str, int]
    config: Path
    commands: tuple[str, ...] = ()
    described: dict[str, str] = field(default_factory=dict)


class Dataset(ABC):
    """A public dataset of real robot logs (module docstring).

    Subclasses set the class attributes and implement :meth:`write`.
    """

    name: ClassVar[str]
    """The name ``wbfriction dataset`` takes (``"kuka-lwr4"``)."""
    folder: ClassVar[str]
    """Its folder in the cache and in :data:`~wbfriction.datasets.store.DATA_ENV`'s copy (``"kuka_lwr4"``)."""
    summary: ClassVar[str]
    """One phrase for the help: the robot, its sensors, the logs, the download's size."""
    files: ClassVar[tuple[RemoteFile, ...]]
    """Every file of the dataset, each from a fixed commit, with its SHA-256."""

    def fetch(self, base: str | None = None) -> dict[str, Path]:
        """The dataset's files (by name), fetched and checked (:func:`~wbfriction.datasets.store.fetch_files`).

        Raises:
            InputError: a missing, damaged or undownloadable file.
            OutputError: the cache cannot be written.
        """
        return fetch_files(self.folder, self.files, base)

    @abstractmethod
    def write(self, directory: str | Path, files: dict[str, Path] | None = None) -> WrittenDataset:
        """Write the dataset's logs (the log format, stamps as recorded) and the robot's configuration into
        ``directory`` (made if missing; each file written whole or not at all).

        Args:
            directory: the output folder.
            files: the dataset's files (default: :meth:`fetch`).

        Raises:
            InputError: what :meth:`fetch` raises; a file that does not read as the dataset's format.
            OutputError: the folder or a file cannot be written.
        """


DATASETS: dict[str, Dataset] = {}
"""The registered datasets by name (:func:`register`), in the order they were registered."""


def register(cls: type[Dataset]) -> type[Dataset]:
    """Class decorator: one instance of ``cls`` in :data:`DATASETS` under ``cls.name``."""
    DATASETS[cls.name] = cls()
    return cls


def dataset(name: str) -> Dataset:
    """The registered dataset ``name``.

    Raises:
        InputError: an unknown name, listing the known ones.
    """
    try:
        return DATASETS[name]
    except KeyError:
        raise InputError(f"unknown dataset '{name}' (one of {', '.join(DATASETS)})") from None
