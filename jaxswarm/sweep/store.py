"""The results store: a Parquet dataset written one finished chunk at a time, plus metadata.

Layout of a store directory::

    metadata.json        package and JAX versions, spec, the swarm's definition (its name, every
                         config field and default param), seeds, git commit, maps, and what the
                         rows depend on outside the spec (``depends_on``: the SHA-256 of every
                         map and scenario file read, a tuner's version and sampler)
    .lock                the writer's lock (:mod:`jaxswarm.runtime.lock`)
    runs/part-MMM-CCCCC.parquet   one file per finished chunk (map MMM, chunk CCCCC)

A chunk is written to a hidden temporary file in ``runs/`` and moved into place with
``os.replace``, so a reader (``pandas.read_parquet(store / "runs")``, which skips hidden files)
never sees half a chunk, and a killed sweep leaves only whole chunks behind. One process writes a
store at a time: the writer holds the store's lock from opening it (where it checks and writes the
metadata) until it lets go of the store, and removes only the temporary files of writers that are
no longer running. Reopening a store for the same spec, the same swarm definition and the same
``depends_on`` finds the finished chunks (resume). Anything else is refused, naming what differs:
a different spec, a swarm that has changed under its name (another recorded definition, or a
store of a release older than the one since which the swarm gives the same results:
:data:`SAME_RESULTS_SINCE`), a map file edited since the store was written, a file in
``runs/`` that is not one of its chunks, a ``metadata.json`` that cannot be read, chunks without
a ``metadata.json``.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from jaxswarm.runtime.atomic import abandoned_temporaries, atomic_path, write_atomically
from jaxswarm.runtime.lock import FolderLockedError, lock_folder

CHUNK_NAME = re.compile(r"part-\d{3,}-\d{5,}\.parquet")
"""The name of a finished chunk in ``runs/``."""
TEMPORARY_NAME = re.compile(r"\..+\.tmp")
"""The name of a chunk being written (:func:`~jaxswarm.runtime.atomic.atomic_path`'s)."""


class StoreMismatchError(ValueError):
    """The directory holds results of a different sweep spec or swarm definition, results that
    depend on other files, or files the store cannot vouch for."""


class StoreBusyError(ValueError):
    """Another process is writing the store."""


class ResultsStore:
    """One sweep's results directory (see the module docstring)."""

    def __init__(self, root, spec: dict, metadata: dict, *, depends_on: dict | None = None,
                 writer: bool = True):
        """Open (or create) the store at ``root`` for ``spec`` (the spec's ``as_dict()``).

        The writer (process 0 of a multi-host sweep; the only process otherwise) takes the
        store's lock, removes the temporary files of writers that are no longer running and
        writes ``metadata`` (with the spec under ``"spec"`` and ``depends_on``) for a new
        store; other processes only read it. ``metadata["swarm"]`` (see
        :func:`jaxswarm.swarm.definition`) must equal the stored one for a resume, and so must
        ``depends_on``.

        Args:
          depends_on: what the rows depend on outside the spec, name -> a JSON record: a file's
            ``{"file": PATH, "sha256": HEX}`` (:func:`jaxswarm.sweep.spec.file_digests`), or
            any other record (a tuner's version and sampler).

        Raises:
          StoreBusyError: another process is writing the store (named with its pid and host).
          StoreMismatchError: ``root`` already holds results of another spec, of another
            definition of the swarm or depending on other files or records; ``runs/`` holds a
            file that is not a chunk, or chunks without a ``metadata.json``; ``metadata.json``
            cannot be read.
        """
        self.root = Path(root)
        self.runs = self.root / "runs"
        self.runs.mkdir(parents=True, exist_ok=True)
        depends_on = json.loads(json.dumps(depends_on or {}, default=str))
        self._lock = None  # a writer holds the lock for as long as the store lives
        if writer:
            try:
                self._lock = lock_folder(self.root)
            except FolderLockedError as error:
                raise StoreBusyError(f"{error}; wait for it to finish, or choose another "
                                     "--out") from None
            for abandoned in abandoned_temporaries(self.runs):
                abandoned.unlink(missing_ok=True)
        check_chunk_files(self.root)
        existing = self.read_metadata(self.root)
        as_stored = json.loads(json.dumps(spec, default=str))  # the spec as JSON gives it back
        if existing is None:
            if any(self.runs.glob("part-*.parquet")):
                raise StoreMismatchError(
                    f"{self.runs} holds chunks but {self.root / 'metadata.json'} is missing, so "
                    "nothing says what they are; choose another --out or delete it")
            if writer:
                write_atomically(self.root / "metadata.json", json.dumps(
                    dict(metadata, spec=spec, depends_on=depends_on), indent=2, default=str))
        elif existing.get("spec") != as_stored:
            raise StoreMismatchError(
                f"{self.root} holds results of a different sweep (differs in: "
                f"{', '.join(_differences(existing.get('spec', {}), as_stored))}); "
                "choose another --out or delete it")
        else:
            _check_definition(self.root, existing, json.loads(json.dumps(
                metadata["swarm"], default=str)))
            _check_depends_on(self.root, existing, depends_on)

    def chunk_path(self, map_index: int, chunk_index: int) -> Path:
        """Where chunk ``chunk_index`` of map ``map_index`` lives once finished."""
        return self.runs / f"part-{map_index:03d}-{chunk_index:05d}.parquet"

    def finished(self, map_index: int, chunk_index: int) -> bool:
        """Whether that chunk was written completely."""
        return self.chunk_path(map_index, chunk_index).is_file()

    def write_chunk(self, map_index: int, chunk_index: int, rows: dict) -> Path:
        """Write one chunk's rows (column name -> list or array, equal lengths) atomically."""
        path = self.chunk_path(map_index, chunk_index)
        with atomic_path(path) as temporary:
            pq.write_table(pa.table(rows), temporary)
        return path

    @staticmethod
    def read_metadata(root) -> dict | None:
        """The store's metadata record, or None if there is none yet.

        Raises:
          StoreMismatchError: ``metadata.json`` is not a JSON object in UTF-8 (named with its
            path, line and column).
        """
        path = Path(root) / "metadata.json"
        if not path.is_file():
            return None
        try:
            metadata = json.loads(path.read_text(encoding="utf-8"))
        except UnicodeDecodeError as error:
            raise StoreMismatchError(f"{path}: not UTF-8 text (byte {error.start}); not a store's "
                                     "metadata: choose another --out or delete it") from None
        except json.JSONDecodeError as error:
            raise StoreMismatchError(
                f"{path}: line {error.lineno} column {error.colno}: not valid JSON "
                f"({error.msg}); not a store's metadata: choose another --out or delete it"
            ) from None
        if not isinstance(metadata, dict):
            raise StoreMismatchError(f"{path}: a JSON {type(metadata).__name__}, not the object "
                                     "of a store's metadata: choose another --out or delete it")
        return metadata


def check_chunk_files(root) -> None:
    """Check that the ``runs/`` folder of the store at ``root`` holds only finished chunks and
    chunks being written (a reader would take any other Parquet file for rows).

    Raises:
      StoreMismatchError: naming the first file that is neither.
    """
    runs = Path(root) / "runs"
    for path in sorted(runs.iterdir()) if runs.is_dir() else ():
        if not (path.is_file() and (CHUNK_NAME.fullmatch(path.name)
                                    or TEMPORARY_NAME.fullmatch(path.name))):
            raise StoreMismatchError(
                f"{path}: not a chunk of the store {root} (its chunks are "
                "runs/part-MMM-CCCCC.parquet); move it out of the store")


def _check_depends_on(root: Path, existing: dict, depends_on: dict) -> None:
    """Refuse to resume a store whose rows depend on other files or records than today's.

    Raises:
      StoreMismatchError: naming the file whose content changed (its SHA-256 then and now) or
        the record that differs, or the jaxswarm version that wrote a store without the record.
    """
    stored = existing.get("depends_on")
    if stored is None:
        if depends_on:
            raise StoreMismatchError(
                f"{root} was written by jaxswarm {existing.get('jaxswarm')}, which did not record "
                f"what its rows depend on ({', '.join(sorted(depends_on))}), so nothing says "
                "they were computed from today's; choose another --out or delete it")
        return
    for name in sorted(set(stored) | set(depends_on)):
        then, now = stored.get(name), depends_on.get(name)
        if _is_file(then) and _is_file(now):
            if then["sha256"] == now["sha256"]:
                continue  # the same content, wherever the file is found today
            raise StoreMismatchError(
                f"{now.get('file')} changed since {root} was written from it ({name}: SHA-256 "
                f"{then.get('sha256')} then, {now.get('sha256')} now); its rows would mix two "
                "maps: restore the file, or choose another --out")
        if then != now:
            raise StoreMismatchError(
                f"{root} holds results that depend on {name} = {then!r}, not {now!r}; choose "
                "another --out or delete it")


def _is_file(record) -> bool:
    """Whether a ``depends_on`` record is a file's (``{"file": PATH, "sha256": HEX}``)."""
    return isinstance(record, dict) and "sha256" in record


def _differences(before: dict, after: dict) -> list[str]:
    """The keys whose values differ between two dicts, sorted."""
    return sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))


SAME_RESULTS_SINCE = {
    "aco_star": (0, 7), "ant_system": (0, 8), "cabc": (0, 7), "improved_max_min_aco": (0, 7),
    "iwd": (0, 8), "iwd_pg": (0, 7), "max_min_aco": (0, 8), "rfd": (0, 8), "rfd_graded": (0, 7),
    "rfd_star": (0, 7)}
"""Per registered swarm, ``(major, minor)``: a store written by an older release is refused."""


def _older_release(version: str | None, since: tuple[int, int]) -> bool:
    """Whether a version string (``0.2.0``, ``0.3.0.dev1``) is a release before ``since``;
    False when unknown (a source checkout that was not installed)."""
    try:
        return tuple(int(part) for part in (version or "").split(".")[:2]) < since
    except ValueError:
        return False


def _check_definition(root: Path, existing: dict, swarm: dict) -> None:
    """Refuse to resume a store whose swarm was defined otherwise than ``swarm`` today.

    Raises:
      StoreMismatchError: naming the difference (the config fields and default params that
        changed), or the jaxswarm release that wrote the store where it is older than the one
        since which the swarm gives the same results (:data:`SAME_RESULTS_SINCE`) or where the
        store did not record the swarm's definition.
    """
    stored, release, name = existing.get("swarm"), existing.get("jaxswarm"), swarm["name"]
    since = SAME_RESULTS_SINCE.get(name)
    if since is None:
        raise StoreMismatchError(
            f"{root}: no release is known since which {name!r} gives the same results (it is "
            "not in jaxswarm.sweep.store.SAME_RESULTS_SINCE); choose another --out or delete it")
    if stored is None or _older_release(release, since):
        unrecorded = f", which did not record the definition of {name!r}" if stored is None else ""
        raise StoreMismatchError(
            f"{root} was written by jaxswarm {release or '(release not recorded)'}{unrecorded}; "
            f"{name!r} gives the same results since jaxswarm {since[0]}.{since[1]}.0 "
            "(CHANGELOG.md says what changed); choose another --out or delete it")
    if stored == swarm:
        return
    changed = [f"config.{k}" for k in _differences(stored.get("config", {}), swarm["config"])]
    changed += [f"default_params.{k}" for k in _differences(stored.get("default_params", {}),
                                                            swarm["default_params"])]
    raise StoreMismatchError(
        f"{root} holds results of another definition of {name!r} (written by jaxswarm "
        f"{release}; differs in: {', '.join(changed) or 'name'}); choose another --out or "
        "delete it")


def read_results(root) -> pd.DataFrame:
    """All finished rows of the store at ``root`` as a DataFrame (empty if none yet).

    Raises:
      StoreMismatchError: ``runs/`` holds a file that is not a chunk
        (:func:`~jaxswarm.sweep.store.check_chunk_files`).
    """
    runs = Path(root) / "runs"
    check_chunk_files(root)
    if not runs.is_dir() or not any(runs.glob("part-*.parquet")):
        return pd.DataFrame()
    return pd.read_parquet(runs).sort_values(["map_index", "run"], kind="stable").reset_index(
        drop=True)
