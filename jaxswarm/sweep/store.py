"""The results store: a Parquet dataset written one finished chunk at a time, plus metadata.

Layout of a store directory::

    metadata.json        package and JAX versions, spec, the swarm's definition (its name, every
                         config field and default param), seeds, git commit, maps
    runs/part-MMM-CCCCC.parquet   one file per finished chunk (map MMM, chunk CCCCC)

A chunk is written to a hidden temporary file in ``runs/`` and moved into place with
``os.replace``, so a reader (``pandas.read_parquet(store / "runs")``, which skips hidden files)
never sees half a chunk, and a killed sweep leaves only whole chunks behind. Reopening a store
for the same spec and the same swarm definition finds the finished chunks (resume); a different
spec, or a swarm that has changed under its name (a store of jaxswarm 0.1.0, whose ``rfd_star``
was the law now called ``rfd_graded``), is refused.
"""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from jaxswarm.runtime.atomic import TEMPORARY_GLOB, atomic_path, write_atomically


class StoreMismatchError(ValueError):
    """The directory holds results of a different sweep spec or swarm definition."""


class ResultsStore:
    """One sweep's results directory (see the module docstring)."""

    def __init__(self, root, spec: dict, metadata: dict, *, writer: bool = True):
        """Open (or create) the store at ``root`` for ``spec`` (the spec's ``as_dict()``).

        The writer (process 0 of a multi-host sweep; the only process otherwise) removes stale
        temporary files of an interrupted write and writes ``metadata`` (with the spec under
        ``"spec"``) for a new store; other processes only read it. ``metadata["swarm"]`` (see
        :func:`jaxswarm.swarm.definition`) must equal the stored one for a resume.

        Raises:
          StoreMismatchError: ``root`` already holds results of another spec or of another
            definition of the swarm.
        """
        self.root = Path(root)
        self.runs = self.root / "runs"
        self.runs.mkdir(parents=True, exist_ok=True)
        if writer:
            for stale in self.runs.glob(TEMPORARY_GLOB):
                stale.unlink()
        existing = self.read_metadata(self.root)
        as_stored = json.loads(json.dumps(spec, default=str))  # the spec as JSON gives it back
        if existing is None:
            if writer:
                write_atomically(self.root / "metadata.json",
                                 json.dumps(dict(metadata, spec=spec), indent=2, default=str))
        elif existing.get("spec") != as_stored:
            raise StoreMismatchError(
                f"{self.root} holds results of a different sweep (differs in: "
                f"{', '.join(_differences(existing.get('spec', {}), as_stored))}); "
                "choose another --out or delete it")
        else:
            _check_definition(self.root, existing, json.loads(json.dumps(
                metadata["swarm"], default=str)))

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
        """The store's metadata record, or None if there is none yet."""
        path = Path(root) / "metadata.json"
        return json.loads(path.read_text()) if path.is_file() else None


def _differences(before: dict, after: dict) -> list[str]:
    """The keys whose values differ between two dicts, sorted."""
    return sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))


SAME_RESULTS_SINCE = (0, 7)
"""The jaxswarm release since which a run's results are the same: 0.7.0 computes with arithmetic
that does not depend on the batch (:mod:`jaxswarm.runtime.arithmetic`; see CHANGELOG.md), so a
store of an older release is not resumed."""

SAME_RESULTS_SINCE_BY_SWARM = {"ant_system": (0, 8), "iwd": (0, 8), "max_min_aco": (0, 8),
                               "rfd": (0, 8)}
"""Swarms whose results changed in a later release than ``SAME_RESULTS_SINCE``: 0.8.0 made the
calibrated constants of these four their defaults (``results/calibration``)."""


def same_results_since(name: str) -> tuple[int, int]:
    """``(major, minor)``: the release since which the registered swarm ``name`` gives the same
    results (``SAME_RESULTS_SINCE_BY_SWARM``, else ``SAME_RESULTS_SINCE``)."""
    return SAME_RESULTS_SINCE_BY_SWARM.get(name, SAME_RESULTS_SINCE)


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
        changed, or the jaxswarm version that wrote a store without a recorded definition or
        before the release since which the swarm gives the same results,
        :func:`same_results_since`).
    """
    stored = existing.get("swarm")
    since = same_results_since(swarm["name"])
    if stored is not None and _older_release(existing.get("jaxswarm"), since):
        raise StoreMismatchError(
            f"{root} was written by jaxswarm {existing.get('jaxswarm')}, whose {swarm['name']!r} "
            f"computed otherwise (its results changed in {since[0]}.{since[1]}.0, see "
            "CHANGELOG.md); choose another --out or delete it")
    if stored == swarm:
        return
    if stored is None:
        renamed = (" (its 'rfd_star' was the graded law, now registered as 'rfd_graded'; "
                   "'rfd_star' is now the RFD paper's RFD*)" if swarm["name"] == "rfd_star"
                   else "")
        raise StoreMismatchError(
            f"{root} was written by jaxswarm {existing.get('jaxswarm') or 'before 0.2.0'}, "
            f"which did not record the definition of {swarm['name']!r}; since 0.2.0 a "
            f"registered name is the paper's algorithm{renamed}, see CHANGELOG.md; choose "
            "another --out or delete it")
    changed = [f"config.{k}" for k in _differences(stored.get("config", {}), swarm["config"])]
    changed += [f"default_params.{k}" for k in _differences(stored.get("default_params", {}),
                                                            swarm["default_params"])]
    raise StoreMismatchError(
        f"{root} holds results of another definition of {swarm['name']!r} (written by jaxswarm "
        f"{existing.get('jaxswarm')}; differs in: {', '.join(changed) or 'name'}); choose "
        "another --out or delete it")


def read_results(root) -> pd.DataFrame:
    """All finished rows of the store at ``root`` as a DataFrame (empty if none yet)."""
    runs = Path(root) / "runs"
    if not runs.is_dir() or not any(runs.glob("part-*.parquet")):
        return pd.DataFrame()
    return pd.read_parquet(runs).sort_values(["map_index", "run"], kind="stable").reset_index(
        drop=True)
