"""The lockstep walk loop shared by drops and ants.

``A`` agents start at one node. The algorithm hands the walker one log-weight per edge,
``f32[N, K]`` (its transition rule evaluated once per walk: pheromone, altitude gradients and
heuristics do not change while the agents walk). Each step, every still-walking agent gathers
its node's row, keeps the admissible slots (an edge with a finite log-weight to a node the agent
has not visited in this walk; on grids and path maps the neighbours are the node plus fixed
slot offsets, so only the log-weights are gathered), and draws one slot through the masked
sampler (:mod:`.sampler`; a greedy agent takes its most likely slot instead, ties drawn at
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

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, PartitionSpec as P

from jaxswarm.graph import NO_NODE, Graph
from jaxswarm.lattice import ORTHOGONAL_SLOTS, lattice_length, slot_offsets, total_length
from jaxswarm.swarm.walking import bits
from jaxswarm.swarm.walking.sampler import sample_masked

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
    return bits.union(walk.visited, num_nodes, which)


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
        :func:`~jaxswarm.swarm.walking.tables.edge_table`); ``-inf`` where the edge may not be
        taken (no neighbour, not valid on the current map, or excluded by the algorithm),
        ``FORCED`` where it must be.
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


class Lanes(NamedTuple):
    """The per-agent state of a walk (a pytree; leading axis ``a``: the agents of a share, or
    the few still walking once compacted).

    Attributes:
      position: i32[a] the node each agent is at.
      visited: u32[a, ceil(N / 32)] the nodes on each agent's path (:mod:`.bits`).
      slots: i8 or i16[a, C] the slot of each move so far, -1 after the agent stopped
        (C = max_steps + STEPS_PER_CHECK columns, so a whole block always fits).
      nodes: i16 or i32[a, C] the node each move reached, -1 after the agent stopped.
      walking: bool[a] still moving.
      arrived: bool[a] reached the goal.
      stuck: bool[a] stopped with no admissible neighbour.
      moves: i32[a] moves made (counted on grids and path maps, for the length).
      diagonal: i32[a] diagonal moves among them.
    """

    position: jax.Array
    visited: jax.Array
    slots: jax.Array
    nodes: jax.Array
    walking: jax.Array
    arrived: jax.Array
    stuck: jax.Array
    moves: jax.Array
    diagonal: jax.Array


class Carry(NamedTuple):
    """The walk loop's carry: ``key`` (the PRNG key of the next block), ``step`` (i32[]
    lockstep steps so far) and the agents' :class:`Lanes`."""

    key: jax.Array
    step: jax.Array
    lanes: Lanes


def _walk_share(key, graph: Graph, log_weights, start, goal, *, first, share: int,
                num_agents: int, max_steps: int, greedy_agents: int) -> Walk:
    """Walk agents ``first .. first + share - 1`` (``first`` may be traced) of a batch of
    ``num_agents``: their uniforms are their columns of the batch's draws."""
    n = graph.num_nodes
    agents = jnp.arange(share)
    greedy = first + agents < greedy_agents if greedy_agents else None
    position = jnp.full((share,), start)
    columns = max_steps + STEPS_PER_CHECK
    slot_dtype = jnp.int8 if graph.max_degree <= 127 else jnp.int16
    node_dtype = jnp.int16 if n <= 32767 else jnp.int32
    counts = jnp.zeros((share,), jnp.int32)
    carry = Carry(key=key, step=jnp.array(0, jnp.int32), lanes=Lanes(
        position=position,
        visited=bits.mark(jnp.zeros((share, (n + 31) // 32), jnp.uint32), agents, position),
        slots=jnp.full((share, columns), -1, slot_dtype),
        nodes=jnp.full((share, columns), NO_NODE, node_dtype),
        walking=jnp.full((share,), start != goal),
        arrived=jnp.full((share,), start == goal),
        stuck=jnp.zeros((share,), bool),
        moves=counts, diagonal=counts))

    def keep_walking(c: Carry):
        return (c.step < max_steps) & jnp.any(c.lanes.walking)

    def block(c: Carry, lanes_ids, greedy) -> Carry:
        """STEPS_PER_CHECK steps of the agents ``lanes_ids`` (i32[a] ids within the share;
        None: the whole share); their slots and nodes go to small step-major blocks (each step
        writes one contiguous row) that are transposed into the buffers once per block."""
        key, draw_key = jax.random.split(c.key)
        # The whole batch's uniforms are drawn and each agent takes its own column, so that a
        # walk does not depend on how the batch was shared out or compacted.
        draws = jax.random.uniform(draw_key, (STEPS_PER_CHECK, num_agents))
        if share < num_agents:
            draws = jax.lax.dynamic_slice_in_dim(draws, first, share, axis=1)
        if lanes_ids is not None:
            draws = draws[:, lanes_ids]
        rows = c.lanes.position.shape[0]

        def step_into_blocks(i, inner):
            lanes, step, slots, nodes = inner
            lanes, step, slot, node = one_step(lanes, step, draws[i], greedy)
            return lanes, step, slots.at[i].set(slot), nodes.at[i].set(node)

        slots = jnp.full((STEPS_PER_CHECK, rows), -1, slot_dtype)
        nodes = jnp.full((STEPS_PER_CHECK, rows), NO_NODE, node_dtype)
        lanes, step, slots, nodes = jax.lax.fori_loop(
            0, STEPS_PER_CHECK, step_into_blocks, (c.lanes, c.step, slots, nodes))
        if graph.is_grid:
            lanes = lanes._replace(moves=lanes.moves + jnp.sum(slots >= 0, axis=0),
                                   diagonal=lanes.diagonal
                                   + jnp.sum(slots >= ORTHOGONAL_SLOTS, axis=0))
        lanes = lanes._replace(
            slots=jax.lax.dynamic_update_slice(lanes.slots, slots.T, (0, c.step)),
            nodes=jax.lax.dynamic_update_slice(lanes.nodes, nodes.T, (0, c.step)))
        return Carry(key=key, step=step, lanes=lanes)

    def neighbours_of(here):
        """i32[a, K] each agent's neighbours, clamped into the map: computed from the slot
        offsets on grids (no gather), read from ``nbr`` otherwise. A slot without a neighbour
        yields some node there, never used: its log-weight is -inf."""
        if graph.is_grid:
            return jnp.clip(here[:, None] + jnp.asarray(slot_offsets(graph)), 0, n - 1)
        return jnp.maximum(graph.nbr[here], 0)

    def one_step(lanes: Lanes, step, uniform, greedy):
        here = lanes.position
        neighbours = neighbours_of(here)
        row = log_weights[here]
        seen = bits.is_marked(lanes.visited, neighbours)
        admissible = (row > -jnp.inf) & ~seen & lanes.walking[:, None]
        choice, has_choice = sample_masked(uniform, row, admissible, greedy)
        moving = lanes.walking & has_choice & (step < max_steps)
        target = jnp.take_along_axis(neighbours, jnp.maximum(choice, 0)[:, None], axis=1)[:, 0]
        there = jnp.where(moving, target, here)
        arrived_now = moving & (there == goal)
        lanes = lanes._replace(
            position=there,
            visited=bits.mark(lanes.visited, jnp.arange(here.shape[0]), there),
            walking=moving & ~arrived_now,
            arrived=lanes.arrived | arrived_now,
            stuck=lanes.stuck | (lanes.walking & ~has_choice))
        return (lanes, jnp.minimum(step + 1, max_steps),
                jnp.where(moving, choice, -1).astype(slot_dtype),
                jnp.where(moving, there, NO_NODE).astype(node_dtype))

    compact_lanes = share // COMPACT_SHARE
    if compact_lanes == 0:
        c = jax.lax.while_loop(keep_walking, lambda c: block(c, None, greedy), carry)
    else:
        c = jax.lax.while_loop(
            lambda c: keep_walking(c) & (jnp.sum(c.lanes.walking) > compact_lanes),
            lambda c: block(c, None, greedy), carry)
        # At most ``compact_lanes`` agents still walk: they go on in a batch of that size.
        ids = jnp.nonzero(c.lanes.walking, size=compact_lanes, fill_value=share)[0]
        held = jnp.minimum(ids, share - 1)  # padding lanes hold a copy, never walk
        few = jax.tree_util.tree_map(lambda x: x[held], c.lanes)
        few = c._replace(lanes=few._replace(walking=few.walking & (ids < share)))
        few = jax.lax.while_loop(
            keep_walking,
            lambda f: block(f, held, None if greedy is None else greedy[held]), few)
        c = Carry(key=few.key, step=few.step, lanes=jax.tree_util.tree_map(
            lambda all_, part: all_.at[ids].set(part, mode="drop"), c.lanes, few.lanes))
    lanes = c.lanes
    path = jnp.concatenate([position[:, None], lanes.nodes[:, :max_steps].astype(jnp.int32)],
                           axis=1)
    slots = lanes.slots[:, :max_steps].astype(jnp.int16)
    if graph.is_grid:
        length = lattice_length(lanes.moves, lanes.diagonal)
    else:
        length = total_length(graph, path[:, :-1], slots)
    return Walk(path=path, slots=slots, length=length, arrived=lanes.arrived,
                stuck=lanes.stuck, position=lanes.position, visited=lanes.visited, steps=c.step)
