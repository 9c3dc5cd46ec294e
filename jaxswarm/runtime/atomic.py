"""Atomic file writes: a hidden temporary file beside the target, moved over it with os.replace.

A reader never sees a half-written file, an existing file stays intact until its replacement is
complete, and an interrupted write leaves at most a hidden ``.NAME.PID.TOKEN.tmp`` file (which
readers of Parquet datasets skip) instead of a damaged ``NAME``. The writer's pid in the name
tells a file that a live process is still writing from one a killed process left behind
(:func:`abandoned_temporaries`).
"""
from __future__ import annotations

import contextlib
import csv
import os
import secrets
from collections.abc import Iterable, Iterator, Mapping, Sequence
from pathlib import Path

from jaxswarm.runtime.lock import process_alive

TEMPORARY_GLOB = ".*.tmp"
"""Matches the temporary files :func:`atomic_path` creates (for cleaning up after a crash)."""


@contextlib.contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a fresh temporary path beside ``path`` (parent directories are created); if the
    block ends without an exception the file written there replaces ``path``, otherwise it is
    deleted. Files are created by the caller, so they get the usual umask permissions."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(6)}.tmp")
    try:
        yield temporary
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)  # gone already after a successful replace


def abandoned_temporaries(folder) -> list[Path]:
    """The temporary files of :func:`atomic_path` in ``folder`` whose writer is no longer running
    on this host, sorted (a file without a pid in its name, of jaxswarm 0.10 or older, is left
    out: nothing tells whether its writer is alive)."""
    abandoned = []
    for temporary in sorted(Path(folder).glob(TEMPORARY_GLOB)):
        pid = temporary.name.split(".")[-3]
        if pid.isdigit() and int(pid) > 0 and not process_alive(int(pid)):
            abandoned.append(temporary)
    return abandoned


def write_atomically(path, data: str | bytes) -> None:
    """Write text (UTF-8) or bytes to ``path`` atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as temporary:
        if isinstance(data, str):
            temporary.write_text(data, encoding="utf-8")
        else:
            temporary.write_bytes(data)


def write_csv(path, rows: Iterable[Mapping], columns: Sequence[str]) -> None:
    """Write ``rows`` (dicts) as a UTF-8 CSV file with a header, columns in the order given,
    atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as temporary, open(temporary, "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=list(columns))
        writer.writeheader()
        writer.writerows(rows)
