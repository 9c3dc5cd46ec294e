"""Memory that changes while the agents walk: the walker's per-step hook.

Most swarms read a table that stays fixed during a walk (:mod:`.loop`). Some change their
memory at every move: a water drop takes soil from the edge it crosses, and its next choice and
its velocity depend on the soil it finds. Such a swarm hands :func:`~.loop.walk` a
:class:`StepHook` (static), its ``memory`` (a pytree per run, e.g. soil ``f32[N, K]``) and its
``hook_params`` (traced numbers). At every lockstep step the walker

1. adds ``hook.log_weights(...)`` (computed from the memory as it is at the start of the step)
   to each agent's row of the fixed table, among the moves the table admits and the agent has
   not visited;
2. draws the moves;
3. lets ``hook.update(...)`` write the step's moves into the memory and into each agent's own
   state (``f32[E]`` per agent, e.g. velocity and carried soil), which the walk returns.

Every agent of a step reads the memory as it was at the start of the step; the writes of agents
that cross the same edge in one step are applied in agent order (:func:`edge_groups` groups
them), so one key gives one bit-identical result. A swarm without a hook pays nothing: the
walker's program is the same as before.
"""
from __future__ import annotations

from typing import Any, Callable, NamedTuple

import jax
import jax.numpy as jnp


class StepHook(NamedTuple):
    """A swarm's per-step memory rule (static: hashable by its functions).

    Attributes:
      state_width: E, floats of state each agent carries.
      initial_state: ``(params) -> f32[E]``: an agent's state when it starts (``params`` one
        run's hook params).
      log_weights: ``(params, memory_rows f32[l, K], admissible bool[l, K]) -> f32[l, K]``:
        added to the fixed table's row of each lane's node (``params`` gathered per lane;
        ``memory_rows`` each lane's node's row of its run's memory).
      update: ``(params, memory, move: Move, graph) -> (memory, f32[l, E])``: the memory of
        every run (leading axis R) and the lanes' states after the step's moves.

    Build hooks from module-level functions, once: the walker's compiled loops are cached by
    the hook (a hook made per call would compile per call).
    """

    state_width: int
    initial_state: Callable[[Any], jax.Array]
    log_weights: Callable[..., jax.Array]
    update: Callable[..., tuple[Any, jax.Array]]


class Move(NamedTuple):
    """One lockstep step's moves, as a hook's ``update`` sees them (leading axis: the lanes).

    Attributes:
      run: i32[l] the run of each lane's agent.
      agent: i32[l] the agent (its row in the walk's results: agent order).
      here: i32[l] the node it left (or stays on).
      slot: i32[l] the slot it took, -1 if it did not move.
      moving: bool[l] it moved in this step.
      state: f32[l, E] its state before the move.
    """

    run: jax.Array
    agent: jax.Array
    here: jax.Array
    slot: jax.Array
    moving: jax.Array
    state: jax.Array


class EdgeGroups(NamedTuple):
    """The lanes of one step grouped by the directed edge they cross (same run, node and slot),
    in agent order within a group; the lanes that did not move form one group of their own, last
    (see :func:`edge_groups`).

    Attributes:
      order: i32[l] the lanes sorted by (edge, agent).
      start, stop: i32[l] per position of ``order``: where its group starts and ends there.
      rank: i32[l] per lane: moving lanes on its edge before it in agent order (0 if not moving).
      count: i32[l] per lane: moving lanes on its edge (0 if not moving).
      last: bool[l] per lane: it is the last of its edge's group (False if not moving).
    """

    order: jax.Array
    start: jax.Array
    stop: jax.Array
    rank: jax.Array
    count: jax.Array
    last: jax.Array

    def group_sum(self, values: jax.Array) -> jax.Array:
        """f32[l] per lane: the sum of ``values`` (f32[l]) over its group, summed in agent
        order."""
        sums = jax.ops.segment_sum(values[self.order], self.start,
                                   num_segments=values.shape[0], indices_are_sorted=True)
        return jnp.zeros_like(values).at[self.order].set(sums[self.start])


def edge_groups(move: Move, num_nodes: int, max_degree: int) -> EdgeGroups:
    """Group the lanes of one step by the directed edge of the same run they cross, each group
    in agent order: so that writes of agents that share an edge can be applied in that order."""
    edge = (move.run * num_nodes + move.here) * max_degree + jnp.maximum(move.slot, 0)
    key = jnp.where(move.moving, edge, jnp.iinfo(jnp.int32).max)
    order = jnp.lexsort((move.agent, key))
    ordered = key[order]
    start = jnp.searchsorted(ordered, ordered, side="left")
    stop = jnp.searchsorted(ordered, ordered, side="right")
    rank = jnp.zeros_like(key).at[order].set(jnp.arange(key.shape[0]) - start)
    count = jnp.zeros_like(key).at[order].set(stop - start)
    return EdgeGroups(order=order, start=start, stop=stop,
                      rank=jnp.where(move.moving, rank, 0),
                      count=jnp.where(move.moving, count, 0),
                      last=move.moving & (rank == count - 1))
