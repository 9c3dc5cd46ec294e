"""The plain walk (no hook) as one native kernel call on CPU (issue 67; ``docs/native.md``).

:func:`walk_runs` takes what the lanes' loop (``loop._walk_runs``) takes and returns the fields
of the same :class:`~.loop.Walk`, every leaf bit for bit: the C++ handler ``walk.cc``
(:mod:`jaxswarm.runtime.native`) walks each agent of each run to its end in turn with the
lanes' arithmetic operation for operation, then replays the lanes' schedule from the agents'
step counts for the two outputs that depend on it (``lane_steps``, and the blocks an
overflowed journal loses). :data:`VARIABLE` picks the implementation when a walk is traced
(:func:`implementation`).
"""
from __future__ import annotations

import os
import warnings

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime import native
from jaxswarm.swarm.walking.log import BLOCK, MoveLog, room_blocks, walked_lengths
from jaxswarm.swarm.walking.options import IMPLEMENTATIONS
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import slot_offsets

VARIABLE = "JAXSWARM_WALKER"
"""The environment variable that picks the walker's implementation when a walk is traced:
``lanes`` (the XLA lanes, the reference) or ``native`` (this module's kernel, for walks without
a hook on CPU). Unset: :data:`DEFAULT`."""

DEFAULT = "lanes"
"""The implementation when :data:`VARIABLE` is unset: the lanes, until the native loop walks
every kind of walk (the hooked and the backtracking walks do not yet)."""


def implementation(hook=None, requested: str | None = None) -> str:
    """The implementation a walk traced now takes: ``requested`` (a swarm's
    :class:`~jaxswarm.swarm.walking.options.WalkerOptions`), else :data:`VARIABLE`'s, else
    :data:`DEFAULT`; ``native`` only for walks without a hook (``hook`` None) when the kernel
    can be built here, else ``lanes`` (with a warning when the kernel cannot be built).

    Raises:
      ValueError: :data:`VARIABLE` names no implementation.
    """
    chosen = requested or os.environ.get(VARIABLE, "").strip().lower() or DEFAULT
    if chosen not in IMPLEMENTATIONS:
        raise ValueError(f"{VARIABLE} must be one of {', '.join(IMPLEMENTATIONS)}, got "
                         f"{chosen!r}")
    if chosen == "native" and hook is not None:
        return "lanes"  # the hooked walk has no native loop yet
    if chosen == "native" and not native.available():
        warnings.warn(f"{VARIABLE}=native but the native walker cannot be built here (no C++ "
                      f"compiler?): walking on the lanes", RuntimeWarning, stacklevel=3)
        return "lanes"
    return chosen


def walk_runs(seed, graph: Graph, log_weights, start, goal, memory, hook_params, *,
              num_agents: int, max_steps: int, greedy_agents: int, hook, log_moves: int | None,
              default_budget: int, schedule: tuple[int, int, int, int]) -> dict:
    """``loop._walk_runs`` without a hook, as one native kernel call: the fields of the same
    :class:`~.loop.Walk` (the loop builds it), every leaf bit for bit, ``lane_steps`` (the
    lane-steps the lanes' loop would have executed, replayed) and an overflowed log's blocks
    included.

    Args:
      seed: u32[R, 2]; graph: the map; log_weights: f32[R or 1, N, K]; start, goal: i32[R];
      memory, hook_params: None (no hook); the rest static, as ``loop._walk_runs``'s, and
      ``schedule``: the lanes' loop's ``(lanes_for(R * A), REFILL_SHARE, COMPACT_SHARE,
      SMALLEST_COMPACTION)``, which the kernel replays.

    Raises:
      ValueError: a hook was given.
    """
    if hook is not None:
        raise ValueError("the native walker walks without a hook only")
    del memory, hook_params
    native.register()
    lanes, refill_share, compact_share, smallest_compaction = schedule
    runs = start.shape[0]
    blocks = room_blocks(num_agents, max_steps, log_moves, default_budget)
    slot_dtype = jnp.int8 if graph.max_degree <= 127 else jnp.int16
    neighbours = (jnp.asarray(slot_offsets(graph)) if graph.is_grid
                  else jnp.asarray(graph.nbr, jnp.int32))
    words = (graph.num_nodes + 31) // 32
    per_agent = (runs, num_agents)
    shapes = (
        jax.ShapeDtypeStruct((runs, blocks, BLOCK), jnp.int32),  # nodes
        jax.ShapeDtypeStruct((runs, blocks, BLOCK), slot_dtype),  # slots
        jax.ShapeDtypeStruct(per_agent, jnp.int32),  # offset
        jax.ShapeDtypeStruct(per_agent, jnp.int32),  # moves
        jax.ShapeDtypeStruct((runs,), jnp.bool_),  # overflowed
        jax.ShapeDtypeStruct(per_agent, jnp.float32),  # length
        jax.ShapeDtypeStruct(per_agent, jnp.bool_),  # arrived
        jax.ShapeDtypeStruct(per_agent, jnp.bool_),  # stuck
        jax.ShapeDtypeStruct(per_agent, jnp.int32),  # position
        jax.ShapeDtypeStruct(per_agent + (words,), jnp.uint32),  # visited
        jax.ShapeDtypeStruct((runs,), jnp.int32),  # lane_steps
    )
    # "sequential": walks on different maps (a vmap the walker's batching rule does not fold)
    # are one call each; the runs of one map come folded into R by that rule.
    (nodes, slots, offset, moves, overflowed, length, arrived, stuck, position, visited,
     lane_steps) = jax.ffi.ffi_call(native.WALK_TARGET, shapes, vmap_method="sequential")(
        jnp.asarray(seed, jnp.uint32), jnp.asarray(log_weights, jnp.float32),
        jnp.asarray(start, jnp.int32), jnp.asarray(goal, jnp.int32), neighbours,
        num_agents=np.int32(num_agents), max_steps=np.int32(max_steps),
        greedy_agents=np.int32(greedy_agents), blocks=np.int32(blocks),
        lanes=np.int32(lanes), refill_share=np.int32(refill_share),
        compact_share=np.int32(compact_share), smallest_compaction=np.int32(smallest_compaction))
    log = MoveLog(nodes=nodes, slots=slots, offset=offset, moves=moves, start=start,
                  overflowed=overflowed, max_steps=max_steps)
    if not graph.is_grid:  # general graphs: the edge costs summed from the log, as the lanes do
        length = walked_lengths(graph, log)
    return dict(log=log, length=length, arrived=arrived, stuck=stuck, position=position,
                visited=visited, moves=moves, lane_steps=lane_steps)

