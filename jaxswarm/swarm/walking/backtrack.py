"""The walk of an agent that backs out of dead ends: a depth-first walk with a memory.

The lane walker (:mod:`.loop`) stops an agent that has no admissible unvisited neighbour
("stuck"). An agent that "knows its old positions" (the Improved Max-Min paper's first ant) does
not stop there: it pops back to the node it came from and tries another way, never entering a
node twice. On a graph that is a depth-first walk: at each node the agent draws one admissible
unvisited neighbour (or, ``greedy``, takes the most likely one, the first of equals), and backs
out when it has none. It reaches the goal whenever a path exists (within ``max_nodes``), and its
path is what remains on its stack: the way it went, without the dead ends it backed out of. It
makes at most ``2 N`` moves, forward and back: every node is entered at most once and left
backwards at most once.

The choice at a node comes from a function of the node and of its unvisited neighbour slots
(:data:`ChoiceRule`), so a rule that depends on what the agent has visited (IWD's soil shift over
the admissible choices) is as easy to hand over as a fixed table's row.
"""
from __future__ import annotations

from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.walking import bits
from jaxswarm.swarm.walking.log import from_rows
from jaxswarm.swarm.walking.loop import Walk
from jaxswarm.swarm.walking.sampler import sample_masked
from jaxswarm.world.graph import NO_NODE, Graph
from jaxswarm.world.lattice import total_length
from jaxswarm.world.paths import step_slots

ChoiceRule = Callable[[jax.Array, jax.Array], jax.Array]
"""``(here i32[], unvisited bool[K]) -> f32[K]``: the log-weights of the moves out of ``here``,
``-inf`` where a move is not admissible (as in an edge table: at least every edge not valid on the
current map), given which slots lead to a neighbour the agent has not visited."""


class DepthFirstWalk(NamedTuple):
    """What one depth-first walk produced.

    Attributes:
      path: i32[max_nodes] the path without its backed-out dead ends, -1 padded (all -1 when
        the goal was not reached).
      found: bool[] the walk reached the goal.
      moves: i32[] the moves it made, forward and back.
    """

    path: jax.Array
    found: jax.Array
    moves: jax.Array


def depth_first_walk(key: jax.Array, graph: Graph, choice: ChoiceRule, start, goal, *,
                     max_nodes: int, greedy: bool = False) -> DepthFirstWalk:
    """One agent's depth-first walk from ``start`` to ``goal`` (see the module docstring).

    Args:
      key: PRNG key of its draws (the ``m``-th move draws from ``fold_in(key, m)``; unused when
        ``greedy``).
      graph: the map.
      choice: the transition rule (:data:`ChoiceRule`).
      start, goal: i32[] node indices (may be traced).
      max_nodes: the longest path the agent may hold (static); a way that would be longer is
        backed out of like a dead end.
      greedy: take the most likely admissible move instead of drawing one (static).

    Returns:
      A :class:`DepthFirstWalk`; with ``found`` False the path is empty (all -1) once every way
      within ``max_nodes`` was tried.
    """
    stack = jnp.full((max_nodes,), NO_NODE, jnp.int32).at[0].set(start)
    visited = jnp.zeros((graph.num_nodes,), bool).at[start].set(True)

    def searching(carry):
        stack, _, depth, _ = carry
        return (depth > 0) & (stack[jnp.maximum(depth - 1, 0)] != goal)

    def advance(carry):
        stack, visited, depth, move = carry
        here = stack[depth - 1]
        heads = jnp.where(graph.nbr[here] >= 0, graph.nbr[here], 0)
        unvisited = (graph.nbr[here] >= 0) & ~visited[heads]
        options = jnp.where(unvisited, choice(here, unvisited), -jnp.inf)
        if greedy:
            best = jnp.argmax(options)
            can_move = options[best] > -jnp.inf
        else:
            uniform = jax.random.uniform(jax.random.fold_in(key, move), (1,))
            drawn, has_choice = sample_masked(uniform, options[None],
                                              jnp.ones_like(options, bool)[None])
            best, can_move = jnp.maximum(drawn[0], 0), has_choice[0]
        can_move = can_move & (depth < max_nodes)
        there = heads[best]
        stack = jnp.where(can_move, stack.at[depth].set(there, mode="drop"),
                          stack.at[depth - 1].set(NO_NODE))
        visited = visited.at[there].set(visited[there] | can_move)
        return stack, visited, jnp.where(can_move, depth + 1, depth - 1), move + 1

    stack, _, depth, moves = jax.lax.while_loop(
        searching, advance, (stack, visited, jnp.int32(1), jnp.int32(0)))
    found = depth > 0
    return DepthFirstWalk(path=jnp.where(found, stack, NO_NODE), found=found, moves=moves)


def backtracking_walk(key: jax.Array, graph: Graph, choice: ChoiceRule, start, goal, *,
                      num_agents: int, max_steps: int) -> Walk:
    """``num_agents`` agents' depth-first walks (:func:`depth_first_walk`), as a
    :class:`~jaxswarm.swarm.walking.loop.Walk`.

    Agent ``a`` draws from ``fold_in(key, a)``; all read the same ``choice`` (a memory that
    does not change during the walk). Its log holds the way without its dead ends, so at most
    ``max_steps`` moves (an agent that found no way: none); ``moves`` counts every move the agent
    made, back-outs included (the work done), ``stuck`` marks an agent that tried every way in
    vain.

    Args:
      key: PRNG key.
      graph: the map.
      choice: the transition rule (:data:`ChoiceRule`).
      start, goal: i32[] node indices (may be traced).
      num_agents: A (static).
      max_steps: the longest path's moves (static).

    Returns:
      A :class:`~jaxswarm.swarm.walking.loop.Walk` (``state`` and ``memory`` None;
      ``lane_steps``: the agents walk in lockstep, A times the longest walk's moves).
    """
    keys = jax.vmap(lambda agent: jax.random.fold_in(key, agent))(jnp.arange(num_agents))
    walked = jax.vmap(lambda k: depth_first_walk(k, graph, choice, start, goal,
                                                 max_nodes=max_steps + 1))(keys)
    path = walked.path
    slots = jax.vmap(lambda p: step_slots(graph, p))(path)
    agents = jnp.arange(num_agents)
    steps = jnp.sum(slots >= 0, axis=1)
    on_path = jnp.zeros((num_agents, graph.num_nodes), bool).at[
        agents[:, None], jnp.where(path >= 0, path, graph.num_nodes)].set(True, mode="drop")
    slot_dtype = jnp.int8 if graph.max_degree <= 127 else jnp.int16
    return Walk(log=from_rows(path, slots.astype(slot_dtype), steps, start, max_steps),
                length=jnp.where(walked.found, total_length(graph, jnp.maximum(path[:, :-1], 0),
                                                            slots), 0.0),
                arrived=walked.found, stuck=~walked.found,
                position=jnp.where(walked.found, path[agents, steps], start),
                visited=bits.pack(on_path), moves=walked.moves,
                lane_steps=num_agents * jnp.max(walked.moves))
