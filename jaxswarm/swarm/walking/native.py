"""The walk as one native kernel call on CPU (issue 67; ``docs/native.md``).

:func:`walk_runs` takes what the lanes' loop (``loop._walk_runs``) takes and returns the fields
of the same :class:`~.loop.Walk`, every leaf bit for bit: the C++ handlers of ``walk.cc``
(:mod:`jaxswarm.runtime.native`) walk each agent of each run to its end in turn (no hook, or a
hook that only reads its memory) or a run's agents step by step together (a hook that writes
its memory, as the lanes walk them), with the lanes' arithmetic operation for operation, then
replay the lanes' schedule from the agents' step counts for the two outputs that depend on it
(``lane_steps``, and the blocks an overflowed journal loses). A hook walks natively when its
rule has a native copy (:data:`HOOK_RULES`). :data:`VARIABLE` picks the implementation when a
walk is traced (:func:`implementation`).
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
from jaxswarm.world.lattice import slot_lengths, slot_offsets

VARIABLE = "JAXSWARM_WALKER"
"""The environment variable that picks the walker's implementation when a walk is traced:
``lanes`` (the XLA lanes, the reference) or ``native`` (this module's kernels, on CPU). Unset:
:func:`platform_default`."""


def platform_default() -> str:
    """The implementation when neither a swarm nor :data:`VARIABLE` names one: ``native`` when
    JAX's default backend is the CPU, ``lanes`` on accelerators (the kernels are CPU code)."""
    return "native" if jax.default_backend() == "cpu" else "lanes"


HOOK_RULES = {
    "iwd_soil_choice": (1, ("alpha", "eps_s")),
    "iwd_soil": (2, ("alpha", "eps_s", "a_v", "b_v", "c_v", "a_s", "b_s", "c_s", "hud_scale",
                     "eps_v", "rho_n", "initial_velocity")),
}
"""The hooks ``walk.cc`` copies, by :attr:`~.hooks.StepHook.native` name: the kernel's rule
number and the hook params' fields it reads, in its order. ``iwd_soil_choice``:
:data:`jaxswarm.swarm.iwd.soil.SOIL_CHOICE` (eqs. 1-3 over the soil, which it does not change);
``iwd_soil``: :data:`jaxswarm.swarm.iwd.soil.SOIL` (eqs. 1-6 as the drops walk). Their memory is
the soil, one ``f32[N, K]`` per run."""


def implementation(hook=None, requested: str | None = None) -> str:
    """The implementation a walk traced now takes: ``requested`` (a swarm's
    :class:`~jaxswarm.swarm.walking.options.WalkerOptions`), else :data:`VARIABLE`'s, else
    :func:`platform_default`'s; ``native`` only for walks without a hook or with one that has a
    native copy (:data:`HOOK_RULES`), and only where the kernels can be built, else ``lanes``
    (with a warning when the kernels cannot be built).

    Raises:
      ValueError: :data:`VARIABLE` names no implementation.
    """
    chosen = requested or os.environ.get(VARIABLE, "").strip().lower() or platform_default()
    if chosen not in IMPLEMENTATIONS:
        raise ValueError(f"{VARIABLE} must be one of {', '.join(IMPLEMENTATIONS)}, got "
                         f"{chosen!r}")
    if chosen == "native" and hook is not None and hook.native not in HOOK_RULES:
        return "lanes"  # a hook of Python functions only: the lanes run it
    if chosen == "native" and not native.available():
        warnings.warn("the native walker cannot be built here (no C++ compiler?): walking on "
                      f"the lanes (set {VARIABLE}=lanes to say so)", RuntimeWarning,
                      stacklevel=3)
        return "lanes"
    return chosen


def check_implementations(names) -> list[str]:
    """``names`` (walker implementations, e.g. a benchmark's ``--implementations`` split at
    commas) as a list, each checked: one of
    :data:`~jaxswarm.swarm.walking.options.IMPLEMENTATIONS`, and ``native`` only where its
    kernels can be built (this builds and registers them).

    Raises:
      ValueError: naming the first that is neither, or saying the kernels cannot be built.
    """
    names = list(names)
    for name in names:
        if name not in IMPLEMENTATIONS:
            raise ValueError(f"{name!r} is none of {', '.join(IMPLEMENTATIONS)}")
    if "native" in names and not native.available():
        raise ValueError("the native kernels cannot be built here")
    return names


def walk_runs(seed, graph: Graph, log_weights, start, goal, memory, hook_params, *,
              num_agents: int, max_steps: int, greedy_agents: int, hook, log_moves: int | None,
              default_budget: int, schedule: tuple[int, int, int, int]) -> dict:
    """``loop._walk_runs`` as one native kernel call: the fields of the same
    :class:`~.loop.Walk` (the loop builds it), every leaf bit for bit, ``lane_steps`` (the
    lane-steps the lanes' loop would have executed, replayed) and an overflowed log's blocks
    included.

    Args:
      seed: u32[R, 2]; graph: the map; log_weights: f32[R or 1, N, K]; start, goal: i32[R];
      memory: with a hook, its memory (f32[R, N, K]); hook_params: its numbers (leaves f32[R]
      or f32[1]); the rest static, as ``loop._walk_runs``'s, and ``schedule``: the lanes'
      loop's ``(lanes, REFILL_SHARE, COMPACT_SHARE, SMALLEST_COMPACTION)``, which the kernel
      replays.

    Raises:
      ValueError: the hook has no native copy (:data:`HOOK_RULES`).
    """
    native.register()
    lanes, refill_share, compact_share, smallest_compaction = schedule
    runs = start.shape[0]
    blocks = room_blocks(num_agents, max_steps, log_moves, default_budget)
    slot_dtype = jnp.int8 if graph.max_degree <= 127 else jnp.int16
    neighbours = (jnp.asarray(slot_offsets(graph)) if graph.is_grid
                  else jnp.asarray(graph.nbr, jnp.int32))
    shapes = _shapes(graph, runs, num_agents, blocks, slot_dtype)
    inputs = [jnp.asarray(seed, jnp.uint32), jnp.asarray(log_weights, jnp.float32),
              jnp.asarray(start, jnp.int32), jnp.asarray(goal, jnp.int32), neighbours]
    attributes = dict(
        num_agents=np.int32(num_agents), max_steps=np.int32(max_steps),
        greedy_agents=np.int32(greedy_agents), blocks=np.int32(blocks), lanes=np.int32(lanes),
        refill_share=np.int32(refill_share), compact_share=np.int32(compact_share),
        smallest_compaction=np.int32(smallest_compaction))
    target = native.WALK_TARGET
    if hook is not None:
        target, attributes["rule"] = native.HOOKED_WALK_TARGET, _rule(hook)
        inputs += [jnp.asarray(memory, jnp.float32), hook_numbers(hook_params, hook),
                   jnp.asarray(slot_lengths(graph) if graph.is_grid else graph.cost,
                               jnp.float32)]
        written = memory.shape if hook.writes else (0,)  # a read-only hook writes none
        shapes += [jax.ShapeDtypeStruct(written, jnp.float32),  # memory after the walk
                   jax.ShapeDtypeStruct((runs, num_agents, hook.state_width), jnp.float32)]
    # "sequential": walks on different maps (a vmap the walker's batching rule does not fold)
    # are one call each; the runs of one map come folded into R by that rule.
    (nodes, slots, offset, moves, overflowed, length, arrived, stuck, position, visited,
     lane_steps, *hooked) = jax.ffi.ffi_call(target, tuple(shapes),
                                             vmap_method="sequential")(*inputs, **attributes)
    log = MoveLog(nodes=nodes, slots=slots, offset=offset, moves=moves, start=start,
                  overflowed=overflowed, max_steps=max_steps)
    if not graph.is_grid:  # general graphs: the edge costs summed from the log, as the lanes do
        length = walked_lengths(graph, log)
    out = dict(log=log, length=length, arrived=arrived, stuck=stuck, position=position,
               visited=visited, moves=moves, lane_steps=lane_steps)
    if hook is not None:
        memory_after, state = hooked
        out.update(state=state, memory=memory_after if hook.writes else memory)
    return out


def _rule(hook) -> np.int32:
    """The kernel's number of ``hook``'s rule (:data:`HOOK_RULES`).

    Raises:
      ValueError: the hook has no native copy.
    """
    if hook.native not in HOOK_RULES:
        raise ValueError(f"the native walker has no copy of this hook (native={hook.native!r}; "
                         f"it has {', '.join(HOOK_RULES)})")
    return np.int32(HOOK_RULES[hook.native][0])


def _shapes(graph: Graph, runs: int, num_agents: int, blocks: int, slot_dtype) -> list:
    """The plain walk kernel's outputs: the log's nodes, slots, offsets, moves and overflow,
    and each agent's length, arrival, stop, position and visited set, and the lane-steps."""
    per_agent = (runs, num_agents)
    words = (graph.num_nodes + 31) // 32
    return [jax.ShapeDtypeStruct((runs, blocks, BLOCK), jnp.int32),
            jax.ShapeDtypeStruct((runs, blocks, BLOCK), slot_dtype),
            jax.ShapeDtypeStruct(per_agent, jnp.int32), jax.ShapeDtypeStruct(per_agent, jnp.int32),
            jax.ShapeDtypeStruct((runs,), jnp.bool_),
            jax.ShapeDtypeStruct(per_agent, jnp.float32),
            jax.ShapeDtypeStruct(per_agent, jnp.bool_), jax.ShapeDtypeStruct(per_agent, jnp.bool_),
            jax.ShapeDtypeStruct(per_agent, jnp.int32),
            jax.ShapeDtypeStruct(per_agent + (words,), jnp.uint32),
            jax.ShapeDtypeStruct((runs,), jnp.int32)]


def hook_numbers(hook_params, hook) -> jax.Array:
    """f32[R or 1, P] the numbers of ``hook``'s native copy (the fields :data:`HOOK_RULES`
    names, in its order) of ``hook_params`` (leaves f32[R], f32[1] or f32[]), side by side."""
    columns = [jnp.atleast_1d(jnp.asarray(getattr(hook_params, name), jnp.float32))
               for name in HOOK_RULES[hook.native][1]]
    rows = max(column.shape[0] for column in columns)
    return jnp.stack([jnp.broadcast_to(column, (rows,)) for column in columns], axis=-1)
