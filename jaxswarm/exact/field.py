"""Batched distance-to-goal field in JAX: the optimum inside vmapped sweeps.

``distance_field(graph, goal)[i]`` is the shortest-path distance from node ``i`` to ``goal`` over
the currently valid edges, computed by Bellman-Ford relaxation to a fixpoint in a
``lax.while_loop`` (each sweep relaxes every edge at once; at most N - 1 sweeps). It is pure and
shape-stable, so it jits once per map shape and vmaps over goals and over stacked maps.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxswarm.world.graph import Graph
from jaxswarm.world.relax import relax

SWEEPS_PER_CHECK = 4
"""Relaxation sweeps between two convergence tests (amortises the loop's overhead)."""


@jax.jit
def distance_field(graph: Graph, goal) -> jax.Array:
    """f32[N]: distance from every node to ``goal``; inf where the goal cannot be reached.

    Args:
      graph: the map (a batch of maps under vmap).
      goal: i32[] goal node index (traced; see :func:`jaxswarm.world.paths.node_index`). A blocked goal
        gives 0 at the goal and inf everywhere else.

    Returns:
      f32[N] distances; ``d[goal] == 0``.
    """
    n = graph.num_nodes
    lengths = jnp.where(graph.valid_edges(), graph.cost, jnp.inf)
    d0 = jnp.where(jnp.arange(n) == goal, 0.0, jnp.inf).astype(jnp.float32)

    def shorten(d, lowest):
        shorter = lowest < d
        return jnp.where(shorter, lowest, d), shorter

    return relax(graph, d0, lengths, shorten, max_sweeps=n,
                 sweeps_per_check=SWEEPS_PER_CHECK)[0]


@jax.jit
def optimum(graph: Graph, start, goal) -> jax.Array:
    """f32[]: shortest start-goal distance (inf if unreachable); start and goal are node indices."""
    return distance_field(graph, goal)[start]
