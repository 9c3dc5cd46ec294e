"""The lanes of a walk loop and one lockstep step of them.

A lane holds one agent at a time (:mod:`.loop` hands queued agents to lanes and stores what they
did). :class:`WalkInputs` is what every lane reads and nothing changes during the walk: the
map, the log-weight table, the runs' seeds, starts and goals, the hook and its params, and the
static sizes. :func:`step` moves every lane once: each walking lane gathers its node's row of
the table, keeps the admissible slots (a finite log-weight, a neighbour not yet visited), adds
the hook's log-weights of its run's memory, draws one slot from its agent's random stream
(:func:`choose_slots`), then moves, lets the hook write the step's moves, and stops when it
arrives, has no admissible slot or has used its step budget.
"""
from __future__ import annotations

from typing import Any, NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.walking import bits
from jaxswarm.swarm.walking.hooks import Move, StepHook, edge_groups
from jaxswarm.swarm.walking.sampler import sample_masked
from jaxswarm.swarm.walking.streams import uniforms
from jaxswarm.world.graph import NO_NODE, Graph
from jaxswarm.world.lattice import ORTHOGONAL_SLOTS


class WalkInputs(NamedTuple):
    """What the lanes of one walk loop read and never change (closed over by the loop, not
    carried). Leading axis R: the runs of a batch of walks sharing the loop.

    Attributes:
      graph: the map.
      log_weights: f32[R, N, K] (or f32[1, N, K], shared by every run) each edge's log-weight.
      seed: u32[R, 2] each run's random stream (:func:`.streams.uniforms`).
      start, goal: i32[R] each run's start and goal node.
      hook: the per-step memory rule (static; :mod:`.hooks`), or None.
      hook_params: the hook's numbers, leaves with leading axis R (or 1, shared by every run).
      num_agents: agents per run (static).
      max_steps: each agent's step budget (static).
      greedy_agents: the first this many agents of each run take their most likely slot
        (static).
      slot_dtype: the dtype of the results' slots (i8, or i16 on maps of more than 127 slots).
      offsets: i32[K] each slot's node offset on grids and path maps; None on other graphs.
    """

    graph: Graph
    log_weights: jax.Array
    seed: jax.Array
    start: jax.Array
    goal: jax.Array
    hook: StepHook | None
    hook_params: Any
    num_agents: int
    max_steps: int
    greedy_agents: int
    slot_dtype: Any
    offsets: jax.Array | None


POSITION, MOVES, DIAGONAL, FLAGS = range(4)
"""Columns of :attr:`Lanes.status`."""

WALKING, ARRIVED, STUCK = 1, 2, 4
"""Bits of a lane's ``FLAGS`` column."""


class Lanes(NamedTuple):
    """The state of the loop's lanes (a pytree; leading axis ``l``, the lanes).

    A lane's counters and flags share one array, ``status``: a step then writes them with one
    kernel instead of one kernel per field (XLA:CPU emits a kernel per output array), which at
    a few lanes is most of a step's cost. Read them through the properties.

    Attributes:
      agent: i32[l] the lane's agent, as its row in the loop's results; the number of rows
        when the lane holds none.
      run: i32[l] the run (of a batch of walks) the agent belongs to.
      status: i32[l, 4] per lane its ``POSITION`` (the node the agent is at), ``MOVES`` (moves
        made), ``DIAGONAL`` (diagonal moves among them, on grids and path maps) and ``FLAGS``
        (bits ``WALKING``, ``ARRIVED``, ``STUCK``); see :func:`lane_status`.
      visited: u32[l, ceil(N / 32)] the nodes on its path (:mod:`.bits`).
      state: f32[l, E] the agent's own state (with a hook; else None).
    """

    agent: jax.Array
    run: jax.Array
    status: jax.Array
    visited: jax.Array
    state: Any = None

    @property
    def position(self) -> jax.Array:
        """i32[l] the node each agent is at."""
        return self.status[:, POSITION]

    @property
    def moves(self) -> jax.Array:
        """i32[l] the moves each agent made."""
        return self.status[:, MOVES]

    @property
    def diagonal(self) -> jax.Array:
        """i32[l] the diagonal moves among them."""
        return self.status[:, DIAGONAL]

    @property
    def walking(self) -> jax.Array:
        """bool[l] the agent still moves."""
        return (self.status[:, FLAGS] & WALKING) != 0

    @property
    def arrived(self) -> jax.Array:
        """bool[l] the agent reached the goal."""
        return (self.status[:, FLAGS] & ARRIVED) != 0

    @property
    def stuck(self) -> jax.Array:
        """bool[l] the agent stopped with no admissible neighbour."""
        return (self.status[:, FLAGS] & STUCK) != 0


def lane_status(position, moves, diagonal, walking, arrived, stuck) -> jax.Array:
    """i32[l, 4] the :attr:`Lanes.status` of lanes with these counters (i32[l] each) and flags
    (bool[l] each)."""
    flags = (walking.astype(jnp.int32) * WALKING | arrived.astype(jnp.int32) * ARRIVED
             | stuck.astype(jnp.int32) * STUCK)
    return jnp.stack([position, moves, diagonal, flags], axis=-1)


def start_visited(inputs: WalkInputs, nodes: jax.Array) -> jax.Array:
    """u32[a, ceil(N / 32)] visited sets holding only ``nodes`` (i32[a], one node per set)."""
    words = (inputs.graph.num_nodes + 31) // 32
    return bits.mark(jnp.zeros((nodes.shape[0], words), jnp.uint32),
                     jnp.arange(nodes.shape[0]), nodes)


def params_of(inputs: WalkInputs, run: jax.Array):
    """The hook params of runs ``run`` (i32[l]), f32[l] leaves."""
    return jax.tree_util.tree_map(
        lambda p: p[run] if p.shape[0] > 1 else jnp.broadcast_to(p[0], run.shape),
        inputs.hook_params)


def initial_state(inputs: WalkInputs, run: jax.Array) -> jax.Array | None:
    """f32[l, E] the hook's state of agents starting in runs ``run`` (i32[l]); None without a
    hook."""
    if inputs.hook is None:
        return None
    return jax.vmap(inputs.hook.initial_state)(params_of(inputs, run))


def neighbours_of(inputs: WalkInputs, here: jax.Array) -> jax.Array:
    """i32[l, K] the neighbours of nodes ``here`` (i32[l]), clamped into the map: the slot
    offsets on grids (no gather), ``nbr`` otherwise. A slot without a neighbour yields some node
    there, never used: its log-weight is -inf."""
    graph = inputs.graph
    if graph.is_grid:
        return jnp.clip(here[:, None] + inputs.offsets, 0, graph.num_nodes - 1)
    return jnp.maximum(graph.nbr[here], 0)


def choose_slots(inputs: WalkInputs, lanes: Lanes, memory):
    """Each lane's draw among the admissible slots of its node: a finite log-weight (the table's
    plus, with a hook, the hook's of the lane's row of its run's memory), a neighbour not on the
    agent's path, the lane walking.

    Args:
      inputs: the walk's inputs.
      lanes: the lanes before the step.
      memory: the hook's memory, leading axis R (None without a hook).

    Returns:
      ``(neighbours i32[l, K], choice i32[l], has_choice bool[l], params)``: the lane's
      neighbours (:func:`neighbours_of`), the slot it drew (-1 without an admissible one), whether
      it had one, and with a hook the lanes' hook params (f32[l] leaves; else None).
    """
    here = lanes.position
    neighbours = neighbours_of(inputs, here)
    log_weights = inputs.log_weights
    row = log_weights[lanes.run if log_weights.shape[0] > 1 else 0, here]
    seen = bits.is_marked(lanes.visited, neighbours)
    admissible = (row > -jnp.inf) & ~seen & lanes.walking[:, None]
    params = None
    if inputs.hook is not None:
        params = params_of(inputs, lanes.run)
        rows = jax.tree_util.tree_map(lambda m: m[lanes.run, here], memory)
        row = row + inputs.hook.log_weights(params, rows, admissible)
    within_run = lanes.agent % inputs.num_agents
    uniform = uniforms(inputs.seed[lanes.run], within_run, lanes.moves)
    greedy = within_run < inputs.greedy_agents if inputs.greedy_agents else None
    choice, has_choice = sample_masked(uniform, row, admissible, greedy)
    return neighbours, choice, has_choice, params


def step(inputs: WalkInputs, lanes: Lanes, memory, claims):
    """One lockstep move of every lane: each walking lane draws a slot (:func:`choose_slots`)
    and takes it, the hook writes the step's moves into the memory and the agents' states, and
    a lane stops walking when its agent arrives, has no admissible slot or used its budget.

    Args:
      inputs: the walk's inputs.
      lanes: the lanes before the move.
      memory: the hook's memory, leading axis R (None without a hook).
      claims: i32[R * N] the hook's grouping scratch (:func:`~.hooks.edge_groups`; None
        without a hook that writes).

    Returns:
      ``(lanes, memory, claims, slot, node)``: the lanes, memory and claims after the move,
      and per lane the slot it took (``inputs.slot_dtype[l]``, -1 where it did not move) and
      the node it moved to (i32[l], ``NO_NODE`` where it did not move).
    """
    graph = inputs.graph
    here = lanes.position
    neighbours, choice, has_choice, params = choose_slots(inputs, lanes, memory)
    moving = lanes.walking & has_choice
    target = jnp.take_along_axis(neighbours, jnp.maximum(choice, 0)[:, None], axis=1)[:, 0]
    there = jnp.where(moving, target, here)
    moves = lanes.moves + moving
    arrived_now = moving & (there == inputs.goal[lanes.run])
    if inputs.hook is not None and inputs.hook.writes:
        slot = jnp.where(moving, choice, -1)
        groups, claims = edge_groups(lanes.run, here, slot, moving, claims, graph.num_nodes,
                                     graph.max_degree)
        memory, state = inputs.hook.update(params, memory, Move(
            run=lanes.run, agent=lanes.agent, here=here, slot=slot, moving=moving,
            state=lanes.state, groups=groups), graph)
        lanes = lanes._replace(state=state)
    lanes = lanes._replace(
        status=lane_status(
            position=there, moves=moves,
            diagonal=lanes.diagonal + (moving & (choice >= ORTHOGONAL_SLOTS)),
            walking=moving & ~arrived_now & (moves < inputs.max_steps),
            arrived=lanes.arrived | arrived_now, stuck=lanes.stuck | (lanes.walking & ~has_choice)),
        visited=bits.mark(lanes.visited, jnp.arange(here.shape[0]), there))
    return (lanes, memory, claims, jnp.where(moving, choice, -1).astype(inputs.slot_dtype),
            jnp.where(moving, there, NO_NODE))
