"""Blind alleys: where a stuck drop's sediment goes when it fills the dead end it ran into."""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxswarm.swarm.walking import Walk
from jaxswarm.swarm.walking.log import columns
from jaxswarm.world.graph import Graph

STEPS_PER_CHECK = 8
"""Steps back along the trails per test of whether any drop is still filling."""


def blind_alleys(graph: Graph, log_weights, drops: Walk):
    """bool[N]: the blind alleys the stuck drops of a walk (``drops``, A agents) ran into, given
    the walk's transition table ``log_weights`` f32[N, K].

    For each stuck drop: the node where it stopped, and back along its trail every node from
    which each admissible move (finite ``log_weights``) leads either back to where the drop came
    from or into a node already filled; the first node with another way out, and the start, end
    the alley.
    """
    n = graph.num_nodes
    last = drops.log.moves  # index of the node where each drop stopped
    filled = jnp.zeros((n,), bool).at[jnp.where(drops.stuck, drops.position, n)].set(
        True, mode="drop")

    def any_filling(carry):
        return jnp.any(carry[1])

    def one_back(carry):
        back, filling, filled = carry
        index = jnp.maximum(last - back, 1)
        nodes, _ = columns(drops.log, jnp.stack([index, index - 1], axis=1))
        node, came_from = nodes[:, 0], nodes[:, 1]
        heads = graph.nbr[node]
        way_out = ((log_weights[node] > -jnp.inf) & (heads != came_from[:, None])
                   & ~filled[jnp.where(heads >= 0, heads, 0)])
        dead = filling & (last - back >= 1) & ~jnp.any(way_out, axis=1)
        return back + 1, dead, filled.at[jnp.where(dead, node, n)].set(True, mode="drop")

    def steps_back(carry):
        # Several steps per test of the loop's condition: under vmap (a sweep) the loop runs
        # until the longest alley of the batch is filled, and a drop done filling idles.
        return jax.lax.fori_loop(0, STEPS_PER_CHECK, lambda _, c: one_back(c), carry)

    _, _, filled = jax.lax.while_loop(any_filling, steps_back,
                                      (jnp.int32(1), drops.stuck, filled))
    return filled
