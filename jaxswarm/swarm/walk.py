"""The lockstep walker shared by drops and ants, and the single masked sampler.

``A`` agents start at one node. The algorithm hands the walker one log-weight per edge,
``f32[N, K]`` (its transition rule evaluated once per walk: pheromone, altitude gradients and
heuristics do not change while the agents walk). Each step, every still-walking agent gathers
its node's row, keeps the admissible slots (an edge with a finite log-weight to a node the agent
has not visited in this walk; on grids and path maps the neighbours are the node plus fixed
slot offsets, so only the log-weights are gathered), and draws one slot through
:func:`sample_masked` (a greedy agent takes its most likely slot instead, ties drawn at
random). An agent stops when it reaches the goal, when it has no admissible neighbour ("stuck"),
or when the step budget runs out. The walk is a ``lax.while_loop`` that ends as soon as every
agent has stopped; once at most ``A // COMPACT_SHARE`` agents still walk, it goes on with a batch
of just those.
With ``devices > 1`` the agents are shared out over that many devices, each running its own
loop (``shard_map``); every agent draws the same uniforms either way, so neither compaction nor
the number of devices changes a walk.

Memory: while walking, the visited sets are bit sets ``u32[A, ceil(N / 32)]``, the chosen slots
``i8[A, L - 1]`` and the nodes ``i16[A, L - 1]`` (i32 above 32,767 nodes; ``L = max_steps + 1``),
written a block of ``STEPS_PER_CHECK`` steps at a time; the paths come out as ``i32[A, L]``
and the visited sets with them (:func:`visited_nodes` reads them).
Batch sizes in sweeps must be chosen with that in mind.
"""
from __future__ import annotations

import functools
import operator
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, PartitionSpec as P

from jaxswarm.graph import NO_NODE, Graph
from jaxswarm.lattice import ORTHOGONAL_SLOTS, lattice_length, slot_offsets, total_length

STEPS_PER_CHECK = 64
"""Steps per test of the walk's stop condition. Under ``vmap`` a ``while_loop`` selects between
the old and new carry of every lane at each iteration, copying the buffers; testing every 64
steps amortises that copy (agents that stopped simply idle in between)."""

COMPACT_SHARE = 8
"""When at most ``A // COMPACT_SHARE`` agents still walk, the walk goes on with only them, in a
batch of that many lanes: in a formed river most agents arrive together and a few stragglers
would otherwise keep the whole batch stepping. The uniforms stay those of the full batch, so
compaction does not change any walk."""

AGENT_AXIS = "agents"
"""The mesh axis over which :func:`walk` spreads its agents (``devices > 1``)."""

FORCED = 1e30
"""A log-weight that wins every draw: use it for moves that must be taken (e.g. into the goal)."""


class Walk(NamedTuple):
    """What a walk produced (a pytree).

    Attributes:
      path: i32[A, L] nodes visited, starting with the start node, -1 padded.
      slots: i16[A, L - 1] neighbour slot of each move (``path[a, t + 1] = nbr[path[a, t], slot]``),
        -1 after the agent stopped.
      length: f32[A] walked length (sum of edge costs). On grids and path maps the moves are
        counted by kind (:func:`jaxswarm.lattice.lattice_length`), so the same moves in any order
        give the same float; on general graphs the edge costs are summed.
      arrived: bool[A] reached the goal.
      stuck: bool[A] stopped with no admissible neighbour (before arriving).
      position: i32[A] the node each agent stopped at.
      visited: u32[A, ceil(N / 32)] the nodes on each agent's path as a packed bit set (bit
        ``n % 32`` of word ``n // 32`` is node ``n``); see :func:`visited_nodes`.
      steps: i32[] lockstep steps executed: the slowest agent's move count rounded up to a
        multiple of ``STEPS_PER_CHECK``, at most ``max_steps``.
    """

    path: jax.Array
    slots: jax.Array
    length: jax.Array
    arrived: jax.Array
    stuck: jax.Array
    position: jax.Array
    visited: jax.Array
    steps: jax.Array


def visited_nodes(walk: Walk, num_nodes: int, which: jax.Array | None = None) -> jax.Array:
    """bool[N]: the nodes on the paths of the agents selected by ``which`` (bool[A]; all
    agents when None), read from the walk's packed visited sets (cheaper than scattering the
    padded paths)."""
    words = walk.visited if which is None else jnp.where(which[:, None], walk.visited, 0)
    union = jax.lax.reduce(words, jnp.uint32(0), jax.lax.bitwise_or, (0,))
    bits = (union[:, None] >> jnp.arange(32, dtype=jnp.uint32)) & 1
    return bits.reshape(-1)[:num_nodes].astype(bool)


def sample_masked(uniform: jax.Array, log_weights: jax.Array, mask: jax.Array,
                  greedy: jax.Array | None = None):
    """Draw one slot per row among the masked-in slots, by inverse CDF.

    Args:
      uniform: f32[A] one uniform draw in [0, 1) per row (e.g. ``jax.random.uniform``).
      log_weights: f32[A, K] unnormalised log-probabilities; ``-inf`` means probability 0 and
        ``FORCED`` makes a slot certain.
      mask: bool[A, K] slots that may be chosen.
      greedy: optional bool[A]; a greedy row takes its most likely slot (ties drawn uniformly).

    Returns:
      ``(choice i32[A], has_choice bool[A])``. Rows with no admissible slot of positive weight get
      ``has_choice = False`` and ``choice = -1``; they must not move (``jax.random.categorical``
      would silently return slot 0 there).
    """
    masked = jnp.where(mask, log_weights, -jnp.inf)
    top = jnp.max(masked, axis=-1, keepdims=True)
    has_choice = jnp.isfinite(top[..., 0])  # False for no slot, all -inf, or NaN weights
    weights = jnp.exp(masked - jnp.where(has_choice[..., None], top, 0.0))
    if greedy is not None:
        weights = jnp.where(greedy[..., None], (masked == top).astype(weights.dtype), weights)
    # The first slot whose cumulative weight exceeds u (a slot of positive weight), capped at the
    # last slot of positive weight in case rounding made u reach the total. The cumulative sums
    # are unrolled over the (small, static) slots and counted on the fly: on CPU this fuses into
    # one loop, cheaper than a cumsum (a reduce-window) and argmax (a variadic reduce).
    columns = [weights[..., k] for k in range(weights.shape[-1])]
    total = functools.reduce(operator.add, columns)
    u = uniform * total
    below_u = below_total = jnp.zeros(total.shape, jnp.int32)
    running = jnp.zeros_like(total)
    for column in columns:
        running = running + column
        below_u = below_u + (running <= u)
        below_total = below_total + (running < total)
    choice = jnp.minimum(below_u, below_total)
    return jnp.where(has_choice, choice, NO_NODE).astype(jnp.int32), has_choice


def step_budget(graph: Graph, max_steps: int | None) -> int:
    """The step budget of a walk (static): ``max_steps``, or by default N - 1 (the longest walk
    without revisits) on general graphs and min(N - 1, 8 (H + W)) on grids."""
    if max_steps is not None:
        return max_steps
    longest = max(graph.num_nodes - 1, 1)
    return min(longest, 8 * sum(graph.shape)) if graph.is_grid else longest


def edge_table(graph: Graph, log_weights: jax.Array) -> jax.Array:
    """f32[N, K]: ``log_weights`` where the edge is valid on the current map, else ``-inf``.

    Algorithms build their per-edge log-weights (any finite values, ``FORCED`` for must-take
    moves, ``-inf`` to exclude) and pass them through this before :func:`walk`.
    """
    return jnp.where(graph.valid_edges(), log_weights, -jnp.inf)


def _mark(bits: jax.Array, agents: jax.Array, nodes: jax.Array) -> jax.Array:
    """Set bit ``nodes[a]`` in row ``agents[a]`` of a packed u32[A, ceil(N / 32)] bit set."""
    words = nodes >> 5
    updated = bits[agents, words] | (jnp.uint32(1) << (nodes & 31).astype(jnp.uint32))
    return bits.at[agents, words].set(updated)


def _is_marked(bits: jax.Array, nodes: jax.Array) -> jax.Array:
    """bool[A, K]: whether node ``nodes[a, k]`` is in agent ``a``'s packed bit set."""
    words = jnp.take_along_axis(bits, nodes >> 5, axis=1)
    return ((words >> (nodes & 31).astype(jnp.uint32)) & 1).astype(bool)


def check_devices(devices: int, num_agents: int) -> None:
    """Static check of a device count for ``num_agents`` agents: at least one, dividing the
    agents (whether JAX has that many devices is checked when the walk is traced)."""
    if devices < 1:
        raise ValueError(f"devices must be at least 1, got {devices}")
    if num_agents % devices:
        raise ValueError(f"devices ({devices}) must divide num_agents ({num_agents})")


def _agent_mesh(devices: int, num_agents: int) -> Mesh:
    """A 1-D mesh (axis ``AGENT_AXIS``) of the first ``devices`` devices for ``num_agents``
    agents, or a ValueError naming what does not fit."""
    check_devices(devices, num_agents)
    available = jax.devices()
    if devices > len(available):
        raise ValueError(
            f"devices={devices} but JAX sees {len(available)} {jax.default_backend()} "
            "device(s); on CPU call jax.config.update('jax_num_cpu_devices', n) before JAX's "
            "first use")
    return Mesh(np.array(available[:devices]), (AGENT_AXIS,))


def walk(key: jax.Array, graph: Graph, log_weights: jax.Array, start, goal, *, num_agents: int,
         max_steps: int, greedy_agents: int = 0, devices: int = 1) -> Walk:
    """Walk ``num_agents`` agents from ``start`` towards ``goal`` in lockstep.

    Args:
      key: PRNG key (split once per ``STEPS_PER_CHECK`` steps, which draw their uniforms in one
        batch: generating them one step at a time cost a third of a step; the same key gives the
        same walk).
      graph: the map.
      log_weights: f32[N, K] unnormalised log-probability of each edge (see
        :func:`edge_table`); ``-inf`` where the edge may not be taken (no neighbour, not valid
        on the current map, or excluded by the algorithm), ``FORCED`` where it must be.
      start, goal: i32[] node indices (may be traced).
      num_agents: A (static).
      max_steps: the step budget (static); paths hold ``max_steps + 1`` nodes.
      greedy_agents: how many agents (the first ones; static) always take their most likely
        admissible move, ties drawn at random, instead of sampling.
      devices: spread the agents evenly over the first ``devices`` of ``jax.devices()``
        (static), each walking its share in its own loop; the result, replicated on those
        devices, is bit-identical to ``devices=1``. On CPU this uses several cores for one
        walk (set ``jax.config.update("jax_num_cpu_devices", n)`` before JAX's first use).

    Returns:
      A :class:`Walk`.

    Raises:
      ValueError: ``devices`` below 1, more than JAX has, or not dividing ``num_agents``.
    """
    args = (key, graph, log_weights, jnp.asarray(start, jnp.int32), jnp.asarray(goal, jnp.int32))
    shape = dict(num_agents=num_agents, max_steps=max_steps, greedy_agents=greedy_agents)
    if devices == 1:
        return _walk_share(*args, first=0, share=num_agents, **shape)
    mesh = _agent_mesh(devices, num_agents)
    share = num_agents // devices

    def walk_share(*args):
        first = jax.lax.axis_index(AGENT_AXIS) * share
        part = _walk_share(*args, first=first, share=share, **shape)
        gathered = {name: jax.lax.all_gather(getattr(part, name), AGENT_AXIS, tiled=True)
                    for name in part._fields if name != "steps"}
        return Walk(steps=jax.lax.pmax(part.steps, AGENT_AXIS), **gathered)

    return jax.shard_map(walk_share, mesh=mesh, in_specs=P(), out_specs=P(),
                         check_vma=False)(*args)


def _walk_share(key, graph: Graph, log_weights, start, goal, *, first, share: int,
                num_agents: int, max_steps: int, greedy_agents: int) -> Walk:
    """Walk agents ``first .. first + share - 1`` (``first`` may be traced) of a batch of
    ``num_agents``: their uniforms are their columns of the batch's draws."""
    n = graph.num_nodes
    agents = jnp.arange(share)
    greedy = first + agents < greedy_agents if greedy_agents else None
    position = jnp.full((share,), start)
    # The buffers get one spare chunk of columns so that a chunk's block always fits.
    columns = max_steps + STEPS_PER_CHECK
    slot_dtype = jnp.int8 if graph.max_degree <= 127 else jnp.int16
    node_dtype = jnp.int16 if n <= 32767 else jnp.int32
    carry = dict(
        key=key,
        position=position,
        visited=_mark(jnp.zeros((share, (n + 31) // 32), jnp.uint32), agents, position),
        slots=jnp.full((share, columns), -1, slot_dtype),
        nodes=jnp.full((share, columns), NO_NODE, node_dtype),
        walking=jnp.full((share,), start != goal),
        arrived=jnp.full((share,), start == goal),
        stuck=jnp.zeros((share,), bool),
        step=jnp.array(0, jnp.int32),
    )
    if graph.is_grid:  # the moves of each kind, tallied per chunk, measure the walks' lengths
        carry.update(moves=jnp.zeros((share,), jnp.int32), diagonal=jnp.zeros((share,), jnp.int32))
    per_agent = [name for name in carry if name not in ("key", "step")]

    def keep_walking(c):
        return (c["step"] < max_steps) & jnp.any(c["walking"])

    def chunk(c, lanes, greedy):
        """STEPS_PER_CHECK steps of the agents ``lanes`` (i32[a] ids within the share; None:
        the whole share); their slots and nodes go to small step-major blocks (each step writes
        one contiguous row) that are transposed into the buffers once per chunk."""
        start_column = c["step"]
        key, draw_key = jax.random.split(c["key"])
        # The whole batch's uniforms are drawn and each agent takes its own column, so that a
        # walk does not depend on how the batch was shared out or compacted.
        draws = jax.random.uniform(draw_key, (STEPS_PER_CHECK, num_agents))
        if share < num_agents:
            draws = jax.lax.dynamic_slice_in_dim(draws, first, share, axis=1)
        if lanes is not None:
            draws = draws[:, lanes]
        rows = share if lanes is None else lanes.shape[0]

        def step_into_blocks(i, inner):
            c, slots, nodes = inner
            c, slot, node = one_step(c, draws[i], greedy)
            return c, slots.at[i].set(slot), nodes.at[i].set(node)

        slots = jnp.full((STEPS_PER_CHECK, rows), -1, slot_dtype)
        nodes = jnp.full((STEPS_PER_CHECK, rows), NO_NODE, node_dtype)
        c, slots, nodes = jax.lax.fori_loop(0, STEPS_PER_CHECK, step_into_blocks,
                                            (dict(c, key=key), slots, nodes))
        if graph.is_grid:
            c = dict(c, moves=c["moves"] + jnp.sum(slots >= 0, axis=0),
                     diagonal=c["diagonal"] + jnp.sum(slots >= ORTHOGONAL_SLOTS, axis=0))
        return dict(c, slots=jax.lax.dynamic_update_slice(c["slots"], slots.T, (0, start_column)),
                    nodes=jax.lax.dynamic_update_slice(c["nodes"], nodes.T, (0, start_column)))

    def neighbours_of(here):
        """i32[a, K] each agent's neighbours, clamped into the map: computed from the slot
        offsets on grids (no gather), read from ``nbr`` otherwise. A slot without a neighbour
        yields some node there, never used: its log-weight is -inf."""
        if graph.is_grid:
            return jnp.clip(here[:, None] + jnp.asarray(slot_offsets(graph)), 0, n - 1)
        return jnp.maximum(graph.nbr[here], 0)

    def one_step(c, uniform, greedy):
        here = c["position"]
        neighbours = neighbours_of(here)
        row = log_weights[here]
        seen = _is_marked(c["visited"], neighbours)
        admissible = (row > -jnp.inf) & ~seen & c["walking"][:, None]
        choice, has_choice = sample_masked(uniform, row, admissible, greedy)
        moving = c["walking"] & has_choice & (c["step"] < max_steps)
        target = jnp.take_along_axis(neighbours, jnp.maximum(choice, 0)[:, None], axis=1)[:, 0]
        there = jnp.where(moving, target, here)
        arrived_now = moving & (there == goal)
        c = dict(
            c,
            position=there,
            visited=_mark(c["visited"], jnp.arange(here.shape[0]), there),
            walking=moving & ~arrived_now,
            arrived=c["arrived"] | arrived_now,
            stuck=c["stuck"] | (c["walking"] & ~has_choice),
            step=jnp.minimum(c["step"] + 1, max_steps),
        )
        return (c, jnp.where(moving, choice, -1).astype(slot_dtype),
                jnp.where(moving, there, NO_NODE).astype(node_dtype))

    compact_lanes = share // COMPACT_SHARE
    if compact_lanes == 0:
        c = jax.lax.while_loop(keep_walking, lambda c: chunk(c, None, greedy), carry)
    else:
        c = jax.lax.while_loop(
            lambda c: keep_walking(c) & (jnp.sum(c["walking"]) > compact_lanes),
            lambda c: chunk(c, None, greedy), carry)
        # At most ``compact_lanes`` agents still walk: they go on in a batch of that size.
        ids = jnp.nonzero(c["walking"], size=compact_lanes, fill_value=share)[0]
        held = jnp.minimum(ids, share - 1)  # padding lanes hold a copy, never walk
        few = {name: c[name][held] for name in per_agent}
        few = jax.lax.while_loop(
            keep_walking, lambda f: chunk(f, held, None if greedy is None else greedy[held]),
            dict(few, walking=few["walking"] & (ids < share), key=c["key"], step=c["step"]))
        c = dict(c, step=few["step"], **{name: c[name].at[ids].set(few[name], mode="drop")
                                         for name in per_agent})
    path = jnp.concatenate([position[:, None], c["nodes"][:, :max_steps].astype(jnp.int32)],
                           axis=1)
    slots = c["slots"][:, :max_steps].astype(jnp.int16)
    if graph.is_grid:
        length = lattice_length(c["moves"], c["diagonal"])
    else:
        length = total_length(graph, path[:, :-1], slots)
    return Walk(path=path, slots=slots, length=length,
                arrived=c["arrived"], stuck=c["stuck"], position=c["position"],
                visited=c["visited"], steps=c["step"])
