"""What algorithms hand the walker: a log-weight per edge, built from safe neighbour gathers and
the goal heuristic, and the walk's step budget."""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import slot_offsets, straight_line


def heads(graph: Graph) -> jax.Array:
    """i32[N, K]: each slot's neighbour, 0 where there is none (a safe gather index; mask the
    slot by ``graph.nbr >= 0`` or by an edge table's ``-inf``)."""
    return jnp.where(graph.nbr >= 0, graph.nbr, 0)


def neighbour_slots(graph: Graph, values: jax.Array) -> jax.Array:
    """[K, N]: ``values[nbr[i, k]]`` of an array ``values`` [N] (any dtype), slot-major, some
    value of the array where slot k has no neighbour (mask it as :func:`heads` says).

    On grids and path maps the slots are fixed offsets, so each row is a shifted slice of the
    padded array, not a gather. Elementwise tables built in this layout and transposed once at
    the end (``table.T``, f32[N, K] as the walker reads it) are several times faster on CPU than
    built in [N, K], where every slot's slice is interleaved with the others.
    """
    if not graph.is_grid:
        return values[heads(graph).T]
    offsets = [int(offset) for offset in slot_offsets(graph)]
    margin = max(abs(offset) for offset in offsets)
    padded = jnp.pad(values, (margin, margin), mode="edge")
    n = graph.num_nodes
    return jnp.stack([padded[margin + offset:margin + offset + n] for offset in offsets])


def goal_log_distance(graph: Graph, goal) -> jax.Array:
    """f32[N] ``log d_j``, the straight-line distance of each node to the goal (the goal
    heuristic of RFD* and ACO*); nodes at distance 0 other than the goal (general graphs without
    coordinates) get 0, a neutral heuristic, instead of ``log 0``."""
    to_goal = straight_line(graph, goal)
    return jnp.log(jnp.where(to_goal > 0, to_goal, 1.0))


def step_budget(graph: Graph, max_steps: int | None) -> int:
    """The step budget of a walk (static): ``max_steps``, or by default N - 1 (the longest walk
    without revisits) on general graphs and min(N - 1, 8 (H + W)) on grids."""
    if max_steps is not None:
        return max_steps
    longest = max(graph.num_nodes - 1, 1)
    return min(longest, 8 * sum(graph.shape)) if graph.is_grid else longest


def edge_table(graph: Graph, log_weights: jax.Array) -> jax.Array:
    """f32[N, K]: ``log_weights`` where the edge is valid on the current map, else ``-inf``.

    Algorithms build their per-edge log-weights (any finite values, ``FORCED`` for must-take
    moves, ``-inf`` to exclude) and pass them through this before
    :func:`~jaxswarm.swarm.walking.loop.walk`.
    """
    return jnp.where(graph.valid_edges(), log_weights, -jnp.inf)
