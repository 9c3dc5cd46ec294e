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
smooths a batch's distinct paths only, :data:`ROWS` at a time (under ``vmap`` a ``while_loop``
runs until its slowest path), on the first ``W`` positions of the paths (the smallest of
:func:`~.memory.widths` that holds them all: past a path's end every position is padding,
where a pass finds nothing to replace). On grids and path maps a move's edge is found from
the cells' coordinates and the slots' fixed directions (:func:`lattice_measure`) instead of a
search of the node's slots.
"""
from __future__ import annotations

import functools
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.iwd.memory import width_index, widths
from jaxswarm.world.graph import NO_NODE, Graph
from jaxswarm.world.lattice import DIRECTIONS, slot_lengths

IMPROVEMENT = 1e-4
"""How much shorter (in length units) a replacement must be: float rounding is no improvement."""

ROWS = 8
"""Distinct paths smoothed together (one ``vmap`` of the passes' ``while_loop``)."""


class Measure(NamedTuple):
    """How a pass measures moves on one map (both functions give inf where there is no valid
    edge, and take ``-1`` nodes).

    Attributes:
      edge: ``(here i32[...], there i32[...]) -> f32[...]`` the length of the valid edge.
      middles: ``(path i32[W], on_path bool[N]) -> (middle i32[W, K], first f32[W, K])`` each
        position's neighbours through its slots (some node where a slot has none) and the
        length of the valid edge to each one that is not on the path (else inf).
      seconds: ``(path i32[W], middle i32[W, K], end i32[W]) -> f32[W, K]`` the length of the
        valid edge from each middle node to the position's ``end``.
    """

    edge: Callable
    middles: Callable
    seconds: Callable


def edge_cost(graph: Graph, valid: jax.Array, here: jax.Array, there: jax.Array) -> jax.Array:
    """f32[...] the length of the valid edge ``here -> there`` (i32[...], -1 allowed); inf where
    there is none (``valid`` bool[N, K] the map's valid edges)."""
    row = jnp.maximum(here, 0)
    hit = ((graph.nbr[row] == there[..., None]) & valid[row] & (here >= 0)[..., None]
           & (there >= 0)[..., None])
    return jnp.min(jnp.where(hit, graph.cost[row], jnp.inf), axis=-1)


def graph_measure(graph: Graph) -> Measure:
    """The :class:`Measure` of any graph: a move's edge searched among the node's slots."""
    valid = graph.valid_edges()

    def middles(path, on_path):
        row = jnp.maximum(path, 0)
        middle = graph.nbr[row]
        first = jnp.where(valid[row] & ~on_path[jnp.maximum(middle, 0)], graph.cost[row],
                          jnp.inf)
        return middle, first

    def seconds(path, middle, end):
        return edge_cost(graph, valid, middle, jnp.broadcast_to(end[:, None], middle.shape))

    return Measure(edge=functools.partial(edge_cost, graph, valid), middles=middles,
                   seconds=seconds)


def lattice_measure(graph: Graph) -> Measure:
    """The :class:`Measure` of a grid or path map, the same lengths as :func:`graph_measure`'s:
    there the valid edge ``a -> b`` is the slot whose direction is ``b``'s cell minus ``a``'s
    (a valid slot has its lattice neighbour, node ``a`` plus the slot's offset), of the slot's
    length (``cost`` wherever a slot has a neighbour)."""
    width, num_slots = graph.shape[1], graph.max_degree
    directions = DIRECTIONS[:num_slots]
    slot_of = np.full(9, -1, np.int32)  # the slot of each (dx, dy) in [-1, 1]^2
    slot_of[(directions[:, 1] + 1) * 3 + directions[:, 0] + 1] = np.arange(num_slots)
    lengths = slot_lengths(graph)
    valid = graph.valid_edges()
    bits = jnp.sum(valid.astype(jnp.int32) << jnp.arange(num_slots, dtype=jnp.int32), axis=1)

    def step_length(a, dx, dy):
        """The length of the valid move of cell offset (dx, dy) out of node ``a`` (>= 0)."""
        near = (jnp.abs(dx) <= 1) & (jnp.abs(dy) <= 1)
        slot = jnp.asarray(slot_of)[jnp.where(near, (dy + 1) * 3 + dx + 1, 4)]
        open_slot = (bits[a] >> jnp.maximum(slot, 0)) & 1
        return jnp.where((slot >= 0) & (open_slot == 1),
                         jnp.asarray(lengths)[jnp.maximum(slot, 0)], jnp.inf)

    def edge(here, there):
        a, b = jnp.maximum(here, 0), jnp.maximum(there, 0)
        length = step_length(a, b % width - a % width, b // width - a // width)
        return jnp.where((here >= 0) & (there >= 0), length, jnp.inf)

    def middles(path, on_path):
        row = jnp.maximum(path, 0)
        offsets = jnp.asarray(directions @ np.array([1, width], np.int32))
        middle = jnp.clip(row[:, None] + offsets, 0, graph.num_nodes - 1)
        open_slot = (bits[row][:, None] >> jnp.arange(num_slots, dtype=jnp.int32)) & 1
        return middle, jnp.where((open_slot == 1) & ~on_path[middle], jnp.asarray(lengths),
                                 jnp.inf)

    def seconds(path, middle, end):
        a, b = jnp.maximum(path, 0), jnp.maximum(end, 0)
        dx = (b % width - a % width)[:, None] - jnp.asarray(directions[:, 0])
        dy = (b // width - a // width)[:, None] - jnp.asarray(directions[:, 1])
        length = step_length(middle, dx, dy)
        return jnp.where(((path >= 0) & (end >= 0))[:, None], length, jnp.inf)

    return Measure(edge=edge, middles=middles, seconds=seconds)


def measure_of(graph: Graph) -> Measure:
    """The :class:`Measure` a pass uses on ``graph``: :func:`lattice_measure` on grids and path
    maps, :func:`graph_measure` on other graphs."""
    return lattice_measure(graph) if graph.is_grid else graph_measure(graph)


def _shifted(path: jax.Array, by: int) -> jax.Array:
    """i32[L]: ``path[t + by]`` at ``t`` (``NO_NODE`` past the end)."""
    return jnp.concatenate([path[by:], jnp.full((by,), NO_NODE, path.dtype)])


def _compact(path: jax.Array, keep: jax.Array) -> jax.Array:
    """i32[L]: the nodes of ``path`` where ``keep``, moved to the front, -1 padded."""
    position = jnp.where(keep, jnp.cumsum(keep) - 1, path.shape[0])
    return jnp.full_like(path, NO_NODE).at[position].set(path, mode="drop")


def _smooth_pass(num_nodes: int, measure: Measure, path: jax.Array):
    """One pass over ``path`` (i32[L]) of a map of ``num_nodes`` nodes: ``(path, changed
    bool[])``."""
    ahead = [path] + [_shifted(path, by) for by in (1, 2, 3)]
    move = [measure.edge(ahead[i], ahead[i + 1]) for i in range(3)]
    window = {2: move[0] + move[1], 3: move[0] + move[1] + move[2]}  # inf past the end
    n = num_nodes
    on_path = jnp.zeros((n + 1,), bool).at[jnp.where(path >= 0, path, n)].set(True)[:n]
    # Through one middle node m: a -> m -> end, m a valid neighbour of a not on the path.
    middle, first_leg = measure.middles(path, on_path)  # [L, K]
    direct, via, via_node = {}, {}, {}
    for w in (2, 3):
        direct[w] = measure.edge(path, ahead[w])
        legs = first_leg + measure.seconds(path, middle, ahead[w])
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


def _passes(num_nodes: int, measure: Measure, path: jax.Array) -> jax.Array:
    """i32[L]: ``path`` after passes until one changes nothing."""
    def one_pass(carry):
        return _smooth_pass(num_nodes, measure, carry[0])

    return jax.lax.while_loop(lambda carry: carry[1], one_pass, (path, jnp.array(True)))[0]


def smooth_path(graph: Graph, path: jax.Array) -> jax.Array:
    """i32[L]: ``path`` (i32[L], -1 padded, a walk on the current map) after the global smooth
    operator (module docstring), repeated until nothing changes. A path of fewer than three
    nodes, or padding, comes back as it was."""
    return _passes(graph.num_nodes, measure_of(graph), path)


def smooth_paths(graph: Graph, paths: jax.Array, which: jax.Array) -> jax.Array:
    """i32[A, L]: each path of ``paths`` (i32[A, L], -1 padded, walks on the current map) where
    ``which`` (bool[A]) after the global smooth operator (:func:`smooth_path`), the others as
    they were; worked on the smallest of :func:`~.memory.widths` that holds every path of
    ``which``."""
    length = paths.shape[1]
    measure = measure_of(graph)

    def within(width):
        def smooth(paths):
            smoothed = _smooth_distinct(graph.num_nodes, measure, paths[:, :width], which)
            return jnp.pad(smoothed, ((0, 0), (0, length - width)), constant_values=NO_NODE)
        return smooth

    smoothed = jax.lax.switch(width_index(jnp.where(which[:, None], paths, NO_NODE)),
                              [within(width) for width in widths(length)], paths)
    return jnp.where(which[:, None], smoothed, paths)


def _smooth_distinct(num_nodes: int, measure: Measure, paths: jax.Array, which: jax.Array):
    """i32[A, W]: the paths (i32[A, W]) where ``which`` (bool[A]) smoothed, each distinct one
    once, :data:`ROWS` at a time (rows of a batch not in ``which`` as they were)."""
    count = paths.shape[0]
    rows = jnp.arange(count)
    same = jnp.all(paths[:, None, :] == paths[None, :, :], axis=-1) & which[None, :]
    first = jnp.argmax(same, axis=1)  # the first row of ``which`` with the same path
    distinct = which & (first == rows)
    batches = -(-count // ROWS)
    order = jnp.nonzero(distinct, size=batches * ROWS, fill_value=count)[0]

    def batch(b, done):
        chosen = jax.lax.dynamic_slice(order, (b * ROWS,), (ROWS,))
        batch_paths = jnp.where((chosen < count)[:, None], paths[jnp.minimum(chosen, count - 1)],
                                NO_NODE)
        smoothed = jax.vmap(functools.partial(_passes, num_nodes, measure))(batch_paths)
        return done.at[chosen].set(smoothed, mode="drop")

    done = jax.lax.fori_loop(0, -(-jnp.sum(distinct) // ROWS), batch, paths)
    return jnp.where(which[:, None], done[first], paths)
