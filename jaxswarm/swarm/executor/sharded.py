"""Many runs of one swarm as compiled calls shared out over the devices: what sweeps and tuners
run on.

A :class:`ShardedRuns` cuts a list of ``(seed, params)`` runs into calls of ``chunk_size`` runs
(padded to a multiple of the device count, or with ``fit_calls`` a small call to a quarter or a
half of that; padding rows are dropped), shares each call out over ``jax.devices()``
(``shard_map``, so it also runs across hosts), and each device goes through its share a group of
runs at a time, a ``vmap`` of the run loop inside ``lax.map`` (the walks of a group share one
queue of agents over the walker's lanes). Worlds of one shape share one compiled program; each
compile is logged. A call in which a walk had no room in its log is made again with room for
every move. A run with seed ``s`` uses ``jax.random.key(s)``, so what it returns equals
:func:`~jaxswarm.swarm.executor.run` with that key bit for bit, whatever the call it is in
(:mod:`jaxswarm.runtime.arithmetic`).
"""
from __future__ import annotations

import dataclasses
import time
from typing import Any, Callable

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec as P

from jaxswarm.runtime.programs import release_if_crowded
from jaxswarm.swarm.core import Swarm, Task, World, check_run, effective_patience
from jaxswarm.swarm.executor.runs import first_row, run_program, with_room
from jaxswarm.swarm.walking import LANES

RUNS_AXIS = "runs"
"""The mesh axis a call's runs are sharded over."""

Summary = Callable[[Any, Any, Any], dict]
"""``(state, trace, extra) -> {output: array}``: what a call keeps of one run (traced, per run;
``extra`` is what :meth:`ShardedRuns.run` was given, shared by every run)."""


def group_size(num_agents: int) -> int:
    """Runs of ``num_agents`` agents vmapped together by default: enough for a walk loop of
    ``LANES`` agents (64 runs of 16 agents, 4 of 256), at least one, whose lanes the queue keeps
    busy (:func:`jaxswarm.swarm.walking.lanes_for`)."""
    return max(1, LANES // num_agents)


@dataclasses.dataclass
class ShardedRuns:
    """One swarm's runs, as compiled calls over the devices (see the module docstring).

    Attributes:
      swarm: the swarm (registered, so that it can be built again with room in its logs).
      summary: what a call keeps of each run (:data:`~jaxswarm.swarm.executor.sharded.Summary`).
      iterations: iteration budget of each run.
      patience: stop a run this many iterations after its last gain (None: never).
      chunk_size: runs per compiled call.
      vmap_size: runs vmapped together on one device (None: :func:`group_size`).
      log: where one-line messages go (compiles, calls made again with room).
      fit_calls: pad a call of at most a quarter or a half of a chunk's runs to that share of
        the chunk rather than to a whole chunk: fewer wasted runs for the many small calls of
        a race, at the cost of up to three programs per world shape.
    """

    swarm: Swarm
    summary: Summary
    iterations: int
    patience: int | None
    chunk_size: int
    vmap_size: int | None = None
    log: Callable[[str], None] = print
    fit_calls: bool = False

    def __post_init__(self):
        devices = jax.devices()
        self.padded = -(-self.chunk_size // len(devices)) * len(devices)
        self.group = min(self.vmap_size or group_size(self.swarm.config.num_agents),
                         self.padded // len(devices))
        self._mesh = Mesh(np.asarray(devices), (RUNS_AXIS,))
        self._runs = NamedSharding(self._mesh, P(RUNS_AXIS))
        self._replicated = NamedSharding(self._mesh, P())
        self._compiled: dict = {}

    def run(self, seeds: np.ndarray, params, world: World, task: Task, extra=None, *,
            label: str = "the map") -> dict[str, np.ndarray]:
        """Run ``seeds`` (u32[C]) with ``params`` (the swarm's Params, leaves f32[C]) in
        ``world`` on ``task``, ``chunk_size`` runs a call.

        Args:
          extra: a pytree of arrays every run's summary is given (an optimum to measure gaps
            against).
          label: the world's name in log messages.

        Returns:
          output -> array[C]: the summary's outputs, host arrays, and ``seconds`` (f64: the
          wall time of the call the run was part of, compile excluded).
        """
        check_run(self.swarm, world, first_row(params), self.iterations, self.patience)
        world, task, extra = jax.device_put((world, task, extra), self._replicated)
        count, parts = len(seeds), []
        for first in range(0, count, self.chunk_size):
            size = min(self.chunk_size, count - first)
            index = np.minimum(np.arange(first, first + self.call_size(size)), count - 1)
            inputs = self._sharded((np.asarray(seeds)[index].astype(np.uint32),
                                    jax.tree_util.tree_map(lambda leaf: leaf[index], params)))
            outputs, seconds = self._call(label, inputs, world, task, extra)
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

    def _call(self, label: str, inputs, world, task, extra) -> tuple[dict, float]:
        """One compiled call on ``inputs`` (seeds u32[C], params with leaves f32[C], sharded
        over the runs axis): ``(outputs, seconds)``, the summary's outputs as host arrays, made
        again with room for every move where a walk overflowed its log, and the call's wall
        time (the first compile for the world's shape excluded)."""
        program = self._compiled_for(label, inputs, world, task, extra, roomy=False)
        began = time.perf_counter()
        outputs = _gather(program(*inputs, world, task, extra))
        if np.any(outputs.pop("overflowed")):
            self.log(f"a walk on {label} had no room for its moves: the call again with room "
                     "for every move")
            outputs = _gather(self._compiled_for(label, inputs, world, task, extra, roomy=True)(
                *inputs, world, task, extra))
            outputs.pop("overflowed")
        return outputs, time.perf_counter() - began

    def _sharded(self, host) -> tuple:
        """``host`` arrays as global arrays sharded over the runs axis (each process builds only
        its own devices' shards, so this also works across hosts)."""
        return jax.tree_util.tree_map(
            lambda x: jax.make_array_from_callback(x.shape, self._runs, lambda i, x=x: x[i]),
            host)

    def _compiled_for(self, label: str, inputs, world, task, extra, *, roomy: bool):
        """The program (``roomy``: with room for every move) compiled for ``world``'s shape:
        compiled and logged the first time a shape comes, reused after."""
        key = (_program_key(world), roomy, inputs[0].shape[0])
        if key not in self._compiled:
            if release_if_crowded():  # the process holds too many programs' pages: drop ours
                self._compiled.clear()
            began = time.perf_counter()
            program = _program(with_room(self.swarm) if roomy else self.swarm, self.summary,
                               self.iterations, self.patience, self._mesh, self.group)
            self._compiled[key] = program.lower(*inputs, world, task, extra).compile()
            size = inputs[0].shape[0]
            self.log(f"compiled {self.swarm.name} for {label}'s shape, "
                     f"{size} runs per chunk on {len(jax.devices())} device(s), "
                     f"{min(self.group, size // len(jax.devices()))} at a time, in "
                     f"{time.perf_counter() - began:.1f} s")
        return self._compiled[key]


def _program(swarm: Swarm, summary: Summary, iterations: int, patience: int | None, mesh: Mesh,
             group: int):
    """The jitted call: ``(seeds u32[C], params with leaves f32[C], world, task, extra) ->
    {output: [C, ...]}`` (the summary's and ``overflowed``), C a multiple of the mesh size, the
    runs sharded over the mesh's ``RUNS_AXIS``; each device maps over its runs ``group`` at a
    time."""
    loop = run_program(swarm, iterations, effective_patience(iterations, patience))

    def one(run_input, world, task, extra):
        seed, params = run_input
        state, trace = loop(jax.random.key(seed), world, task, params, None,
                            jnp.int32(iterations))
        return summary(state, trace, extra) | {"overflowed": trace.overflowed}

    def share(seeds, params, world, task, extra):
        return jax.lax.map(lambda run_input: one(run_input, world, task, extra),
                           (seeds, params), batch_size=min(group, seeds.shape[0]))

    return jax.jit(jax.shard_map(share, mesh=mesh,
                                 in_specs=(P(RUNS_AXIS), P(RUNS_AXIS), P(), P(), P()),
                                 out_specs=P(RUNS_AXIS), check_vma=False))


def _program_key(world) -> tuple:
    """Worlds with equal structure and array shapes share one compiled program."""
    leaves, treedef = jax.tree_util.tree_flatten(world)
    return treedef, tuple(leaf.shape for leaf in leaves)


def _gather(outputs) -> Any:
    """Call outputs as host arrays, from every process's devices."""
    if jax.process_count() > 1:
        from jax.experimental import multihost_utils
        return multihost_utils.process_allgather(outputs, tiled=True)
    return jax.device_get(outputs)
