"""The journal a walk loop writes its agents' moves to, and the logs laid out from it.

Lanes make their moves in blocks of ``BLOCK`` steps; after each block, every lane whose agent
moved appends that block to the journal, in the order the lanes wrote them (which depends on
the lanes' schedule). When the loop ends, :func:`ordered_logs` lays each run's blocks out agent
by agent as a :class:`~.log.MoveLog`, whose layout depends on the moves only.
"""
from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.walking.log import BLOCK, MoveLog, blocks_for
from jaxswarm.world.graph import NO_NODE


class Journal(NamedTuple):
    """The blocks of moves of a loop's agents in the order the lanes wrote them (leading axis:
    the blocks, room for every run's log), before they are laid out agent by agent.

    Attributes:
      nodes: i32[C, BLOCK] and slots: ``slot_dtype[C, BLOCK]`` a block's moves (as
        :class:`~.log.MoveLog`'s).
      row: i32[C] the block's agent (its row in the loop's results; the number of rows: no
        block).
      index: i32[C] the block's place among its agent's blocks.
      written: i32[] blocks written (more than C: the journal overflowed, the last were lost).
    """

    nodes: jax.Array
    slots: jax.Array
    row: jax.Array
    index: jax.Array
    written: jax.Array


def empty_journal(room: int, count: int, slot_dtype) -> Journal:
    """A journal with room for ``room`` blocks (static) of a loop of ``count`` agents (static),
    none written."""
    return Journal(nodes=jnp.zeros((room, BLOCK), jnp.int32),
                   slots=jnp.zeros((room, BLOCK), slot_dtype),
                   row=jnp.full((room,), count, jnp.int32),
                   index=jnp.zeros((room,), jnp.int32), written=jnp.int32(0))


def append(journal: Journal, nodes: jax.Array, slots: jax.Array, agent: jax.Array,
           first_move: jax.Array, moved: jax.Array) -> Journal:
    """``journal`` with the block of every lane whose agent moved appended (blocks past its
    room are lost, and counted).

    Args:
      journal: the journal.
      nodes: i32[BLOCK, l] and slots: ``slot_dtype[BLOCK, l]`` the lanes' block of moves, step
        major.
      agent: i32[l] each lane's agent (its row in the loop's results).
      first_move: i32[l] the agent's moves before the block (a multiple of ``BLOCK``).
      moved: bool[l] the agent moved in the block.
    """
    room = journal.row.shape[0]
    place = jnp.where(moved, journal.written + jnp.cumsum(moved) - 1, room)  # past: dropped
    return Journal(nodes=journal.nodes.at[place].set(nodes.T, mode="drop"),
                   slots=journal.slots.at[place].set(slots.T, mode="drop"),
                   row=journal.row.at[place].set(agent, mode="drop"),
                   index=journal.index.at[place].set(first_move // BLOCK, mode="drop"),
                   written=journal.written + jnp.sum(moved, dtype=jnp.int32))


def ordered_logs(journal: Journal, moves: jax.Array, start: jax.Array, num_agents: int,
                 blocks: int, max_steps: int) -> MoveLog:
    """Each run's :class:`~.log.MoveLog` (leading axis R) of ``blocks`` blocks (static): the
    journal's blocks laid out agent by agent.

    Args:
      journal: the loop's journal.
      moves: i32[R * A] each agent's moves (row ``f`` is agent ``f % A`` of run ``f // A``),
        which give each agent's blocks and so their offsets.
      start: i32[R] each run's start node.
      num_agents: A, agents per run (static).
      blocks: each run's log's blocks (static).
      max_steps: the walk's step budget (static).

    Returns:
      The logs; a run whose agents own more blocks than ``blocks``, or any run of a journal
      that overflowed, is marked ``overflowed``.
    """
    runs, agents = start.shape[0], num_agents
    owned = blocks_for(moves).reshape(runs, agents)
    offset = jnp.cumsum(owned, axis=1) - owned
    overflowed = (jnp.sum(owned, axis=1) > blocks) | (journal.written > journal.row.shape[0])
    count = runs * agents
    row = jnp.minimum(journal.row, count - 1)
    place = offset.reshape(-1)[row] + journal.index
    target = jnp.where((journal.row < count) & (place < blocks), row // agents * blocks + place,
                       runs * blocks)
    # Which journal block each log block is: a scatter of indices, then one gather of the
    # moves (the log written once, not filled and then overwritten).
    source = jnp.full((runs * blocks,), journal.row.shape[0], jnp.int32).at[target].set(
        jnp.arange(journal.row.shape[0], dtype=jnp.int32), mode="drop")

    def laid_out(table, fill):
        out = jnp.take(table, source, axis=0, mode="fill", fill_value=fill)
        return out.reshape((runs, blocks, BLOCK))

    return MoveLog(nodes=laid_out(journal.nodes, NO_NODE),
                   slots=laid_out(journal.slots, -1), offset=offset,
                   moves=moves.reshape(runs, agents), start=start,
                   overflowed=overflowed, max_steps=max_steps)
