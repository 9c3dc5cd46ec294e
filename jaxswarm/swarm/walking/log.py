"""A walk's moves, stored as they were made: blocks of moves with per-agent offsets.

The walker's lanes move ``BLOCK`` steps at a time, and each lane whose agent moved in those steps
writes one block: the slot of each move and the node it led to. After the walk the blocks are
laid out agent by agent, each agent's blocks in the order it made them, so an agent's ``m``-th
move is entry ``m % BLOCK`` of block ``offset[a] + m // BLOCK`` (:class:`MoveLog`). The log
holds the moves made, not the longest walk possible: an agent that stopped after 84 moves owns
6 blocks whatever the step budget.

Capacity: the log of a walk of ``A`` agents has room for ``A`` times the blocks of
``log_moves`` moves (:func:`log_blocks`), an average per agent, so a few agents that wander for
the whole budget fit beside the many that stop early. Shapes are static, so a walk whose agents
made more moves than that cannot keep them all: its log says so (``overflowed``), the moves of
some agents are missing from it, and what is read from it is wrong. The run that made it is
run again with room for every agent's whole budget (:mod:`jaxswarm.swarm.executor` does it;
a caller who maps a run inside a program of its own reads ``Trace.overflowed``): the log's size
changes no move, so the result is the one a larger log would have given.
:func:`default_log_moves` is the room a large walk gets when its swarm does not say
(:func:`room_blocks`; a small one gets room for every move).

Reading the log: :func:`paths` gives agents' paths and slots padded to a width (the columns a
rule needs, cut as :func:`~jaxswarm.swarm.walking.moves.on_walk` cuts them), :func:`columns`
some columns of every agent's path, :func:`agent_rows` one agent's row of them,
:func:`agent_path` one agent's whole path, and
:func:`all_same` whether every agent walked the same moves.
"""
from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.world.graph import NO_NODE
from jaxswarm.world.lattice import total_length

BLOCK = 16
"""Moves per block: the moves a lane makes between two refills of the walk loop."""

ROOM_FOR_EVERY_MOVE = 2 ** 31 - 1
"""A ``log_moves`` that gives every agent room for its whole step budget: no walk overflows."""

SMALLEST_DEFAULT_ROOM = 8 * BLOCK
"""The fewest moves per agent :func:`default_log_moves` gives a walk's log (small maps, whose
budgets are short, get room for every move)."""

WHOLE_ROOM_BYTES = 2 ** 20
"""A run whose log with room for every agent's whole budget takes at most this many bytes gets
that room (:func:`room_blocks`): small walks never overflow, so never run twice; larger ones
get :func:`default_log_moves`, which does not grow with the budget. Per run, not per batch: a
run's shapes may not depend on the batch it is in."""

BLOCK_BYTES = BLOCK * 5
"""Bytes of one block of a log: 16 i32 nodes and 16 i8 slots."""


@dataclasses.dataclass(frozen=True)
class MoveLog:
    """The moves of one walk's ``A`` agents (a pytree; ``max_steps`` static).

    Attributes:
      nodes: i32[C, BLOCK] the node each move led to; ``NO_NODE`` past an agent's last move.
      slots: i8[C, BLOCK] (i16 on graphs of more than 127 slots) the neighbour slot of each
        move (``nodes = nbr[previous node, slot]``); -1 past an agent's last move.
      offset: i32[A] each agent's first block (its blocks follow in order).
      moves: i32[A] the moves each agent made (those the log holds).
      start: i32[] the node every agent started at.
      overflowed: bool[] the agents made more moves than the log holds: some are missing.
      max_steps: the step budget (static): a path holds at most ``max_steps + 1`` nodes.
    """

    nodes: jax.Array
    slots: jax.Array
    offset: jax.Array
    moves: jax.Array
    start: jax.Array
    overflowed: jax.Array
    max_steps: int


jax.tree_util.register_dataclass(
    MoveLog, data_fields=["nodes", "slots", "offset", "moves", "start", "overflowed"],
    meta_fields=["max_steps"])


def blocks_for(moves: jax.Array) -> jax.Array:
    """i32[...] the blocks that hold ``moves`` (i32[...]) moves."""
    return (moves + BLOCK - 1) // BLOCK


def default_log_moves(max_steps: int, default_budget: int) -> int:
    """The moves per agent a walk's log has room for, on average, when its swarm does not say:
    half the map's default step budget (``default_budget``, which grows with the map, not with
    the ``max_steps`` a caller asks for), at least ``SMALLEST_DEFAULT_ROOM``, at most
    ``max_steps``. On maze100 (a budget of 1,600) that is 800, against 103 moves per ant from
    ACO*'s first pheromone and 475 per drop from rfd_graded's converged altitudes
    (``benchmarks/walk.py``)."""
    return max(1, min(max_steps, max(SMALLEST_DEFAULT_ROOM, default_budget // 2)))


def room_blocks(num_agents: int, max_steps: int, log_moves: int | None,
                default_budget: int) -> int:
    """The blocks of the log of a walk of ``num_agents`` agents (all static): room for
    ``log_moves`` moves an agent on average; when None, room for every move if the log then
    fits ``WHOLE_ROOM_BYTES``, else :func:`default_log_moves` (of the map's
    ``default_budget``)."""
    if log_moves is not None:
        return log_blocks(num_agents, max_steps, log_moves)
    whole = log_blocks(num_agents, max_steps, max_steps)
    if whole * BLOCK_BYTES <= WHOLE_ROOM_BYTES:
        return whole
    return log_blocks(num_agents, max_steps, default_log_moves(max_steps, default_budget))


def log_blocks(num_agents: int, max_steps: int, log_moves: int) -> int:
    """Blocks of the log of a walk of ``num_agents`` agents with room for ``log_moves`` moves
    per agent on average: never more than every agent's whole budget needs, where no walk can
    overflow."""
    return num_agents * int(blocks_for(min(log_moves, max_steps)))


def from_rows(path: jax.Array, slots: jax.Array, moves: jax.Array, start,
              max_steps: int) -> MoveLog:
    """The log of agents' padded paths and slots (a walk that keeps whole rows).

    Args:
      path: i32[A, L] nodes visited from the start, -1 padded (``L <= max_steps + 1``).
      slots: [A, L - 1] each move's slot, -1 padded.
      moves: i32[A] the moves on each path.
      start: i32[] the start node.
      max_steps: the step budget (static).

    Returns:
      A :class:`MoveLog` whose agents own ``ceil((L - 1) / BLOCK)`` blocks each.
    """
    count, width = slots.shape
    per_agent = int(blocks_for(width))
    pad = per_agent * BLOCK - width
    nodes = jnp.pad(path[:, 1:], ((0, 0), (0, pad)), constant_values=NO_NODE)
    slots = jnp.pad(slots, ((0, 0), (0, pad)), constant_values=-1)
    return MoveLog(nodes=nodes.reshape(-1, BLOCK), slots=slots.reshape(-1, BLOCK),
                   offset=jnp.arange(count, dtype=jnp.int32) * per_agent,
                   moves=moves.astype(jnp.int32), start=jnp.asarray(start, jnp.int32),
                   overflowed=jnp.array(False), max_steps=max_steps)


def columns(log: MoveLog, column: jax.Array):
    """Columns of the agents' paths and slots, as if padded to the budget.

    Args:
      log: the walk's log.
      column: i32[A, k] (or i32[k], the same for every agent) path columns, any value.

    Returns:
      ``(nodes i32[A, k], slots [A, k])``: ``path[a, column]`` (the start at column 0, -1 past
      the agent's last node or outside the path) and ``slots[a, column]`` (the slot of move
      ``column``, -1 where no such move was made).
    """
    column = jnp.broadcast_to(column, log.moves.shape + column.shape[-1:])
    moves = log.moves[:, None]

    def entry(table, move, fill):
        made = (move >= 0) & (move < moves)
        safe = jnp.where(made, move, 0)
        block = jnp.minimum(log.offset[:, None] + safe // BLOCK, table.shape[0] - 1)
        return jnp.where(made, table[block, safe % BLOCK], fill)

    nodes = entry(log.nodes, column - 1, NO_NODE)
    nodes = jnp.where((column == 0), log.start, nodes)
    return nodes, entry(log.slots, column, jnp.asarray(-1, log.slots.dtype))


def paths(log: MoveLog, width: int | None = None):
    """Every agent's path and slots, padded to ``width`` moves.

    Args:
      log: the walk's log.
      width: the moves a row holds (static; None: ``log.max_steps``). A row keeps the first
        ``width`` moves of its agent's walk.

    Returns:
      ``(path i32[A, width + 1], slots [A, width])`` as a walk padded to ``width`` lays them out:
      the start, then the node of each move, -1 after the last; each move's slot, -1 after it.
    """
    width = log.max_steps if width is None else width
    path, _ = columns(log, jnp.arange(width + 1))
    _, slots = columns(log, jnp.arange(width))
    return path, slots


def agent_rows(log: MoveLog, agent: jax.Array, width: int):
    """One agent's row of :func:`paths`: ``(path i32[width + 1], slots [width])`` of agent
    ``agent`` (i32[]), its first ``width`` moves; an ``agent`` past the last (``>= A``) made
    no moves (the start, then -1; slots -1)."""
    one = _one_agent(log, agent)
    path, _ = columns(one, jnp.arange(width + 1))
    _, slots = columns(one, jnp.arange(width))
    return path[0], slots[0]


def agent_path(log: MoveLog, agent: jax.Array, length: int) -> jax.Array:
    """i32[length] agent ``agent``'s (i32[]) path, -1 padded (cut after ``length`` nodes)."""
    return columns(_one_agent(log, agent), jnp.arange(length))[0][0]


def _one_agent(log: MoveLog, agent: jax.Array) -> MoveLog:
    """The log of agent ``agent`` (i32[]) alone; an agent past the last made no moves."""
    count = log.moves.shape[0]
    known = jnp.minimum(agent, count - 1)
    return dataclasses.replace(log, offset=log.offset[known][None],
                               moves=jnp.where(agent < count, log.moves[known], 0)[None])


def walked_lengths(graph, logs: MoveLog) -> jax.Array:
    """f32[R, A]: each agent's walked length on a general graph, the edge costs summed along its
    logged moves (``logs`` with a leading run axis R)."""
    def one(log):
        path, slots = paths(log)
        return total_length(graph, path[:, :-1], slots)
    return jax.vmap(one)(logs)


def known_overflowed(flag: jax.Array) -> bool:
    """Whether ``flag`` (bool[...], a log's or a trace's ``overflowed``), when concrete, is set
    anywhere; False for a traced flag, which only its caller can act on."""
    return not isinstance(flag, jax.core.Tracer) and bool(np.any(np.asarray(flag)))


def all_same(log: MoveLog) -> jax.Array:
    """bool[]: every agent made the same moves as agent 0 (so walked its path)."""
    moves = log.moves
    owned = blocks_for(moves[0])
    block = jnp.arange(log.slots.shape[0])
    # Agent a's j-th block against agent 0's j-th, over every block an agent owns.
    agent = jnp.searchsorted(log.offset, block, side="right") - 1
    index = block - log.offset[agent]
    owns = index < blocks_for(moves[agent])
    same = jnp.all(log.slots[block] == log.slots[log.offset[0] + jnp.minimum(index, owned - 1)],
                   axis=1)
    return jnp.all(moves == moves[0]) & jnp.all(same | ~owns)
