"""The compiled search loops of the exact planners (numba, nopython, cached on disk).

numba because a priority-queue search is a scalar loop with data-dependent branches: XLA has no
fast form of it, and a pure-Python heap spends most of its time in the interpreter (measured:
``docs/performance.md``). The loops are written over plain arrays
(:class:`~jaxswarm.world.edges.EdgeArrays`, a :class:`~jaxswarm.exact.search.Workspace`), so a
batch of queries reuses its buffers and pays no Python per node.

The indexed binary heap orders entries by ``(f, -g, node)`` exactly as the readable heapq planners
of :mod:`jaxswarm.exact.reference` do (ties on f towards the larger g, then the smaller node), and
moves a queued node whose cost improves instead of leaving a stale entry behind. Keys are
distinct, so both expand the same nodes in the same order: the same paths, expansions and
relaxations (the heapq planners also pop the stale entries they leave).
"""
from __future__ import annotations

import math

import numba
import numpy as np

ZERO, EUCLIDEAN, OCTILE = 0, 1, 2
"""Heuristic codes of the kernels (by name: :func:`jaxswarm.exact.host.heuristic_code`)."""

DIAGONAL_EXTRA = math.sqrt(2.0) - 1.0

jit = numba.njit(cache=True, nogil=True, error_model="numpy")
inline = numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")


@inline
def heuristic(kind, x, y, v, tx, ty):
    """Lower bound on the distance from node ``v`` to the point ``(tx, ty)``."""
    if kind == ZERO:
        return 0.0
    dx = abs(x[v] - tx)
    dy = abs(y[v] - ty)
    if kind == OCTILE:
        return dx + DIAGONAL_EXTRA * dy if dx > dy else dy + DIAGONAL_EXTRA * dx
    return math.sqrt(dx * dx + dy * dy)


@inline
def _before(f1, h1, n1, f2, h2, n2):
    """Whether entry ``(f1, h1, n1)`` orders before ``(f2, h2, n2)`` (lexicographically).
    Bitwise, not short-circuit: no branches to mispredict."""
    return (f1 < f2) | ((f1 == f2) & ((h1 < h2) | ((h1 == h2) & (n1 < n2))))


@inline
def _place(heap, position, i, first, second, node):
    heap[i, 0], heap[i, 1], heap[i, 2] = first, second, node
    position[node] = i


@inline
def _sift_up(heap, position, i, first, second, node):
    while i > 0:  # move the hole up past every parent that orders after the entry
        up = (i - 1) >> 1
        if not _before(first, second, node, heap[up, 0], heap[up, 1], heap[up, 2]):
            break
        _place(heap, position, i, heap[up, 0], heap[up, 1], np.int64(heap[up, 2]))
        i = up
    _place(heap, position, i, first, second, node)


@inline
def _sift_down(heap, position, size, i, first, second, node):
    while True:  # move the hole down past every child that orders before the entry
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and _before(heap[child + 1, 0], heap[child + 1, 1],
                                        heap[child + 1, 2], heap[child, 0], heap[child, 1],
                                        heap[child, 2]):
            child += 1
        if not _before(heap[child, 0], heap[child, 1], heap[child, 2], first, second, node):
            break
        _place(heap, position, i, heap[child, 0], heap[child, 1], np.int64(heap[child, 2]))
        i = child
    _place(heap, position, i, first, second, node)


@inline
def _resift(heap, position, size, i, first, second, node):
    """Put the entry into row ``i`` (whose entry it replaces) and move it up or down from there."""
    if _before(first, second, node, heap[i, 0], heap[i, 1], heap[i, 2]):
        _sift_up(heap, position, i, first, second, node)
    else:
        _sift_down(heap, position, size, i, first, second, node)


@inline
def heap_set(heap, position, size, queued, node, first, second):
    """Queue ``node`` with key ``(first, second)``, or move it to that key if it is ``queued``
    already. The heap is the first ``size`` rows ``(first, second, node)`` of ``heap`` f64[C, 3];
    ``position`` i32[N] is each queued node's row. Returns the new size."""
    if not queued:
        _sift_up(heap, position, size, first, second, node)
        return size + 1
    _resift(heap, position, size, position[node], first, second, node)
    return size


@inline
def heap_remove(heap, position, size, node):
    """Take a queued ``node`` off the heap (its ``position`` becomes -1); returns the new size."""
    i = position[node]
    position[node] = -1
    size -= 1
    if i < size:  # the last row fills the gap
        _resift(heap, position, size, i, heap[size, 0], heap[size, 1], np.int64(heap[size, 2]))
    return size


@inline
def heap_pop(heap, position, size):
    """Take the first node off the heap: ``(new size, node)``."""
    node = np.int64(heap[0, 2])
    return heap_remove(heap, position, size, node), node


@inline
def _label(g, parent, seen, position, stamp, v, g_v, u):
    """Give ``v`` cost ``g_v`` through ``u``; returns whether it was queued before."""
    queued = seen[v] == stamp and position[v] >= 0
    if seen[v] != stamp:
        seen[v] = stamp
        position[v] = -1
    g[v] = g_v
    parent[v] = u
    return queued


@inline
def _known(g, seen, stamp, v):
    return g[v] if seen[v] == stamp else np.inf


@jit
def best_first(indptr, heads, lengths, x, y, source, target, kind, side, stamp):
    """A* (Dijkstra with ``kind`` ZERO) from ``source`` to ``target``.

    Args:
      indptr, heads, lengths: the graph's valid edges (CSR).
      x, y: f64[N] node coordinates (for the heuristic).
      kind: heuristic code.
      side: the search's buffers ``(g f64[N], parent i32[N], seen i32[N], heap f64[N + 1, 3],
        position i32[N])``: a label is valid where ``seen == stamp`` (a new stamp clears them
        all at once); the heap's rows are ``(f, -g, node)``, ``position`` a queued node's row.
      stamp: this search's stamp.

    Returns:
      ``(cost, iterations, expanded, generated)``; cost is inf when ``target`` is unreachable,
      and the path is then read back from ``parent``. A node whose cost improves while queued
      moves in the queue (no stale entries), so iterations (pops) are the expansions plus the
      goal's pop.
    """
    g, parent, seen, heap, position = side
    tx, ty = x[target], y[target]
    _label(g, parent, seen, position, stamp, source, 0.0, -1)
    size = heap_set(heap, position, 0, False, source, heuristic(kind, x, y, source, tx, ty),
                    -0.0)
    iterations, expanded, generated = 0, 0, 1
    while size > 0:
        size, u = heap_pop(heap, position, size)
        g_u = g[u]
        iterations += 1
        if u == target:
            return g_u, iterations, expanded, generated
        expanded += 1
        for e in range(indptr[u], indptr[u + 1]):
            w = lengths[e]
            v = heads[e]
            g_v = g_u + w
            if g_v < _known(g, seen, stamp, v):
                queued = _label(g, parent, seen, position, stamp, v, g_v, u)
                size = heap_set(heap, position, size, queued, v,
                                g_v + heuristic(kind, x, y, v, tx, ty), -g_v)
                generated += 1
    return np.inf, iterations, expanded, generated


@jit
def bidirectional(edges, back_edges, x, y, source, target, kind, forward, backward, stamp,
                  balanced):
    """Bidirectional A*: the forward search over ``edges = (indptr, heads, lengths)`` from
    ``source``, the backward one over the reversed edges ``back_edges = (rev_indptr, tails,
    lengths)`` from ``target``, until no unseen path can beat the best meeting cost ``mu``.
    ``forward`` and ``backward`` are buffers as :func:`best_first`'s ``side``.

    With ``balanced`` False (:func:`jaxswarm.exact.astar.bidirectional_astar`) each side is an A*
    towards the other's root (key ``g + h``), the sides pop in turn, and the search stops when
    either smallest key reaches ``mu``. With ``balanced`` True
    (:func:`jaxswarm.exact.astar.balanced_bidirectional_astar`) each side is keyed by ``g`` plus
    its :func:`potential`, the side with fewer queued nodes pops, the search stops when the two
    smallest keys sum to ``mu``, and a node whose ``g`` plus heuristic reaches ``mu`` is not
    queued.

    Returns:
      ``(mu, meet, iterations, expanded, generated)``; ``meet`` is -1 when no path was found.
    """
    if source == target:
        return 0.0, source, 0, 0, 1
    sx, sy, tx, ty = x[source], y[source], x[target], y[target]
    # Unpacked once: taking arrays out of a tuple in the loop costs reference counting.
    indptr, heads, lengths = edges
    back_indptr, tails, back_lengths = back_edges
    g, parent, seen, heap, position = forward
    back_g, back_parent, back_seen, back_heap, back_position = backward
    _label(g, parent, seen, position, stamp, source, 0.0, -1)
    _label(back_g, back_parent, back_seen, back_position, stamp, target, 0.0, -1)
    size = heap_set(heap, position, 0, False, source,
                    _key(kind, x, y, source, tx, ty, sx, sy, 0.0, balanced), -0.0)
    back_size = heap_set(back_heap, back_position, 0, False, target,
                         _key(kind, x, y, target, sx, sy, tx, ty, 0.0, balanced), -0.0)
    mu, meet = np.inf, -1
    iterations, generated = 0, 2
    forward_turn = True
    while size > 0 and back_size > 0:
        if balanced:
            if heap[0, 0] + back_heap[0, 0] >= mu:
                break  # no unseen path can beat mu
            forward_turn = size <= back_size
        elif heap[0, 0] >= mu or back_heap[0, 0] >= mu:
            break
        iterations += 1
        if forward_turn:
            size, mu, meet, grown = _expand(
                indptr, heads, lengths, x, y, tx, ty, sx, sy, kind, g, parent, seen, heap,
                position, back_g, back_seen, stamp, size, mu, meet, balanced)
        else:
            back_size, mu, meet, grown = _expand(
                back_indptr, tails, back_lengths, x, y, sx, sy, tx, ty, kind, back_g,
                back_parent, back_seen, back_heap, back_position, g, seen, stamp, back_size,
                mu, meet, balanced)
        forward_turn = not forward_turn
        generated += grown
    return mu, meet, iterations, iterations, generated


@inline
def potential(kind, x, y, v, tx, ty, rx, ry):
    """A search's key offset of node ``v`` when it runs from ``(rx, ry)`` towards ``(tx, ty)``:
    half the heuristic to its target minus half the heuristic to its root. The two directions'
    potentials sum to 0 and are consistent when the heuristic is, so each direction is Dijkstra
    over lengths reduced by them (Ikeda et al. 1994; Goldberg and Harrelson 2005)."""
    return 0.5 * (heuristic(kind, x, y, v, tx, ty) - heuristic(kind, x, y, v, rx, ry))


@inline
def _key(kind, x, y, v, tx, ty, rx, ry, g_v, balanced):
    """A bidirectional side's key of node ``v`` at cost ``g_v``."""
    if balanced:
        return g_v + potential(kind, x, y, v, tx, ty, rx, ry)
    return g_v + heuristic(kind, x, y, v, tx, ty)


@inline
def _expand(indptr, ends, lengths, x, y, tx, ty, rx, ry, kind, g, parent, seen, heap, position,
            other_g, other_seen, stamp, size, mu, meet, balanced):
    """Pop and expand one node of a bidirectional search's side, running from ``(rx, ry)``
    towards ``(tx, ty)``: ``(size, mu, meet, generated)``."""
    size, u = heap_pop(heap, position, size)
    g_u = g[u]
    generated = 0
    for e in range(indptr[u], indptr[u + 1]):
        w = lengths[e]
        v = ends[e]
        g_v = g_u + w
        if g_v < _known(g, seen, stamp, v):
            queued = _label(g, parent, seen, position, stamp, v, g_v, u)
            through = g_v + _known(other_g, other_seen, stamp, v)
            if through < mu:
                mu, meet = through, v
            if balanced and g_v + heuristic(kind, x, y, v, tx, ty) >= mu:
                if queued:  # no better path runs through v
                    size = heap_remove(heap, position, size, v)
                continue
            size = heap_set(heap, position, size, queued, v,
                            _key(kind, x, y, v, tx, ty, rx, ry, g_v, balanced), -g_v)
            generated += 1
    return size, mu, meet, generated


@jit
def walk_back(parent, node, out):
    """Write the nodes from ``node`` back to its root (parent -1) into ``out``; returns how
    many."""
    count = 0
    while node != -1:
        out[count] = node
        count += 1
        node = parent[node]
    return count


@jit
def many(indptr, heads, lengths, x, y, sources, targets, kind, side, first_stamp, cost, counts):
    """:func:`best_first` for every (``sources[q]``, ``targets[q]``): ``cost[q]`` and
    ``counts[q] = (iterations, expanded, generated)``, stamps ``first_stamp + q``."""
    for q in range(sources.shape[0]):
        result = best_first(indptr, heads, lengths, x, y, sources[q], targets[q], kind, side,
                            first_stamp + q)
        cost[q] = result[0]
        counts[q, 0] = result[1]
        counts[q, 1] = result[2]
        counts[q, 2] = result[3]
