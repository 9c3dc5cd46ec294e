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

How it is computed (the result is the same function of each path): :func:`smooth_paths`
smooths a run's distinct paths only, one at a time (passes over several paths at once, in a
``vmap`` of the ``while_loop``, run until the slowest path and cost each path four to five times
as much), on the first ``W`` positions of the paths (the narrowest width
of :func:`~jaxswarm.swarm.walking.moves.on_moves` that holds them all in the batch: past a
path's end every position is padding, where a pass finds nothing to replace). On grids and
path maps a move's edge is found from the cells' coordinates and the slots' fixed directions
(:func:`lattice_costs`) instead of a search of the node's slots. On CPU the passes run natively by
default (:mod:`.native_smooth`: one kernel call smooths every selected path, bit for bit these
passes' paths); :func:`jaxswarm.swarm.walking.native.implementation` chooses, as for the walker.
"""
from __future__ import annotations

import functools
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.iwd.native_smooth import smooth_rows
from jaxswarm.swarm.walking import native, on_moves
from jaxswarm.world.graph import NO_NODE, Graph
from jaxswarm.world.lattice import DIRECTIONS, ORTHOGONAL_SLOTS, slot_lengths

IMPROVEMENT = 1e-4
"""How much shorter (in length units) a replacement must be: float rounding is no improvement."""

class Costs(NamedTuple):
    """The lengths a pass compares, at each position ``t`` of a path (i32[W]); inf where
    there is no valid edge (padding included).

    Attributes:
      moves: three f32[W]: the moves ``p[t + i] -> p[t + i + 1]``, i = 0, 1, 2.
      direct: ``{w: f32[W]}`` the edge ``p[t] -> p[t + w]``, w = 2, 3.
      legs: ``{w: f32[W, K]}`` ``p[t] -> m -> p[t + w]`` through each slot's neighbour ``m``
        of ``p[t]`` that is not on the path.
      middle: i32[W, K] those neighbours (some node where a slot has none).
    """

    moves: list
    direct: dict
    legs: dict
    middle: jax.Array


def edge_cost(graph: Graph, valid: jax.Array, here: jax.Array, there: jax.Array) -> jax.Array:
    """f32[...] the length of the valid edge ``here -> there`` (i32[...], -1 allowed); inf where
    there is none (``valid`` bool[N, K] the map's valid edges)."""
    row = jnp.maximum(here, 0)
    hit = ((graph.nbr[row] == there[..., None]) & valid[row] & (here >= 0)[..., None]
           & (there >= 0)[..., None])
    return jnp.min(jnp.where(hit, graph.cost[row], jnp.inf), axis=-1)


def graph_costs(graph: Graph) -> Callable:
    """``(path i32[W], on_path bool[N]) -> Costs`` on any graph: each edge searched among the
    node's slots."""
    valid = graph.valid_edges()

    def costs(path, on_path):
        ahead = [path] + [_shifted(path, by) for by in (1, 2, 3)]
        row = jnp.maximum(path, 0)
        middle = graph.nbr[row]
        first = jnp.where(valid[row] & ~on_path[jnp.maximum(middle, 0)], graph.cost[row],
                          jnp.inf)
        legs = {w: first + edge_cost(graph, valid, middle, jnp.broadcast_to(
            ahead[w][:, None], middle.shape)) for w in (2, 3)}
        return Costs(
            moves=[edge_cost(graph, valid, ahead[i], ahead[i + 1]) for i in range(3)],
            direct={w: edge_cost(graph, valid, path, ahead[w]) for w in (2, 3)},
            legs=legs, middle=middle)

    return costs


def lattice_costs(graph: Graph) -> Callable:
    """``(path i32[W], on_path bool[N]) -> Costs`` on a grid or path map, the same lengths as
    :func:`graph_costs`: there the valid edge ``a -> b`` is the slot whose direction is ``b``'s
    cell minus ``a``'s (a valid slot's neighbour is node ``a`` plus the slot's offset), of the
    slot's length (``cost`` wherever a slot has a neighbour). Each node's valid moves are a
    mask of bits, one per cell offset ``(dx, dy)`` in ``[-1, 1]^2`` (bit ``3 (dy + 1) + dx +
    1``), so a pass gathers only each position's mask and its neighbours' (a table made once),
    not each edge's slots."""
    width, num_slots = graph.shape[1], graph.max_degree
    directions = DIRECTIONS[:num_slots]
    offsets = directions @ np.array([1, width], np.int32)
    codes = (directions[:, 1] + 1) * 3 + directions[:, 0] + 1
    valid = graph.valid_edges()
    moves = jnp.sum(valid.astype(jnp.int32) << codes, axis=1)  # i32[N] the mask of each node
    neighbour = jnp.clip(jnp.arange(graph.num_nodes)[:, None] + offsets, 0, graph.num_nodes - 1)
    reach = jnp.where(valid, moves[neighbour], 0)  # i32[N, K] the mask of each neighbour
    lengths = slot_lengths(graph)
    # Odd bits are the orthogonal offsets, even ones the diagonal (slot_lengths: one length
    # each).
    straight, diagonal = lengths[0], lengths[min(ORTHOGONAL_SLOTS, num_slots - 1)]

    def step(dx, dy, mask):
        """The length of the move of cell offset (dx, dy) set in ``mask``, else inf."""
        code = jnp.clip((dy + 1) * 3 + dx + 1, 0, 8)
        near = (jnp.abs(dx) <= 1) & (jnp.abs(dy) <= 1) & (((mask >> code) & 1) == 1)
        return jnp.where(near, jnp.where(code % 2 == 1, straight, diagonal), jnp.inf)

    def costs(path, on_path):
        real = [_shifted(path, by) >= 0 if by else path >= 0 for by in range(4)]
        node = jnp.maximum(path, 0)
        x = [_shifted(node % width, by) for by in range(4)]
        y = [_shifted(node // width, by) for by in range(4)]
        mask = [_shifted(moves[node], by) for by in range(3)]

        def edge(i, j):
            return jnp.where(real[i] & real[j], step(x[j] - x[i], y[j] - y[i], mask[i]),
                             jnp.inf)

        middle = jnp.clip(node[:, None] + offsets, 0, graph.num_nodes - 1)
        first = jnp.where((((mask[0][:, None] >> codes) & 1) == 1) & ~on_path[middle], lengths,
                          jnp.inf)
        legs = {w: first + jnp.where((real[0] & real[w])[:, None], step(
            (x[w] - x[0])[:, None] - directions[:, 0], (y[w] - y[0])[:, None] - directions[:, 1],
            reach[node]), jnp.inf) for w in (2, 3)}
        return Costs(moves=[edge(i, i + 1) for i in range(3)],
                     direct={w: edge(0, w) for w in (2, 3)}, legs=legs, middle=middle)

    return costs


def costs_of(graph: Graph) -> Callable:
    """The :class:`Costs` of a pass on ``graph``: :func:`lattice_costs` on grids and path maps,
    :func:`graph_costs` on other graphs."""
    return lattice_costs(graph) if graph.is_grid else graph_costs(graph)


def _shifted(path: jax.Array, by: int) -> jax.Array:
    """i32[L]: ``path[t + by]`` at ``t`` (``NO_NODE`` past the end)."""
    return jnp.concatenate([path[by:], jnp.full((by,), NO_NODE, path.dtype)])


def _compact(path: jax.Array, keep: jax.Array) -> jax.Array:
    """i32[L]: the nodes of ``path`` where ``keep``, moved to the front, -1 padded."""
    position = jnp.where(keep, jnp.cumsum(keep) - 1, path.shape[0])
    return jnp.full_like(path, NO_NODE).at[position].set(path, mode="drop")


def _smooth_pass(num_nodes: int, costs_at: Callable, path: jax.Array):
    """One pass over ``path`` (i32[L]) of a map of ``num_nodes`` nodes, its lengths from
    ``costs_at`` (:func:`costs_of`): ``(path, changed bool[])``."""
    n = num_nodes
    on_path = jnp.zeros((n + 1,), bool).at[jnp.where(path >= 0, path, n)].set(True)[:n]
    costs = costs_at(path, on_path)
    move, direct = costs.moves, costs.direct
    window = {2: move[0] + move[1], 3: move[0] + move[1] + move[2]}  # inf past the end
    # Through one middle node m: a -> m -> end, m a valid neighbour of a not on the path.
    via = {w: jnp.min(costs.legs[w], axis=-1) for w in (2, 3)}
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
    # The middle node of the shortest legs at t (the first slot among equals).
    via_node = {w: costs.middle[t, jnp.argmin(costs.legs[w][t])] for w in (2, 3)}
    m = jnp.where(better[2][t], via_node[2], via_node[3])
    rerouted = path.at[t + 1].set(m)
    # Through m, a window of three moves loses its node at t + 2: the rest moves up one.
    rerouted = jnp.where((w == 3) & (positions > t + 1), _shifted(rerouted, 1), rerouted)
    has_direct = jnp.any(taken)
    changed = has_direct | jnp.any(any_middle)
    return jnp.where(has_direct, shortened, jnp.where(changed, rerouted, path)), changed


def _passes(num_nodes: int, costs_at: Callable, path: jax.Array) -> jax.Array:
    """i32[L]: ``path`` after passes until one changes nothing."""
    def one_pass(carry):
        return _smooth_pass(num_nodes, costs_at, carry[0])

    return jax.lax.while_loop(lambda carry: carry[1], one_pass, (path, jnp.array(True)))[0]


def smooth_path(graph: Graph, path: jax.Array) -> jax.Array:
    """i32[L]: ``path`` (i32[L], -1 padded, a walk on the current map) after the global smooth
    operator (module docstring), repeated until nothing changes. A path of fewer than three
    nodes, or padding, comes back as it was."""
    return _passes(graph.num_nodes, costs_of(graph), path)


def smooth_paths(graph: Graph, paths: jax.Array, which: jax.Array,
                 implementation: str | None = None) -> jax.Array:
    """i32[A, L]: each path of ``paths`` (i32[A, L], -1 padded, walks on the current map) where
    ``which`` (bool[A]) after the global smooth operator (:func:`smooth_path`), the others as
    they were; worked on the narrowest width that holds every path of ``which`` in the batch
    (:func:`~jaxswarm.swarm.walking.moves.on_moves`).

    ``implementation`` (static): ``"lanes"`` (the XLA passes) or ``"native"`` (one kernel call,
    :func:`~.native_smooth.smooth_rows`; the same paths bit for bit); None: the walker's choice
    (:func:`jaxswarm.swarm.walking.native.implementation`, native on CPU), made when traced.
    """
    natively = native.implementation(requested=implementation) == "native"
    nodes = jnp.where(which, jnp.sum(paths >= 0, axis=1, dtype=jnp.int32), 0)
    smoothed = on_moves(functools.partial(_smooth_within, paths.shape[1], natively), nodes,
                        (paths,), which, graph)
    return jnp.where(which[:, None], smoothed, paths)


def _smooth_within(length: int, natively: bool, columns, which, graph: Graph) -> jax.Array:
    """i32[A, length]: the paths ``columns`` (one i32[A, W]) where ``which`` (bool[A]) smoothed,
    natively or by the XLA passes, -1 padded to ``length``."""
    (paths,) = columns
    if natively:
        smoothed = smooth_rows(graph, paths, which, IMPROVEMENT)
    else:
        smoothed = _smooth_distinct(graph.num_nodes, costs_of(graph), paths, which)
    return jnp.pad(smoothed, ((0, 0), (0, length - paths.shape[1])), constant_values=NO_NODE)


def _smooth_distinct(num_nodes: int, costs_at: Callable, paths: jax.Array, which: jax.Array):
    """i32[A, W]: the paths (i32[A, W]) where ``which`` (bool[A]) smoothed, each distinct one
    once and one at a time (rows of a batch not in ``which`` as they were)."""
    count = paths.shape[0]
    same = jnp.all(paths[:, None, :] == paths[None, :, :], axis=-1) & which[None, :]
    first = jnp.argmax(same, axis=1)  # the first row of ``which`` with the same path
    distinct = which & (first == jnp.arange(count))
    order = jnp.nonzero(distinct, size=count, fill_value=count)[0]

    def one(index, done):
        # Under ``vmap`` the loop runs to the batch's largest count: past a run's own, ``row``
        # is ``count``, read clamped and written nowhere.
        row = order[index]
        smoothed = _passes(num_nodes, costs_at, paths[jnp.minimum(row, count - 1)])
        return done.at[row].set(smoothed, mode="drop")

    done = jax.lax.fori_loop(0, jnp.sum(distinct), one, paths)
    return jnp.where(which[:, None], done[first], paths)
