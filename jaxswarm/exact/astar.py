"""A* and bidirectional A* (front-to-end, with a proven-optimal stopping rule)."""
from __future__ import annotations

import heapq
import math
import time

from jaxswarm.exact._host import host_graph, heuristic as make_heuristic
from jaxswarm.exact.best_first import relax, search, walk_back
from jaxswarm.exact.stats import SearchStats, make_solution
from jaxswarm.graph import Graph
from jaxswarm.paths import Solution, as_node


def astar(graph: Graph, start, goal, *, heuristic: str | None = None,
          max_len: int | None = None) -> Solution:
    """Shortest path by A*.

    Args:
      graph: the map.
      start, goal: (x, y) cells or node indices.
      heuristic: "octile" (default on grids), "euclidean" (default on general graphs; admissible
        when edge lengths are at least the straight-line distance) or "zero" (Dijkstra).
      max_len: length L of the padded path buffer (default N).

    Returns:
      Solution with path i32[L], cost f64[], found bool[], stats (:class:`SearchStats`).

    Raises:
      ValueError: start or goal off the map or blocked; unknown heuristic.
    """
    return search(graph, start, goal, heuristic_kind=_default(graph, heuristic), max_len=max_len)


def bidirectional_astar(graph: Graph, start, goal, *, heuristic: str | None = None,
                        max_len: int | None = None) -> Solution:
    """Shortest path by bidirectional A*: a forward search from the start and a backward search
    (over reversed edges) from the goal, expanded alternately.

    Every time the two searches touch, the best start-goal cost through the meeting node updates
    ``mu``. The search stops when the smallest f on either queue is at least ``mu``: with an
    admissible heuristic every path not yet seen costs at least that much, so ``mu`` is proven
    optimal (meeting alone is not enough).

    Args and Returns: as :func:`astar`; ``stats`` counts both directions.
    """
    kind = _default(graph, heuristic)
    source = as_node(graph, start, name="start")
    target = as_node(graph, goal, name="goal")
    host = host_graph(graph)
    began = time.perf_counter()
    nodes, cost, counts = _bidirectional(host, source, target, kind)
    stats = SearchStats(*counts, wall_time=time.perf_counter() - began)
    return make_solution(nodes, cost, stats, max_len or graph.num_nodes)


def _default(graph: Graph, kind: str | None) -> str:
    if kind is None:
        return "octile" if graph.is_grid else "euclidean"
    return kind


def _bidirectional(host, source: int, target: int, kind: str):
    if source == target:
        return [source], 0.0, (0, 0, 1)
    # Per direction: heuristic, best g, parent, heap, adjacency.
    sides = [
        (make_heuristic(kind, host, target), {source: 0.0}, {source: -1}, [], host.succ),
        (make_heuristic(kind, host, source), {target: 0.0}, {target: -1}, [], host.pred),
    ]
    for (h, _, _, heap, _), root in zip(sides, (source, target)):
        heap.append((h(root), -0.0, root))
    mu, meet = math.inf, -1
    iterations, expanded, generated = 0, 0, 2
    turn = 0
    while sides[0][3] and sides[1][3]:
        if sides[0][3][0][0] >= mu or sides[1][3][0][0] >= mu:
            break  # no unseen path can beat mu
        h, g, parent, heap, edges = sides[turn]
        g_other = sides[1 - turn][1]
        _, neg_g, u = heapq.heappop(heap)
        iterations += 1
        turn = 1 - turn
        g_u = -neg_g
        if g_u > g[u]:
            continue
        expanded += 1
        improved = relax(u, g_u, edges[u], g, parent, heap, h)
        generated += len(improved)
        for v in improved:
            if v in g_other and g[v] + g_other[v] < mu:
                mu, meet = g[v] + g_other[v], v
    counts = (iterations, expanded, generated)
    if meet < 0:
        return None, math.inf, counts
    forward = walk_back(sides[0][2], meet)[::-1]
    backward = walk_back(sides[1][2], meet)[1:]
    return forward + backward, mu, counts
