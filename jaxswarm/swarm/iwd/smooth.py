"""The global smooth operator of IWD_PG: runs of moves replaced by shorter ones on the map.

The paper's Figure 2 (the patterns replaced) did not survive the text; its words are "check
sequential moves and replace them with better moves": a detour of two moves where one diagonal
or straight move does. Ours, on any graph: a window of two or three consecutive moves ``p[t] ->
... -> p[t + w]`` is replaced by the shortest connection of at most two moves between its ends
(the direct edge, or through one middle node not already on the path) when that is strictly
shorter. Every move of a replacement is a valid edge of the current map, so a smoothed path
never crosses an obstacle, a closed passage or a cut corner. Passes repeat until nothing
changes; each pass applies every direct shortcut whose window does not overlap an earlier
candidate's, and the first replacement through a middle node (one per pass, so no two passes'
middle nodes meet). A smoothed path is never longer, and stays simple when it was simple.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxswarm.world.graph import NO_NODE, Graph

IMPROVEMENT = 1e-4
"""How much shorter (in length units) a replacement must be: float rounding is no improvement."""


def _shifted(path: jax.Array, by: int) -> jax.Array:
    """i32[L]: ``path[t + by]`` at ``t`` (``NO_NODE`` past the end)."""
    return jnp.concatenate([path[by:], jnp.full((by,), NO_NODE, path.dtype)])


def edge_cost(graph: Graph, valid: jax.Array, here: jax.Array, there: jax.Array) -> jax.Array:
    """f32[...] the length of the valid edge ``here -> there`` (i32[...], -1 allowed); inf where
    there is none (``valid`` bool[N, K] the map's valid edges)."""
    row = jnp.maximum(here, 0)
    hit = ((graph.nbr[row] == there[..., None]) & valid[row] & (here >= 0)[..., None]
           & (there >= 0)[..., None])
    return jnp.min(jnp.where(hit, graph.cost[row], jnp.inf), axis=-1)


def _compact(path: jax.Array, keep: jax.Array) -> jax.Array:
    """i32[L]: the nodes of ``path`` where ``keep``, moved to the front, -1 padded."""
    position = jnp.where(keep, jnp.cumsum(keep) - 1, path.shape[0])
    return jnp.full_like(path, NO_NODE).at[position].set(path, mode="drop")


def _smooth_pass(graph: Graph, valid: jax.Array, path: jax.Array):
    """One pass over ``path`` (i32[L]): ``(path, changed bool[])``."""
    n = graph.num_nodes
    ahead = [path] + [_shifted(path, by) for by in (1, 2, 3)]
    move = [edge_cost(graph, valid, ahead[i], ahead[i + 1]) for i in range(3)]
    window = {2: move[0] + move[1], 3: move[0] + move[1] + move[2]}  # inf past the end
    on_path = jnp.zeros((n + 1,), bool).at[jnp.where(path >= 0, path, n)].set(True)[:n]
    # Through one middle node m: a -> m -> end, m a valid neighbour of a not on the path.
    middle = graph.nbr[jnp.maximum(path, 0)]  # [L, K]
    first_leg = jnp.where(valid[jnp.maximum(path, 0)] & ~on_path[jnp.maximum(middle, 0)],
                          graph.cost[jnp.maximum(path, 0)], jnp.inf)
    direct, via, via_node = {}, {}, {}
    for w in (2, 3):
        direct[w] = edge_cost(graph, valid, path, ahead[w])
        legs = first_leg + edge_cost(graph, valid, middle, jnp.broadcast_to(
            ahead[w][:, None], middle.shape))
        via[w] = jnp.min(legs, axis=-1)
        via_node[w] = jnp.take_along_axis(middle, jnp.argmin(legs, axis=-1)[:, None], 1)[:, 0]
    short = {w: direct[w] < window[w] - IMPROVEMENT for w in (2, 3)}
    # Direct shortcuts: a window is taken when no candidate starts one or two moves before it,
    # so the windows taken share at most an end node.
    candidate = short[2] | short[3]
    earlier = jnp.concatenate([jnp.zeros((1,), bool), candidate[:-1]]) | jnp.concatenate(
        [jnp.zeros((2,), bool), candidate[:-2]])
    taken = candidate & ~earlier
    width = jnp.where(short[2], 2, 3)
    positions = jnp.arange(path.shape[0])
    start = jnp.where(taken, positions, -1)
    # Each node's latest taken window start at or before it (windows do not overlap).
    latest = jax.lax.cummax(start)
    latest_width = width[jnp.maximum(latest, 0)]
    inside = (latest >= 0) & (positions > latest) & (positions < latest + latest_width)
    shortened = _compact(path, ~inside)
    # Otherwise the first window a middle node shortens.
    better = {w: via[w] < jnp.minimum(window[w], direct[w]) - IMPROVEMENT for w in (2, 3)}
    any_middle = better[2] | better[3]
    t = jnp.argmax(any_middle)
    w = jnp.where(better[2][t], 2, 3)
    m = jnp.where(better[2][t], via_node[2][t], via_node[3][t])
    rerouted = path.at[t + 1].set(m)
    rerouted = _compact(rerouted, ~((positions > t + 1) & (positions < t + w)))
    has_direct = jnp.any(taken)
    changed = has_direct | jnp.any(any_middle)
    return jnp.where(has_direct, shortened, jnp.where(changed, rerouted, path)), changed


def smooth_path(graph: Graph, path: jax.Array) -> jax.Array:
    """i32[L]: ``path`` (i32[L], -1 padded, a walk on the current map) after the global smooth
    operator (module docstring), repeated until nothing changes. A path of fewer than three
    nodes, or padding, comes back as it was."""
    valid = graph.valid_edges()

    def unfinished(carry):
        return carry[1]

    def one_pass(carry):
        return _smooth_pass(graph, valid, carry[0])

    return jax.lax.while_loop(unfinished, one_pass, (path, jnp.array(True)))[0]
