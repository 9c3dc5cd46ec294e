"""The sweep runner: every (params, seed) run of a spec on every map, batched and resumable.

Per map, the runs are ordered combination-major (run ``r`` = combination ``r // S``, seed
``seeds[r % S]``) and cut into chunks of ``chunk_size``. A chunk is one call of a compiled
program: its runs are shared out over ``jax.devices()`` (``shard_map``; the chunk is padded to
a multiple of the device count, and padding rows are dropped), and each device goes through its
share a group of runs at a time, a ``vmap`` of :func:`jaxswarm.swarm.run` over keys and
stacked params inside ``lax.map``. Under that ``vmap`` the walks of a group's runs share one queue
of agents over the walker's lanes (:func:`jaxswarm.swarm.walking.walk`), and a run that stopped
walks no more, so small swarms fill the lanes from many runs: the group is ``vmap_size`` runs, by
default enough to fill the lanes (:func:`group_size`). A swarm whose ``vmap`` runs its members
one at a time (:attr:`jaxswarm.swarm.core.Swarm.vmap_one_at_a_time`) goes through its group's
runs one after another.
Maps of the same shape share the compiled program; each compile is logged. A run with seed
``s`` uses ``jax.random.key(s)``, so a row equals ``run(swarm, jax.random.key(s), ...)`` bit for
bit whatever the chunk size, the group size and the number of devices or threads (the arithmetic
of :mod:`jaxswarm.runtime.arithmetic`); its ``fingerprint`` column says so
(:func:`jaxswarm.sweep.replay.replay_row` reruns a row alone and compares).

Each map's optimum is measured as the swarms measure their paths (Dijkstra's path on a graph,
:func:`jaxswarm.exact.optimal_length`; the visibility-graph shortest path on a plane,
:func:`jaxswarm.exact.visibility.shortest_path`), so every row carries its optimality gap, never
negative.
Finished chunks go to the :class:`~jaxswarm.sweep.store.ResultsStore`; running the same spec again
skips them.
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
import jax.numpy as jnp
import numpy as np
import pandas as pd
from jax.sharding import Mesh, NamedSharding, PartitionSpec as P
from tqdm.auto import tqdm

from jaxswarm.runtime.programs import release_if_crowded
from jaxswarm.swarm import definition, make, make_task, run
from jaxswarm.swarm.core import with_room
from jaxswarm.swarm.fingerprint import hex_fingerprint, run_fingerprint
from jaxswarm.swarm.walking import LANES
from jaxswarm.sweep.maps import SweepMap, check_query, resolve_map
from jaxswarm.sweep.spec import SweepSpec
from jaxswarm.sweep.store import ResultsStore, read_results

SUCCESS_GAP = 1e-4
"""A run succeeds when its relative gap to the optimum is below this."""

RUNS_AXIS = "runs"
"""The mesh axis a chunk's runs are sharded over."""


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
      ValueError: a map cannot be resolved (before any compute), or ``out`` holds another spec
        or another definition of the swarm (:class:`~jaxswarm.sweep.store.StoreMismatchError`).
    """
    out = Path(out) if out is not None else default_out(spec)
    base_dir = Path(spec.source).parent if spec.source != "<dict>" else None
    maps = _resolve_maps(spec, base_dir)  # every entry checked before anything is written
    chunks = _set_up(spec, maps, out, log)
    todo, finished_runs = _unfinished_chunks(chunks, len(maps), out)
    bar = tqdm(total=chunks.num_runs * len(maps), unit="run", disable=not progress,
               desc=spec.name, initial=finished_runs)
    try:
        for m, sweep_map in enumerate(maps):
            if todo[m]:
                _run_map(chunks, m, sweep_map, todo[m], bar)
    finally:
        bar.close()
    return read_results(out)


@dataclasses.dataclass(frozen=True)
class _SweepChunks:
    """What every chunk of one sweep shares, set up once by :func:`_set_up`.

    Attributes:
      spec: the sweep.
      grid: its param combinations (``spec.grid()``), P of them.
      seeds: int[S] its seeds.
      num_runs: runs per map, P * S.
      params: the swarm's params with leaves f32[P * S]: run ``r``'s at index ``r``.
      padded: runs per chunk call: ``chunk_size`` rounded up to a multiple of the device count.
      group: runs vmapped together on one device.
      batch_sharding: the runs axis split over the devices.
      replicated: a whole copy on every device (the world and the task).
      program: the jitted chunk (:func:`_chunk_program`).
      roomy_program: the same with room in the walks' logs for every move
        (:func:`~jaxswarm.swarm.core.with_room`), for a chunk where a walk overflowed.
      compiled: ``(`` :func:`_program_key` ``, roomy)`` -> ``program`` (``roomy_program``)
        compiled for that map shape, filled as the shapes come.
      store: the results store.
      writer: whether this process writes the store (process 0).
      log: where one-line messages go.
    """

    spec: SweepSpec
    grid: list
    seeds: np.ndarray
    num_runs: int
    params: Any
    padded: int
    group: int
    batch_sharding: NamedSharding
    replicated: NamedSharding
    program: Callable
    roomy_program: Callable
    compiled: dict
    store: ResultsStore
    writer: bool
    log: Callable[[str], None]


def _set_up(spec: SweepSpec, maps: list[SweepMap], out: Path,
            log: Callable[[str], None]) -> _SweepChunks:
    """Lay a sweep's chunks out over ``jax.devices()``, open (or create) its store in ``out``
    and stack its runs' params.

    Raises:
      StoreMismatchError: ``out`` holds another spec or another definition of the swarm.
    """
    writer = jax.process_index() == 0
    swarm = make(spec.algorithm, **spec.config)
    devices = jax.devices()
    padded = -(-spec.chunk_size // len(devices)) * len(devices)
    group = min(spec.vmap_size or group_size(swarm.config.num_agents), padded // len(devices))
    store = ResultsStore(out, spec.as_dict(), _metadata(spec, maps, swarm, group),
                         writer=writer)
    grid = spec.grid()
    seeds = np.asarray(spec.seeds)
    mesh = Mesh(np.asarray(devices), (RUNS_AXIS,))
    return _SweepChunks(
        spec=spec, grid=grid, seeds=seeds, num_runs=spec.num_runs,
        params=_stacked_params(swarm.default_params, grid, len(seeds)), padded=padded,
        group=group, batch_sharding=NamedSharding(mesh, P(RUNS_AXIS)),
        replicated=NamedSharding(mesh, P()), program=_chunk_program(swarm, spec, mesh, group),
        roomy_program=_chunk_program(with_room(swarm), spec, mesh, group), compiled={}, store=store, writer=writer, log=log)


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


def _run_map(chunks: _SweepChunks, map_index: int, sweep_map: SweepMap, todo: list[int],
             bar) -> None:
    """Run the chunks ``todo`` of one map (compiling for its shape when it is the first of
    it), write each to the store as it finishes and advance the progress bar."""
    spec = chunks.spec
    task = make_task(sweep_map.world, sweep_map.start, sweep_map.goal)
    best = sweep_map.optimum()
    world, task = jax.device_put((sweep_map.world, task), chunks.replicated)
    compiled = _compiled(chunks, sweep_map, world, task)
    for c in todo:
        first = c * spec.chunk_size
        count = _chunk_runs(c, spec.chunk_size, chunks.num_runs)
        inputs = _chunk_inputs(chunks.params, chunks.seeds, first, chunks.padded,
                               chunks.num_runs, chunks.batch_sharding)
        began = time.perf_counter()
        *outputs, overflowed = _gather(compiled(*inputs, world, task))
        if np.any(overflowed[:count]):
            chunks.log(f"a walk of chunk {c} of {sweep_map.label} had no room for its moves: "
                       "the chunk again with room for every move")
            roomy = _compiled(chunks, sweep_map, world, task, roomy=True)
            *outputs, _ = _gather(roomy(*inputs, world, task))
        seconds = time.perf_counter() - began
        rows = _rows(spec, chunks.grid, chunks.seeds, sweep_map.label, map_index, c, first,
                     count, *(x[:count] for x in outputs), best, seconds)
        if chunks.writer:
            chunks.store.write_chunk(map_index, c, rows)
        bar.update(count)


def _compiled(chunks: _SweepChunks, sweep_map: SweepMap, world, task, *, roomy: bool = False):
    """The chunk program (with ``roomy`` the one with room for every move) compiled for
    ``sweep_map``'s shape (``world`` and ``task`` already on the devices): compiled and logged
    the first time a shape comes, reused after."""
    program = (_program_key(sweep_map.world), roomy)
    if program not in chunks.compiled:
        if release_if_crowded():  # the process holds too many programs' pages: drop ours too
            chunks.compiled.clear()
        began = time.perf_counter()
        example = _chunk_inputs(chunks.params, chunks.seeds, 0, chunks.padded, chunks.num_runs,
                                chunks.batch_sharding)
        chosen = chunks.roomy_program if roomy else chunks.program
        chunks.compiled[program] = chosen.lower(*example, world, task).compile()
        chunks.log(f"compiled {chunks.spec.algorithm} for {sweep_map.label}'s shape, "
                   f"{chunks.padded} runs per chunk on {len(jax.devices())} device(s), "
                   f"{chunks.group} at a time, in {time.perf_counter() - began:.1f} s")
    return chunks.compiled[program]


def _resolve_maps(spec: SweepSpec, base_dir: Path | None) -> list[SweepMap]:
    """Every map of the spec, resolved and its start and goal checked.

    Raises:
      ValueError: naming the spec file, the entry (``sweep.maps[i]``) and the problem.
    """
    maps = []
    for i, entry in enumerate(spec.maps):
        try:
            sweep_map = resolve_map(entry, base_dir)
            check_query(sweep_map)
        except ValueError as error:
            raise ValueError(f"{spec.source}: sweep.maps[{i}] = {entry!r}: {error}") from None
        maps.append(sweep_map)
    return maps


def _program_key(world) -> tuple:
    """Worlds with equal structure and array shapes share one compiled program."""
    leaves, treedef = jax.tree_util.tree_flatten(world)
    return treedef, tuple(leaf.shape for leaf in leaves)


def group_size(num_agents: int) -> int:
    """Runs of ``num_agents`` agents vmapped together by default: enough for a walk loop of
    ``LANES`` agents (64 runs of 16 agents, 4 of 256), at least one, whose lanes the queue keeps
    busy (:func:`jaxswarm.swarm.walking.lanes_for`)."""
    return max(1, LANES // num_agents)


def _chunk_program(swarm, spec: SweepSpec, mesh: Mesh, group: int):
    """The jitted chunk: ``(seeds i32[C], params with leaves f32[C], world, task) -> (cost
    f32[C], iterations i32[C], moves i32[C], evaluations i32[C], fingerprint u32[C, 2],
    overflowed bool[C])`` (:func:`~jaxswarm.swarm.fingerprint.run_fingerprint`; a run whose
    walk overflowed its log must be made again), C a multiple of the mesh
    size, the runs sharded over the mesh's ``RUNS_AXIS``; each device maps over its runs
    ``group`` at a time."""
    def one(run_input, world, task):
        seed, params = run_input
        state, trace = run(swarm, jax.random.key(seed), world, task, params,
                           iterations=spec.iterations, patience=spec.patience)
        return (swarm.best(state).cost, trace.iterations, jnp.sum(trace.moves),
                jnp.sum(trace.evaluations), run_fingerprint(state, trace), trace.overflowed)

    def share(seeds, params, world, task):
        return jax.lax.map(lambda run_input: one(run_input, world, task), (seeds, params),
                           batch_size=min(group, seeds.shape[0]))

    return jax.jit(jax.shard_map(share, mesh=mesh,
                                 in_specs=(P(RUNS_AXIS), P(RUNS_AXIS), P(), P()),
                                 out_specs=P(RUNS_AXIS), check_vma=False))


def _stacked_params(defaults, grid: list[dict], num_seeds: int):
    """Params pytree with leaves f32[P * S]: combination ``r // S`` for run ``r``."""
    columns = {name: np.full(len(grid), np.float32(value))
               for name, value in defaults._asdict().items()}
    for p, combination in enumerate(grid):
        for name, value in combination.items():
            columns[name][p] = value
    return defaults._replace(**{name: np.repeat(values, num_seeds)
                                for name, values in columns.items()})


def _chunk_runs(chunk: int, chunk_size: int, num_runs: int) -> int:
    return min(chunk_size, num_runs - chunk * chunk_size)


def _chunk_inputs(params, seeds: np.ndarray, first: int, padded: int, num_runs: int, sharding):
    """Seeds i32[padded] and params (leaves f32[padded]) of runs ``first ..``, padded by
    repeating the last run, as global arrays sharded over the batch axis (each process builds
    only its own devices' shards, so this also works across hosts)."""
    index = np.minimum(np.arange(first, first + padded), num_runs - 1)
    host = (seeds[index % len(seeds)].astype(np.int32),
            jax.tree_util.tree_map(lambda leaf: leaf[index], params))
    return jax.tree_util.tree_map(
        lambda x: jax.make_array_from_callback(x.shape, sharding, lambda i, x=x: x[i]), host)


def _gather(outputs):
    """Batch outputs as host arrays, from every process's devices."""
    if jax.process_count() > 1:
        from jax.experimental import multihost_utils
        return multihost_utils.process_allgather(outputs, tiled=True)
    return jax.device_get(outputs)


def _rows(spec: SweepSpec, grid, seeds, label, map_index, chunk, first, count, cost, iterations,
          moves, evaluations, fingerprints, best, seconds) -> dict:
    runs = np.arange(first, first + count)
    cost = np.asarray(cost, np.float64)
    found = np.isfinite(cost)
    gap = (cost - best) / best if math.isfinite(best) and best > 0 else np.full(count, np.nan)
    rows = dict(map=[label] * count, map_index=np.full(count, map_index, np.int32),
                run=runs.astype(np.int64), algorithm=[spec.algorithm] * count,
                seed=seeds[runs % len(seeds)].astype(np.int64))
    for name in spec.params:
        rows[name] = np.array([grid[r // len(seeds)][name] for r in runs], np.float64)
    rows.update(cost=cost, optimum=np.full(count, best), gap=gap, found=found,
                success=found & (gap < SUCCESS_GAP), iterations=np.asarray(iterations, np.int32),
                moves=np.asarray(moves, np.int64), evaluations=np.asarray(evaluations, np.int64),
                fingerprint=[hex_fingerprint(f) for f in fingerprints],
                chunk_seconds=np.full(count, seconds), chunk=np.full(count, chunk, np.int32))
    return rows


def _metadata(spec: SweepSpec, maps: list[SweepMap], swarm, group: int) -> dict:
    import jaxlib
    return dict(
        created=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        jaxswarm=_version(), jax=jax.__version__, jaxlib=jaxlib.__version__,
        numpy=np.__version__, python=platform.python_version(), machine=platform.machine(),
        devices=[str(d) for d in jax.devices()], git_commit=_git_commit(),
        algorithm=spec.algorithm, config=spec.config, swarm=definition(swarm),
        seeds=list(spec.seeds),
        vmap_size=group,
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
