"""Memory that changes while the agents walk: the walker's per-step hook.

Most swarms read a table that stays fixed during a walk (:mod:`.loop`). Some change their
memory at every move: a water drop takes soil from the edge it crosses, and its next choice and
its velocity depend on the soil it finds. Such a swarm hands :func:`~.loop.walk` a
:class:`StepHook` (static), its ``memory`` (a pytree per run, e.g. soil ``f32[N, K]``) and its
``hook_params`` (traced numbers). At every lockstep step the walker

1. reads each lane's row of its run's memory at the lane's node (the memory as it is at the
   start of the step) and adds ``hook.log_weights(...)`` of it to the lane's row of the fixed
   table, among the moves the table admits and the agent has not visited;
2. draws the moves and groups the lanes by the directed edge they cross (:func:`edge_groups`);
3. lets ``hook.update(...)`` write the step's moves into the memory and into each agent's own
   state (``f32[E]`` per agent, e.g. velocity and carried soil), which the walk returns.

Every agent of a step reads the memory as it was at the start of the step; the writes of agents
that cross the same edge in one step are applied in the order of their lanes. When the hook
changes the memory, every agent of a run has a lane from the first step, in agent order, and the
lanes never take another agent: step ``m`` is every agent's ``m``-th move, the lanes of one run
keep their order, and runs write only their own memory, so what a run's agents see of each
other's writes depends on neither the number of lanes nor the other runs of a batch.
A swarm without a hook pays nothing: the walker's program is the same as before.
"""
from __future__ import annotations

from typing import Any, Callable, NamedTuple

import jax
import jax.numpy as jnp

UNCLAIMED = jnp.iinfo(jnp.int32).max
"""The value of every entry of the walker's claims buffer (:func:`edge_groups`) between steps."""


class StepHook(NamedTuple):
    """A swarm's per-step memory rule (static: hashable by its functions).

    Attributes:
      state_width: E, floats of state each agent carries.
      initial_state: ``(params) -> f32[E]``: an agent's state when it starts (``params`` one
        run's hook params).
      log_weights: ``(params, memory_rows, admissible bool[l, K]) -> f32[l, K]``: added to the
        fixed table's row of each lane's node (``params`` per lane, f32[l] leaves;
        ``memory_rows`` each lane's node's row of its run's memory, e.g. f32[l, K]).
      update: ``(params, memory, move: Move, graph) -> (memory, f32[l, E])``: the memory of
        every run (leading axis R) and the lanes' states after the step's moves; None for a
        hook that only reads its memory (the walk leaves the memory and the states as they
        were, groups no moves, and the agents may walk in any lanes at any time).

      native: the name of the native walker's copy of this rule
        (:data:`jaxswarm.swarm.walking.native.HOOK_RULES`), or None: walks with this hook stay
        on the lanes.

    Build hooks from module-level functions, once: the walker's compiled loops are cached by
    the hook (a hook made per call would compile per call).
    """

    state_width: int
    initial_state: Callable[[Any], jax.Array]
    log_weights: Callable[..., jax.Array]
    update: Callable[..., tuple[Any, jax.Array]] | None = None
    native: str | None = None

    @property
    def writes(self) -> bool:
        """Whether the hook writes its memory and the agents' states at each step."""
        return self.update is not None


class EdgeGroups(NamedTuple):
    """The lanes of one step grouped by the directed edge they cross (same run, node and slot),
    in lane order within a group (see :func:`edge_groups`).

    Attributes:
      group: i32[l] per lane: its group's id, below ``num_groups`` (lanes that did not move
        share one group of their own).
      rank: i32[l] per lane: moving lanes of its group before it (0 if not moving).
      count: i32[l] per lane: moving lanes of its group (0 if not moving).
      moving: bool[l] the lane crosses an edge.
      num_groups: how many group ids there are (static).
    """

    group: jax.Array
    rank: jax.Array
    count: jax.Array
    moving: jax.Array
    num_groups: int

    @property
    def first(self) -> jax.Array:
        """bool[l]: the lane is the first of its group (one per crossed edge: the lane that
        writes the edge's memory)."""
        return self.moving & (self.rank == 0)

    def group_sum(self, values: jax.Array) -> jax.Array:
        """f32[l] per lane: the sum of ``values`` (f32[l]) over its group, summed in lane
        order (0 for lanes that did not move)."""
        sums = jax.ops.segment_sum(jnp.where(self.moving, values, 0.0), self.group,
                                   num_segments=self.num_groups)
        return jnp.where(self.moving, sums[self.group], 0.0)


class Move(NamedTuple):
    """One lockstep step's moves, as a hook's ``update`` sees them (leading axis: the lanes).

    Attributes:
      run: i32[l] the run of each lane's agent.
      agent: i32[l] the agent (its row in the walk's results: agent order).
      here: i32[l] the node it left (or stays on).
      slot: i32[l] the slot it took, -1 if it did not move.
      moving: bool[l] it moved in this step.
      state: f32[l, E] its state before the move.
      groups: the lanes grouped by the edge they cross (:class:`EdgeGroups`).
    """

    run: jax.Array
    agent: jax.Array
    here: jax.Array
    slot: jax.Array
    moving: jax.Array
    state: jax.Array
    groups: EdgeGroups


def edge_groups(run, here, slot, moving, claims, num_nodes: int, max_degree: int):
    """Group one step's lanes by the directed edge of the same run they cross.

    Args:
      run, here, slot: i32[l] each lane's run, node and slot (-1 or any value where it does not
        move).
      moving: bool[l] the lane crosses an edge in this step.
      claims: i32[R * N], ``UNCLAIMED`` everywhere: scratch with one entry per node of every
        run, carried by the walker from step to step, so grouping costs a few scatters of
        ``l`` entries rather than work on the whole memory.
      num_nodes, max_degree: N and K.

    Returns:
      ``(EdgeGroups, claims)``, the claims ``UNCLAIMED`` again. The lanes on one node of one
      run are named by the first of them (a scatter-min of lane numbers into the nodes'
      claims); a group is such a name and a slot, and a lane's rank is its place in the sort
      of the ``(group, lane)`` pairs (packed into one u32 key where they fit).
    """
    width = run.shape[0]
    lane = jnp.arange(width, dtype=jnp.int32)
    at = jnp.where(moving, run * num_nodes + here, claims.shape[0])  # out of range: dropped
    claims = claims.at[at].min(lane, mode="drop")
    first_on_node = claims.at[at].get(mode="fill", fill_value=width)
    # The reset's values are computed from the read, so XLA reads first and resets in place (a
    # reset that does not depend on the read made it copy the whole buffer at every step).
    claims = claims.at[at].set(jnp.where(first_on_node >= 0, UNCLAIMED, 0), mode="drop")
    num_groups = (width + 1) * max_degree  # lanes not moving: group ``width * K``
    group = first_on_node * max_degree + jnp.where(moving, slot, 0)
    ordered_group, ordered_lane = _sorted_pairs(group, lane, num_groups, width)
    position = jnp.arange(width, dtype=jnp.int32)
    group_start = jnp.full((num_groups,), width, jnp.int32).at[ordered_group].min(position)
    rank = jnp.zeros((width,), jnp.int32).at[ordered_lane].set(
        position - group_start[ordered_group], unique_indices=True)
    count = jax.ops.segment_sum(moving.astype(jnp.int32), group, num_segments=num_groups)
    return EdgeGroups(group=group, rank=jnp.where(moving, rank, 0),
                      count=jnp.where(moving, count[group], 0), moving=moving,
                      num_groups=num_groups), claims


def _sorted_pairs(group: jax.Array, lane: jax.Array, num_groups: int, width: int):
    """``(group, lane)`` (i32[l] each, ``group < num_groups``, ``lane`` the numbers ``0 ..
    width - 1``) sorted by group, then lane: two i32[l]. Packed into one u32 key when both fit
    its 32 bits (a sort of a single operand is several times cheaper on CPU than a sort of
    several), else sorted as two keys."""
    lane_bits = max(width - 1, 1).bit_length()
    if (num_groups - 1).bit_length() + lane_bits > 32:
        return jax.lax.sort((group, lane), num_keys=2)
    packed = jnp.sort((group.astype(jnp.uint32) << lane_bits) | lane.astype(jnp.uint32))
    return ((packed >> lane_bits).astype(jnp.int32),
            (packed & ((1 << lane_bits) - 1)).astype(jnp.int32))
