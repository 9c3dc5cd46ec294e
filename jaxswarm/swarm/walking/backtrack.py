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

The choice at a node comes from a rule of the node and of its unvisited neighbour slots. The
rules the swarms use are data (:class:`DepthFirstRule`: a fixed table's row, or IWD's soil shift
over the admissible choices), which both implementations evaluate: XLA's while loop (``lanes``,
the reference) and the native kernel (``native``, :mod:`.native_backtrack`), bit for bit the
same walks; ``implementation`` picks one as it picks the walker's
(:func:`~.native.implementation`). Any other rule is a function (:data:`ChoiceRule`), which only
XLA can evaluate.
"""
from __future__ import annotations

import functools
from typing import Any, Callable, NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.walking import bits, native, native_backtrack
from jaxswarm.swarm.walking.hooks import StepHook
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


class DepthFirstRule(NamedTuple):
    """A transition rule as data, which either implementation evaluates.

    Without ``soil`` the log-weights out of ``here`` are ``table[here]`` (the Improved Max-Min
    paper's first ant, :mod:`jaxswarm.swarm.aco.bug2`); with it, the row plus the ``hook``'s
    log-weights of ``soil[here]`` over the admissible slots (unvisited, ``table > -inf``), as
    the walker adds a hook's (:mod:`.hooks`; IWD's soil choice,
    :data:`jaxswarm.swarm.iwd.soil.SOIL_CHOICE`, eqs. 1-3). The native kernel walks the table's
    rule and IWD's soil choice (``hook.native == "iwd_soil_choice"``).

    Attributes:
      table: f32[N, K] log-weights (``-inf``: not admissible).
      soil: f32[N, K] the memory the hook reads, or None (the table's row alone).
      hook: a hook that only reads its memory (:class:`~.hooks.StepHook`), with ``soil``.
      hook_params: its numbers (a pytree of f32[] leaves), with ``soil``.
    """

    table: jax.Array
    soil: jax.Array | None = None
    hook: StepHook | None = None
    hook_params: Any = None


NATIVE_HOOK = "iwd_soil_choice"
"""The one hook the native depth-first walk evaluates (:data:`.native.HOOK_RULES`)."""


def rule_choice(rule: DepthFirstRule | ChoiceRule) -> ChoiceRule:
    """The :data:`ChoiceRule` XLA evaluates for ``rule`` (a :data:`ChoiceRule` is itself)."""
    if not isinstance(rule, DepthFirstRule):
        return rule
    if rule.soil is None:
        return lambda here, unvisited: jnp.asarray(rule.table)[here]
    return functools.partial(_hooked_choice, rule)


def _hooked_choice(rule: DepthFirstRule, here, unvisited):
    """The log-weights f32[K] out of ``here``: the table's row plus the hook's over one lane."""
    row = jnp.asarray(rule.table)[here]
    admissible = unvisited & (row > -jnp.inf)
    one_lane = jax.tree_util.tree_map(lambda p: jnp.asarray(p)[None], rule.hook_params)
    return row + rule.hook.log_weights(one_lane, jnp.asarray(rule.soil)[here][None],
                                       admissible[None])[0]


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


def depth_first_walk(key: jax.Array, graph: Graph, choice: DepthFirstRule | ChoiceRule, start,
                     goal, *, max_nodes: int, greedy: bool = False,
                     implementation: str | None = None) -> DepthFirstWalk:
    """One agent's depth-first walk from ``start`` to ``goal`` (see the module docstring).

    Args:
      key: PRNG key of its draws (the ``m``-th move draws from ``fold_in(key, m)``; unused when
        ``greedy``).
      graph: the map.
      choice: the transition rule (:class:`DepthFirstRule`, or a :data:`ChoiceRule`, which
        walks on XLA whatever the implementation).
      start, goal: i32[] node indices (may be traced).
      max_nodes: the longest path the agent may hold (static); a way that would be longer is
        backed out of like a dead end.
      greedy: take the most likely admissible move instead of drawing one (static).
      implementation: ``"lanes"`` (XLA), ``"native"`` or None (:func:`.native.implementation`);
        static. Both walk the same walks, bit for bit.

    Returns:
      A :class:`DepthFirstWalk`; with ``found`` False the path is empty (all -1) once every way
      within ``max_nodes`` was tried.
    """
    if walks_natively(choice, implementation):
        path, found, moves = _native_walks(native_backtrack.key_data(key)[None], graph, choice,
                                           start, goal, max_nodes=max_nodes, greedy=greedy)
        return DepthFirstWalk(path=path[0], found=found[0], moves=moves[0])
    return _xla_walk(key, graph, rule_choice(choice), start, goal, max_nodes=max_nodes,
                     greedy=greedy)


def walks_natively(choice, implementation: str | None) -> bool:
    """Whether a walk with ``choice`` under ``implementation`` (resolved as the walker's,
    :func:`.native.implementation`) takes the kernel: a :data:`ChoiceRule` is Python, and a
    hook other than :data:`NATIVE_HOOK` has no copy in the kernel."""
    chosen = native.implementation(requested=implementation)
    return chosen == "native" and isinstance(choice, DepthFirstRule) and (
        choice.soil is None or choice.hook.native == NATIVE_HOOK)


def _native_walks(keys, graph: Graph, rule: DepthFirstRule, start, goal, *, max_nodes: int,
                  greedy: bool):
    """:func:`~.native_backtrack.depth_first_walks` of ``rule`` on ``graph``, one walk per row
    of ``keys`` (u32[W, 2]): ``(path i32[W, max_nodes], found bool[W], moves i32[W])``."""
    alpha = eps_s = None
    if rule.soil is not None:
        alpha, eps_s = native.hook_numbers(rule.hook_params, rule.hook)[0]
    return native_backtrack.depth_first_walks(
        keys, graph.nbr, rule.table, rule.soil, alpha, eps_s, start, goal,
        max_nodes=max_nodes, greedy=greedy)


def _xla_walk(key: jax.Array, graph: Graph, choice: ChoiceRule, start, goal, *, max_nodes: int,
              greedy: bool) -> DepthFirstWalk:
    """:func:`depth_first_walk` on XLA: a while loop of moves over the agent's stack."""
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


def backtracking_walk(key: jax.Array, graph: Graph, choice: DepthFirstRule | ChoiceRule, start,
                      goal, *, num_agents: int, max_steps: int,
                      implementation: str | None = None) -> Walk:
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
      choice: the transition rule (:class:`DepthFirstRule`, or a :data:`ChoiceRule`, which
        walks on XLA whatever the implementation).
      start, goal: i32[] node indices (may be traced).
      num_agents: A (static).
      max_steps: the longest path's moves (static).
      implementation: as :func:`depth_first_walk`'s (static); the native kernel walks every
        agent in one call (and a ``vmap``'s every run's agents too).

    Returns:
      A :class:`~jaxswarm.swarm.walking.loop.Walk` (``state`` and ``memory`` None;
      ``lane_steps``: the agents walk in lockstep, A times the longest walk's moves).
    """
    keys = jax.vmap(lambda agent: jax.random.fold_in(key, agent))(jnp.arange(num_agents))
    if walks_natively(choice, implementation):
        walked = DepthFirstWalk(*_native_walks(native_backtrack.key_data(keys), graph, choice,
                                               start, goal, max_nodes=max_steps + 1,
                                               greedy=False))
    else:
        rule = rule_choice(choice)
        walked = jax.vmap(lambda k: _xla_walk(k, graph, rule, start, goal,
                                              max_nodes=max_steps + 1, greedy=False))(keys)
    return _population_walk(graph, walked, start, num_agents=num_agents, max_steps=max_steps)


def _population_walk(graph: Graph, walked: DepthFirstWalk, start, *, num_agents: int,
                     max_steps: int) -> Walk:
    """The :class:`~jaxswarm.swarm.walking.loop.Walk` of the agents' depth-first walks
    ``walked`` (each field with a leading axis of A)."""
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
