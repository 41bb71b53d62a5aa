"""Files of a public repository, fetched once and checked: pooch (URL pinned to a commit + SHA-256) or a local copy.

Every file of a dataset (:class:`RemoteFile`) is named by the repository it comes from, a commit and its path
there, and its SHA-256. :func:`fetch_files` downloads the files into the user's cache
(``pooch.os_cache("wbfriction")/<folder>``, e.g. ``~/.cache/wbfriction/ur10e``) on first use, or, where the
environment variable :data:`DATA_ENV` (``WBFRICTION_DATA``) names a folder, reads them from
``$WBFRICTION_DATA/<folder>/<file>`` (offline machines, continuous integration: nothing downloaded). Either way
each file must have its SHA-256: a damaged or another copy is refused, naming it.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from wbfriction.exceptions import InputError
from wbfriction.logs.tables import file_sha256, output_error

DATA_ENV = "WBFRICTION_DATA"
"""Environment variable: a folder holding local copies of the datasets (``<folder>/<dataset folder>/<file>``),
used instead of downloading."""

GITHUB_RAW = "https://raw.githubusercontent.com"
"""Where GitHub serves a repository's files, by ``<owner>/<name>/<commit>/<path>``."""


@dataclass(frozen=True)
class RemoteFile:
    """One file of a dataset, as a public repository holds it.

    Attributes:
        name: the file's name in the dataset's folder (the cache, :data:`DATA_ENV`'s copy).
        repository: ``owner/name`` on GitHub.
        commit: the commit (40 hex digits) whose file this is: the URL never moves.
        path: its path in the repository at that commit.
        sha256: its SHA-256 (hex): a download or a local copy that differs is refused.
    """

    name: str
    repository: str
    commit: str
    path: str
    sha256: str

    def url(self, base: str | None = None) -> str:
        """The URL it is downloaded from: ``<base>/<repository>/<commit>/<path>`` (``base``: :data:`GITHUB_RAW`)."""
        return f"{GITHUB_RAW if base is None else base}/{self.repository}/{self.commit}/{self.path}"


def local_folder(folder: str) -> Path | None:
    """The folder :data:`DATA_ENV` names for the dataset folder ``folder`` (``$WBFRICTION_DATA/<folder>``), or
    None when the variable is not set (or empty)."""
    root = os.environ.get(DATA_ENV, "")
    return Path(root).expanduser() / folder if root else None


def verified_copy(folder: Path, file: RemoteFile, others: Sequence[RemoteFile] = ()) -> Path:
    """``file`` in the local copy ``folder``, once its SHA-256 is the expected one.

    Raises:
        InputError: the file is not in ``folder`` (naming it, :data:`DATA_ENV` and the files the folder must
            hold, ``others``), or its SHA-256 differs (naming the file, the expected and the found hash, and
            where the original is).
    """
    path = folder / file.name
    if not path.is_file():
        names = ", ".join(f.name for f in others) or file.name
        raise InputError(f"{path}: not found ({DATA_ENV}={os.environ.get(DATA_ENV, '')} names a local copy of the "
                         f"datasets; its {folder.name} folder must hold {names})")
    found = file_sha256(path)
    if found != file.sha256:
        raise InputError(f"{path}: SHA-256 {found}, expected {file.sha256}: not {file.repository}'s file, refused "
                         f"(a damaged or different copy; the original is {file.url()})")
    return path


def downloaded(folder: str, files: Sequence[RemoteFile], base: str | None = None) -> dict[str, Path]:
    """``files`` in the user's cache (``pooch.os_cache("wbfriction")/<folder>``), downloaded there first if they
    are not, each checked by pooch against its SHA-256 (a cached file that differs is downloaded again).

    Args:
        folder: the dataset's folder name.
        files: what to fetch.
        base: where the repositories are served (default :data:`GITHUB_RAW`; a test serves its own).

    Raises:
        InputError: a file that cannot be downloaded (no network, the server's refusal), or whose download
            differs from its SHA-256, naming it, the URL and the reason, and :data:`DATA_ENV` as the way to
            work offline.
        OutputError: the cache folder cannot be written.
    """
    import pooch
    import requests

    cache = Path(pooch.os_cache("wbfriction")) / folder
    urls = {f.name: f.url(base) for f in files}
    store = pooch.create(path=cache, base_url="", registry={f.name: f"sha256:{f.sha256}" for f in files}, urls=urls,
                         retry_if_failed=2)
    offline = (f"set {DATA_ENV} to a folder holding {folder}/{{name}} (a copy of the repository's files) to work "
               "offline")
    paths = {}
    logger = pooch.get_logger()  # its retries' lines ("Failed to download ... Will retry") would come first
    level = logger.level
    logger.setLevel("WARNING")
    try:
        for f in files:
            try:
                paths[f.name] = Path(store.fetch(f.name))
            except requests.RequestException as exc:
                reason = " ".join(str(exc).split()) or type(exc).__name__
                raise InputError(f"{f.name}: cannot be downloaded from {urls[f.name]} ({reason}); "
                                 + offline.format(name=f.name)) from exc
            except ValueError as exc:  # pooch: the download's hash is not the registry's
                reason = " ".join(str(exc).split())
                raise InputError(f"{f.name}: the file downloaded from {urls[f.name]} is refused ({reason}); "
                                 + offline.format(name=f.name)) from exc
            except OSError as exc:
                raise output_error(cache / f.name, exc) from exc
    finally:
        logger.setLevel(level)
    return paths


def fetch_files(folder: str, files: Sequence[RemoteFile], base: str | None = None) -> dict[str, Path]:
    """The paths of ``files`` (by name): from ``$WBFRICTION_DATA/<folder>/`` when :data:`DATA_ENV` is set,
    else from the user's cache, downloaded there on first use (:func:`downloaded`). Either way each file's
    SHA-256 is checked.

    Raises:
        InputError: a local copy missing a file or holding one that differs; a file that cannot be downloaded
            or whose download differs (naming it and saying to set :data:`DATA_ENV`).
        OutputError: the cache folder cannot be written.
    """
    local = local_folder(folder)
    if local is not None:
        return {f.name: verified_copy(local, f, files) for f in files}
    return downloaded(folder, files, base)
