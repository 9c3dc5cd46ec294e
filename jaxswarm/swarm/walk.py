"""The lockstep walker shared by drops and ants, and the single masked sampler.

``A`` agents start at one node. Each step, every still-walking agent gathers its ``K`` neighbour
slots, keeps the admissible ones (a valid edge of the current map to a node the agent has not
visited in this walk), asks the algorithm for one log-weight per slot, and draws one slot through
:func:`sample_masked`. An agent stops when it reaches the goal, when it has no admissible
neighbour ("stuck"), or when the step budget runs out. The walk is a ``lax.while_loop`` that ends
as soon as every agent has stopped.

Memory: the visited sets are bit sets ``u32[A, ceil(N / 32)]``, the paths ``i32[A, L]`` and the chosen slots
``i16[A, L - 1]`` with ``L = max_steps + 1``; batch sizes in sweeps must be chosen with that in mind.
"""
from __future__ import annotations

from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.graph import NO_NODE, Graph

FORCED = 1e30
"""A log-weight that wins every draw: use it for moves that must be taken (e.g. into the goal)."""


class Walk(NamedTuple):
    """What a walk produced (a pytree).

    Attributes:
      path: i32[A, L] nodes visited, starting with the start node, -1 padded.
      slots: i16[A, L - 1] neighbour slot of each move (``path[a, t + 1] = nbr[path[a, t], slot]``),
        -1 after the agent stopped.
      length: f32[A] walked length (sum of edge costs).
      arrived: bool[A] reached the goal.
      stuck: bool[A] stopped with no admissible neighbour (before arriving).
      position: i32[A] the node each agent stopped at.
      steps: i32[] number of lockstep steps taken (the slowest agent's move count).
    """

    path: jax.Array
    slots: jax.Array
    length: jax.Array
    arrived: jax.Array
    stuck: jax.Array
    position: jax.Array
    steps: jax.Array


LogWeights = Callable[[jax.Array, jax.Array, jax.Array, jax.Array], jax.Array]
"""``log_weights(position i32[A], neighbours i32[A, K], edge_cost f32[A, K], admissible bool[A, K])
-> f32[A, K]``: unnormalised log-probabilities of each slot (only admissible slots matter)."""


def sample_masked(key: jax.Array, log_weights: jax.Array, mask: jax.Array):
    """Draw one slot per row among the masked-in slots, by inverse CDF (one uniform per row).

    Args:
      key: PRNG key.
      log_weights: f32[A, K] unnormalised log-probabilities; ``-inf`` means probability 0 and
        ``FORCED`` makes a slot certain.
      mask: bool[A, K] slots that may be chosen.

    Returns:
      ``(choice i32[A], has_choice bool[A])``. Rows with no admissible slot of positive weight get
      ``has_choice = False`` and ``choice = -1``; they must not move (``jax.random.categorical``
      would silently return slot 0 there).
    """
    masked = jnp.where(mask, log_weights, -jnp.inf)
    top = jnp.max(masked, axis=-1, keepdims=True)
    has_choice = jnp.isfinite(top[..., 0])  # False for no slot, all -inf, or NaN weights
    weights = jnp.exp(masked - jnp.where(has_choice[..., None], top, 0.0))
    cdf = _cumsum_last(weights)
    total = cdf[..., -1:]
    u = jax.random.uniform(key, has_choice.shape)[..., None] * total
    # The first slot whose cumulative weight exceeds u (a slot of positive weight), capped at the
    # last slot of positive weight in case rounding made u reach the total. Counting is cheaper
    # than argmax (a variadic reduce) on CPU.
    choice = jnp.minimum(jnp.sum(cdf <= u, axis=-1), jnp.sum(cdf < total, axis=-1))
    return jnp.where(has_choice, choice, NO_NODE).astype(jnp.int32), has_choice


def _mark(bits: jax.Array, agents: jax.Array, nodes: jax.Array) -> jax.Array:
    """Set bit ``nodes[a]`` in row ``agents[a]`` of a packed u32[A, ceil(N / 32)] bit set."""
    words = nodes >> 5
    updated = bits[agents, words] | (jnp.uint32(1) << (nodes & 31).astype(jnp.uint32))
    return bits.at[agents, words].set(updated)


def _is_marked(bits: jax.Array, nodes: jax.Array) -> jax.Array:
    """bool[A, K]: whether node ``nodes[a, k]`` is in agent ``a``'s packed bit set."""
    words = jnp.take_along_axis(bits, nodes >> 5, axis=1)
    return ((words >> (nodes & 31).astype(jnp.uint32)) & 1).astype(bool)


def _cumsum_last(x: jax.Array) -> jax.Array:
    """Cumulative sum over the (small, static) last axis, unrolled: XLA's cumsum lowers to a
    reduce-window that is about twice as slow on CPU for K = 8."""
    columns = [x[..., 0]]
    for k in range(1, x.shape[-1]):
        columns.append(columns[-1] + x[..., k])
    return jnp.stack(columns, axis=-1)


def walk(key: jax.Array, graph: Graph, valid_edges: jax.Array, start, goal,
         log_weights: LogWeights, *, num_agents: int, max_steps: int) -> Walk:
    """Walk ``num_agents`` agents from ``start`` towards ``goal`` in lockstep.

    Args:
      key: PRNG key (one split per step; the same key gives the same walk).
      graph: the map.
      valid_edges: bool[N, K] ``graph.valid_edges()``, computed once by the caller.
      start, goal: i32[] node indices (may be traced).
      log_weights: the algorithm's transition rule (see ``LogWeights``).
      num_agents: A (static).
      max_steps: the step budget (static); paths hold ``max_steps + 1`` nodes.

    Returns:
      A :class:`Walk`.
    """
    n = graph.num_nodes
    agents = jnp.arange(num_agents)
    start = jnp.asarray(start, jnp.int32)
    goal = jnp.asarray(goal, jnp.int32)
    position = jnp.full((num_agents,), start)
    path = jnp.full((num_agents, max_steps + 1), NO_NODE, jnp.int32).at[:, 0].set(start)
    carry = dict(
        key=key,
        position=position,
        visited=_mark(jnp.zeros((num_agents, (n + 31) // 32), jnp.uint32), agents, position),
        path=path,
        slots=jnp.full((num_agents, max_steps), -1, jnp.int16),
        length=jnp.zeros((num_agents,), jnp.float32),
        walking=jnp.full((num_agents,), start != goal),
        arrived=jnp.full((num_agents,), start == goal),
        stuck=jnp.zeros((num_agents,), bool),
        step=jnp.array(0, jnp.int32),
    )

    def keep_walking(c):
        return (c["step"] < max_steps) & jnp.any(c["walking"])

    def one_step(c):
        key, draw_key = jax.random.split(c["key"])
        here = c["position"]
        neighbours = graph.nbr[here]
        safe = jnp.where(neighbours >= 0, neighbours, 0)
        edge_cost = graph.cost[here]
        seen = _is_marked(c["visited"], safe)
        admissible = valid_edges[here] & ~seen & c["walking"][:, None]
        choice, has_choice = sample_masked(
            draw_key, log_weights(here, neighbours, edge_cost, admissible), admissible)
        moving = c["walking"] & has_choice
        slot = jnp.maximum(choice, 0)[:, None]
        target = jnp.take_along_axis(neighbours, slot, axis=1)[:, 0]
        there = jnp.where(moving, target, here)
        arrived_now = moving & (there == goal)
        step = c["step"]
        return dict(
            key=key,
            position=there,
            visited=_mark(c["visited"], agents, there),
            path=c["path"].at[:, step + 1].set(jnp.where(moving, there, NO_NODE)),
            slots=c["slots"].at[:, step].set(jnp.where(moving, choice, -1).astype(jnp.int16)),
            length=c["length"] + jnp.where(moving, jnp.take_along_axis(edge_cost, slot, 1)[:, 0], 0.0),
            walking=moving & ~arrived_now,
            arrived=c["arrived"] | arrived_now,
            stuck=c["stuck"] | (c["walking"] & ~has_choice),
            step=step + 1,
        )

    c = jax.lax.while_loop(keep_walking, one_step, carry)
    return Walk(path=c["path"], slots=c["slots"], length=c["length"], arrived=c["arrived"],
                stuck=c["stuck"], position=c["position"], steps=c["step"])
