"""Runs of one swarm as compiled batches over the devices: what sweeps and tuners share.

A :class:`RunBatches` holds a swarm (its registry name and static config), the iteration budget and
the patience, and runs any list of ``(seed, params)`` runs on a map: the runs are cut into calls of
``chunk_size`` (padded to a multiple of the device count, or with ``fit_calls`` a small call to a
quarter or a half of that; padding rows are dropped), shared out over ``jax.devices()``
(``shard_map``), and each device goes through its share a group of runs at a time, a ``vmap`` of
:func:`jaxswarm.swarm.run` inside ``lax.map`` (the walks of a group share one queue of agents over
the walker's lanes). Maps of the same shape share one compiled program; each compile is logged. A
call in which a walk had no room in its log for its moves is made again with room for every move
(:func:`~jaxswarm.swarm.core.with_room`). A run with seed ``s`` uses ``jax.random.key(s)``, so its
outputs equal ``run(swarm, jax.random.key(s), ...)`` bit for bit whatever the batch it is in
(:mod:`jaxswarm.runtime.arithmetic`).
"""
from __future__ import annotations

import dataclasses
import math
import time
from typing import Any, Callable

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec as P

from jaxswarm.maps.entry import ResolvedMap
from jaxswarm.runtime.programs import release_if_crowded
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.core import with_room
from jaxswarm.swarm.fingerprint import run_fingerprint
from jaxswarm.swarm.walking import LANES
from jaxswarm.sweep.spec import SEED_LIMIT

SUCCESS_GAP = 1e-4
"""A run succeeds when its relative gap to the optimum is below this."""

RUNS_AXIS = "runs"
"""The mesh axis a call's runs are sharded over."""

OUTPUTS = ("cost", "iterations", "moves", "evaluations", "fingerprint", "target_iterations",
           "target_evaluations")
"""What :meth:`RunBatches.run` returns per run (see there)."""


def group_size(num_agents: int) -> int:
    """Runs of ``num_agents`` agents vmapped together by default: enough for a walk loop of
    ``LANES`` agents (64 runs of 16 agents, 4 of 256), at least one, whose lanes the queue keeps
    busy (:func:`jaxswarm.swarm.walking.lanes_for`)."""
    return max(1, LANES // num_agents)


@dataclasses.dataclass
class RunBatches:
    """One swarm's runs, batched and compiled per map shape (see the module docstring).

    Attributes:
      algorithm: a registered swarm name.
      config: static keyword arguments of its factory.
      iterations: iteration budget of each run.
      patience: stop a run this many iterations after its last gain (None: never).
      chunk_size: runs per compiled call.
      vmap_size: runs vmapped together on one device (None: :func:`group_size`).
      log: where one-line messages go (compiles, calls made again with room).
      fit_calls: pad a call of at most a quarter or a half of a chunk's runs to that share of
        the chunk rather than to a whole chunk: fewer wasted runs for the many small calls of
        a race, at the cost of up to three programs per map shape (a sweep, whose chunks are
        full but its last, keeps one).
    """

    algorithm: str
    config: dict
    iterations: int
    patience: int | None
    chunk_size: int
    vmap_size: int | None = None
    log: Callable[[str], None] = print
    fit_calls: bool = False

    def __post_init__(self):
        self.swarm = make(self.algorithm, **self.config)
        devices = jax.devices()
        self.padded = -(-self.chunk_size // len(devices)) * len(devices)
        self.group = min(self.vmap_size or group_size(self.swarm.config.num_agents),
                         self.padded // len(devices))
        mesh = Mesh(np.asarray(devices), (RUNS_AXIS,))
        self._runs = NamedSharding(mesh, P(RUNS_AXIS))
        self._replicated = NamedSharding(mesh, P())
        self._programs = {roomy: _program(with_room(self.swarm) if roomy else self.swarm,
                                          self.iterations, self.patience, mesh, self.group)
                          for roomy in (False, True)}
        self._compiled: dict = {}

    @property
    def default_params(self):
        """The swarm's default params (a NamedTuple of floats)."""
        return self.swarm.default_params

    def run(self, sweep_map: ResolvedMap, seeds: np.ndarray, params: dict[str, np.ndarray],
            optimum: float = np.inf) -> dict[str, np.ndarray]:
        """Run ``seeds`` (int[C], each in ``[0, SEED_LIMIT)``) with ``params`` (name -> f64[C];
        params not named keep the swarm's defaults) on ``sweep_map``, whose optimum is
        ``optimum`` (:meth:`~jaxswarm.maps.entry.ResolvedMap.optimum`), ``chunk_size`` runs a
        call.

        Returns:
          name -> array[C]: ``cost`` (f64, inf without a path), ``iterations`` (i32, used),
          ``moves`` and ``evaluations`` (i64, all iterations), ``fingerprint`` (u32[C, 2],
          :func:`~jaxswarm.swarm.fingerprint.run_fingerprint`), ``target_iterations`` and
          ``target_evaluations`` (i32 and i64: the iterations, and the evaluations they made,
          until the best cost was within :data:`SUCCESS_GAP` of ``optimum``, the rule of
          :func:`jaxswarm.dynamic.events.first_iteration_at`; -1 where it never was), and
          ``seconds`` (f64: the wall time of the call the run was part of, compile excluded).

        Raises:
          ValueError: a seed outside ``[0, SEED_LIMIT)``, where seeds give distinct keys.
        """
        seeds = np.asarray(seeds)
        if seeds.size and (seeds.min() < 0 or seeds.max() >= SEED_LIMIT):
            raise ValueError(f"seeds must be integers from 0 to {SEED_LIMIT - 1} (2^32 - 1), "
                             f"got {seeds.min()} to {seeds.max()}")
        count = len(seeds)
        stacked = _stacked_params(self.swarm.default_params, params, count)
        world, task = jax.device_put(
            (sweep_map.world, make_task(sweep_map.world, sweep_map.start, sweep_map.goal)),
            self._replicated)
        target = jax.device_put(jnp.float32(optimum), self._replicated)
        parts = []
        for first in range(0, count, self.chunk_size):
            size = min(self.chunk_size, count - first)
            index = np.minimum(np.arange(first, first + self.call_size(size)), count - 1)
            inputs = self._sharded((seeds[index].astype(np.uint32),
                                    jax.tree_util.tree_map(lambda leaf: leaf[index], stacked)))
            outputs, seconds = self._call(sweep_map, inputs, world, task, target)
            parts.append({name: value[:size] for name, value in outputs.items()}
                         | {"seconds": np.full(size, seconds)})
        return {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}

    def call_size(self, count: int) -> int:
        """The runs of a call that holds ``count`` runs: the padded chunk, or with ``fit_calls``
        the smallest of a quarter, a half and the whole of it (each a multiple of the device
        count) that holds them."""
        if not self.fit_calls:
            return self.padded
        devices = len(jax.devices())
        for share in (4, 2):
            size = -(-self.padded // (share * devices)) * devices
            if count <= size:
                return size
        return self.padded

    def _call(self, sweep_map: ResolvedMap, inputs, world, task,
              target) -> tuple[dict[str, np.ndarray], float]:
        """One compiled call on ``inputs`` (seeds u32[C], params with leaves f32[C], sharded
        over the runs axis): ``(outputs, seconds)``, :data:`OUTPUTS` as host arrays, made again
        with room for every move where a walk overflowed its log, and the call's wall time (the
        first compile for the map's shape excluded)."""
        program = self._compiled_for(sweep_map, inputs, world, task, target, roomy=False)
        began = time.perf_counter()
        outputs = _gather(program(*inputs, world, task, target))
        if np.any(outputs["overflowed"]):
            self.log(f"a walk on {sweep_map.label} had no room for its moves: the call again "
                     "with room for every move")
            outputs = _gather(self._compiled_for(sweep_map, inputs, world, task, target,
                                                 roomy=True)(*inputs, world, task, target))
        return {name: outputs[name] for name in OUTPUTS}, time.perf_counter() - began

    def _sharded(self, host) -> tuple:
        """``host`` arrays as global arrays sharded over the runs axis (each process builds only
        its own devices' shards, so this also works across hosts)."""
        return jax.tree_util.tree_map(
            lambda x: jax.make_array_from_callback(x.shape, self._runs, lambda i, x=x: x[i]),
            host)

    def _compiled_for(self, sweep_map: ResolvedMap, inputs, world, task, target, *, roomy: bool):
        """The program (``roomy``: with room for every move) compiled for ``sweep_map``'s
        shape: compiled and logged the first time a shape comes, reused after."""
        key = (_program_key(sweep_map.world), roomy, inputs[0].shape[0])
        if key not in self._compiled:
            if release_if_crowded():  # the process holds too many programs' pages: drop ours
                self._compiled.clear()
            began = time.perf_counter()
            self._compiled[key] = self._programs[roomy].lower(
                *inputs, world, task, target).compile()
            size = inputs[0].shape[0]
            self.log(f"compiled {self.algorithm} for {sweep_map.label}'s shape, "
                     f"{size} runs per chunk on {len(jax.devices())} device(s), "
                     f"{min(self.group, size // len(jax.devices()))} at a time, in "
                     f"{time.perf_counter() - began:.1f} s")
        return self._compiled[key]


def _program(swarm, iterations: int, patience: int | None, mesh: Mesh, group: int):
    """The jitted call: ``(seeds u32[C], params with leaves f32[C], world, task, optimum f32[])
    -> {output: [C, ...]}`` (:data:`OUTPUTS` and ``overflowed``), C a multiple of the mesh
    size, the runs sharded over the mesh's ``RUNS_AXIS``; each device maps over its runs
    ``group`` at a time."""
    def one(run_input, world, task, optimum):
        seed, params = run_input
        state, trace = run(swarm, jax.random.key(seed), world, task, params,
                           iterations=iterations, patience=patience)
        # The relative gap of first_iteration_at and of the rows' success (NaN after the stop).
        reached = (trace.best_cost - optimum) / optimum < SUCCESS_GAP
        first = jnp.argmax(reached)
        found = reached[first]
        evaluations = jnp.cumsum(trace.evaluations)
        return dict(cost=swarm.best(state).cost, iterations=trace.iterations,
                    moves=jnp.sum(trace.moves), evaluations=jnp.sum(trace.evaluations),
                    fingerprint=run_fingerprint(state, trace),
                    target_iterations=jnp.where(found, first + 1, -1),
                    target_evaluations=jnp.where(found, evaluations[first], -1),
                    overflowed=trace.overflowed)

    def share(seeds, params, world, task, target):
        return jax.lax.map(lambda run_input: one(run_input, world, task, target),
                           (seeds, params), batch_size=min(group, seeds.shape[0]))

    return jax.jit(jax.shard_map(share, mesh=mesh,
                                 in_specs=(P(RUNS_AXIS), P(RUNS_AXIS), P(), P(), P()),
                                 out_specs=P(RUNS_AXIS), check_vma=False))


def _stacked_params(defaults, params: dict[str, np.ndarray], count: int):
    """The swarm's params with leaves f32[count]: ``params[name]`` where given, else the
    default."""
    return defaults._replace(**{
        name: np.asarray(params[name], np.float32) if name in params
        else np.full(count, np.float32(value)) for name, value in defaults._asdict().items()})


def _program_key(world) -> tuple:
    """Worlds with equal structure and array shapes share one compiled program."""
    leaves, treedef = jax.tree_util.tree_flatten(world)
    return treedef, tuple(leaf.shape for leaf in leaves)


def run_outcomes(cost: np.ndarray, optimum: float) -> dict[str, np.ndarray]:
    """The outcome columns of runs whose best paths cost ``cost`` (f64[C], inf without a path)
    on a map whose optimum is ``optimum``: ``gap`` (f64, relative; NaN without a path or a
    positive finite optimum), ``found`` and ``success`` (bool: within :data:`SUCCESS_GAP`)."""
    cost = np.asarray(cost, np.float64)
    found = np.isfinite(cost)
    gap = ((cost - optimum) / optimum if math.isfinite(optimum) and optimum > 0
           else np.full(cost.shape, np.nan))
    return dict(gap=gap, found=found, success=found & (gap < SUCCESS_GAP))


def _gather(outputs) -> Any:
    """Batch outputs as host arrays, from every process's devices."""
    if jax.process_count() > 1:
        from jax.experimental import multihost_utils
        return multihost_utils.process_allgather(outputs, tiled=True)
    return jax.device_get(outputs)
