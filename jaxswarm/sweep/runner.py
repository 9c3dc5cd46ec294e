"""The sweep runner: every (params, seed) run of a spec on every map, batched and resumable.

Per map, the runs are ordered combination-major (run ``r`` = combination ``r // S``, seed
``seeds[r % S]``) and cut into chunks of ``chunk_size``. A chunk is one call of the swarm's
compiled batches (:class:`~jaxswarm.sweep.batches.RunBatches`, through the executor's
:class:`~jaxswarm.swarm.executor.ShardedRuns`): its runs are shared out over ``jax.devices()``,
and each device goes through its share a group of ``vmap_size`` runs at a time (by default enough
to fill the walker's lanes, :func:`jaxswarm.swarm.executor.group_size`). Maps of the same shape
share the compiled program; each compile is logged. A run
with seed ``s`` uses ``jax.random.key(s)``, so a row equals ``run(swarm, jax.random.key(s), ...)``
bit for bit whatever the chunk size, the group size and the number of devices or threads (the
arithmetic of :mod:`jaxswarm.runtime.arithmetic`); its ``fingerprint`` column says so
(:func:`jaxswarm.sweep.replay.replay_row` reruns a row alone and compares).

Each map's optimum is measured as the swarms measure their paths (Dijkstra's path on a graph,
:func:`jaxswarm.exact.optimal_length`; the visibility-graph shortest path on a plane,
:func:`jaxswarm.exact.visibility.shortest_path`), so every row carries its optimality gap, never
negative.
Finished chunks go to the :class:`~jaxswarm.sweep.store.ResultsStore`; running the same spec again
skips them. After the first chunk it runs, a sweep logs how long the rest will take at that
chunk's pace. The param combinations are never built as a whole: a chunk's values are computed
from its runs' numbers (:meth:`~jaxswarm.sweep.spec.SweepSpec.combination_values`).
"""
from __future__ import annotations

import dataclasses
import datetime
import importlib.metadata
import math
import platform
import subprocess
import time
from pathlib import Path
from typing import Any, Callable

import jax
import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from jaxswarm.maps.entry import ResolvedMap
from jaxswarm.swarm import definition
from jaxswarm.swarm.fingerprint import hex_fingerprint
from jaxswarm.sweep.batches import RunBatches, run_outcomes
from jaxswarm.sweep.spec import SweepSpec, file_digests, resolve_maps
from jaxswarm.sweep.store import ResultsStore, read_results


def default_out(spec: SweepSpec) -> Path:
    """``out/sweeps/<name>``: where a sweep writes unless told otherwise."""
    return Path("out") / "sweeps" / spec.name


def run_sweep(spec: SweepSpec, out=None, *, progress: bool = True,
              log: Callable[[str], None] = print) -> pd.DataFrame:
    """Run (or resume) a sweep and return all its rows.

    Args:
      spec: a checked spec (:func:`jaxswarm.sweep.load_spec`).
      out: the store directory (default :func:`default_out`).
      progress: show a progress bar (runs, runs/s) updated per chunk.
      log: where one-line messages go (compiles, skipped chunks).

    Returns:
      DataFrame, one row per (map, params, seed): ``map``, ``map_index``, ``run``, ``algorithm``,
      ``seed``, one column per swept param, ``cost`` (inf if no path), ``optimum``, ``gap``
      (relative), ``found``, ``success`` (gap < 1e-4), ``iterations`` (used), ``moves`` (made
      by its agents, all iterations), ``evaluations`` (complete paths evaluated, all
      iterations: fitness calls), ``fingerprint`` (16 hex digits of the run's final state and
      trace, :func:`~jaxswarm.swarm.fingerprint.run_fingerprint`), ``chunk`` (the compiled
      batch the run was part of) and ``chunk_seconds`` (that whole chunk's wall time, compile
      excluded: the same in each of its rows; runs of a chunk run together, so no run has a
      time of its own).

    Raises:
      ValueError: ``out`` is a file or lies in one, a map cannot be resolved (both before any
        compute), or ``out`` holds another spec or another definition of the swarm
        (:class:`~jaxswarm.sweep.store.StoreMismatchError`).
    """
    out = Path(out) if out is not None else default_out(spec)
    check_folder(out, "out")
    base_dir = Path(spec.source).parent if spec.source != "<dict>" else None
    # Every entry checked before anything is written.
    maps = resolve_maps(spec.maps, "sweep.maps", spec.source, base_dir)
    chunks = _set_up(spec, maps, out, log)
    todo, finished_runs = _unfinished_chunks(chunks, len(maps), out)
    bar = tqdm(total=chunks.num_runs * len(maps), unit="run", disable=not progress,
               desc=spec.name, initial=finished_runs)
    pace = _Pace(sum(len(chunks_of_map) for chunks_of_map in todo), log)
    try:
        for m, sweep_map in enumerate(maps):
            if todo[m]:
                _run_map(chunks, m, sweep_map, todo[m], bar, pace)
    finally:
        bar.close()
    return read_results(out)


def check_folder(path: Path, argument: str) -> None:
    """``path`` is a folder or can be made one: neither it nor a folder above it is a file.

    Raises:
      ValueError: naming ``argument`` and the file in the way.
    """
    for place in (path, *path.parents):
        if place.exists():
            if not place.is_dir():
                what = "is a file" if place == path else f"lies in {place}, a file"
                raise ValueError(f"{argument}: {path} {what}, not a folder; name a folder for "
                                 "the results")
            return


@dataclasses.dataclass
class _Pace:
    """The estimate a sweep logs after the first chunk it runs: the rest at that chunk's pace.

    Attributes:
      chunks: the chunks this call of the sweep has to run.
      log: where the estimate goes.
      done: whether it was logged.
    """

    chunks: int
    log: Callable[[str], None]
    done: bool = False

    def first_chunk(self, runs: int, seconds: float) -> None:
        """Log the estimate once, after a first chunk of ``runs`` runs that took ``seconds``
        (compile excluded)."""
        if self.done:
            return
        self.done = True
        rest = self.chunks - 1
        if rest > 0:
            self.log(f"first chunk: {runs} runs in {seconds:.1f} s; the {rest:,} chunk(s) left "
                     f"take about {_duration(rest * seconds)} at its pace (plus a compile per "
                     "other map shape)")


def _duration(seconds: float) -> str:
    """``seconds`` as a rounded duration: ``"40 s"``, ``"12 min"``, ``"3.5 h"``, ``"2.1 days"``."""
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    if seconds < 172800:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.1f} days"


@dataclasses.dataclass(frozen=True)
class _SweepChunks:
    """What every chunk of one sweep shares, set up once by :func:`_set_up`.

    Attributes:
      spec: the sweep.
      seeds: int[S] its seeds.
      num_runs: runs per map, P * S for P param combinations.
      batches: the swarm's compiled runs (:class:`~jaxswarm.sweep.batches.RunBatches`).
      store: the results store.
      writer: whether this process writes the store (process 0).
      log: where one-line messages go.
    """

    spec: SweepSpec
    seeds: np.ndarray
    num_runs: int
    batches: RunBatches
    store: ResultsStore
    writer: bool
    log: Callable[[str], None]


def _set_up(spec: SweepSpec, maps: list[ResolvedMap], out: Path,
            log: Callable[[str], None]) -> _SweepChunks:
    """Open (or create) a sweep's store in ``out``, lay its runs out and set up its compiled
    batches.

    Raises:
      StoreMismatchError: ``out`` holds another spec or another definition of the swarm.
    """
    writer = jax.process_index() == 0
    batches = RunBatches(spec.algorithm, spec.config, spec.iterations, spec.patience,
                         spec.chunk_size, spec.vmap_size, log)
    store = ResultsStore(out, spec.as_dict(), _metadata(spec, maps, batches.swarm,
                                                        batches.group),
                         depends_on=file_digests(maps, "sweep.maps"), writer=writer)
    return _SweepChunks(spec=spec, seeds=np.asarray(spec.seeds, np.int64),
                        num_runs=spec.num_runs, batches=batches, store=store, writer=writer,
                        log=log)


def _unfinished_chunks(chunks: _SweepChunks, num_maps: int, out: Path) -> tuple[list, int]:
    """``(todo, finished_runs)``: per map, the indices of the chunks its store does not hold
    yet (in order), and how many runs the finished chunks of all maps hold; logs a resume."""
    spec = chunks.spec
    per_map = math.ceil(chunks.num_runs / spec.chunk_size)
    done = {(m, c) for m in range(num_maps) for c in range(per_map)
            if chunks.store.finished(m, c)}
    if done:
        chunks.log(f"resuming {out}: {len(done)} of {num_maps * per_map} chunks already "
                   "finished")
    todo = [[c for c in range(per_map) if (m, c) not in done] for m in range(num_maps)]
    return todo, sum(_chunk_runs(c, spec.chunk_size, chunks.num_runs) for _, c in done)


def _run_map(chunks: _SweepChunks, map_index: int, sweep_map: ResolvedMap, todo: list[int],
             bar, pace: _Pace) -> None:
    """Run the chunks ``todo`` of one map, write each to the store as it finishes, advance
    the progress bar and tell ``pace`` the first chunk's time."""
    spec = chunks.spec
    best = sweep_map.optimum()
    for c in todo:
        first = c * spec.chunk_size
        runs = np.arange(first, first + _chunk_runs(c, spec.chunk_size, chunks.num_runs))
        swept = spec.combination_values(runs // len(chunks.seeds))
        outputs = chunks.batches.run(sweep_map, chunks.seeds[runs % len(chunks.seeds)], swept,
                                     best)
        rows = _rows(spec, swept, chunks.seeds, sweep_map.label, map_index, c, runs, outputs,
                     best)
        if chunks.writer:
            chunks.store.write_chunk(map_index, c, rows)
        bar.update(len(runs))
        pace.first_chunk(len(runs), float(outputs["seconds"][0]))


def _chunk_runs(chunk: int, chunk_size: int, num_runs: int) -> int:
    return min(chunk_size, num_runs - chunk * chunk_size)


def _rows(spec: SweepSpec, swept, seeds, label, map_index, chunk, runs, outputs, best) -> dict:
    """A chunk's rows (see :func:`run_sweep`) from its runs' swept values (name -> f64[C]) and
    outputs (:meth:`~jaxswarm.sweep.batches.RunBatches.run`)."""
    count = len(runs)
    rows = dict(map=[label] * count, map_index=np.full(count, map_index, np.int32),
                run=runs.astype(np.int64), algorithm=[spec.algorithm] * count,
                seed=seeds[runs % len(seeds)].astype(np.int64))
    rows.update(swept)
    cost = np.asarray(outputs["cost"], np.float64)
    rows.update(cost=cost, optimum=np.full(count, best), **run_outcomes(cost, best),
                iterations=np.asarray(outputs["iterations"], np.int32),
                moves=np.asarray(outputs["moves"], np.int64),
                evaluations=np.asarray(outputs["evaluations"], np.int64),
                fingerprint=[hex_fingerprint(f) for f in outputs["fingerprint"]],
                chunk_seconds=np.asarray(outputs["seconds"], np.float64),
                chunk=np.full(count, chunk, np.int32))
    return rows


def provenance() -> dict:
    """Where results come from, for a store's metadata: the time, the versions of jaxswarm,
    JAX, jaxlib, NumPy and Python, the machine, the devices and the git commit."""
    import jaxlib
    return dict(
        created=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        jaxswarm=_version(), jax=jax.__version__, jaxlib=jaxlib.__version__,
        numpy=np.__version__, python=platform.python_version(), machine=platform.machine(),
        devices=[str(d) for d in jax.devices()], git_commit=_git_commit())


def _metadata(spec: SweepSpec, maps: list[ResolvedMap], swarm, group: int) -> dict:
    return dict(
        provenance(), algorithm=spec.algorithm, config=spec.config, swarm=definition(swarm),
        seeds=list(spec.seeds), vmap_size=group,
        maps=[dict(label=m.label, start=list(m.start), goal=list(m.goal), size=m.size)
              for m in maps])


def _version() -> str | None:
    """The installed jaxswarm version (None when run from a source tree that is not installed)."""
    try:
        return importlib.metadata.version("jaxswarm")
    except importlib.metadata.PackageNotFoundError:
        return None


def _git_commit() -> str | None:
    """The commit of the jaxswarm checkout, if it is one."""
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                              cwd=Path(__file__).parent, check=True,
                              timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
