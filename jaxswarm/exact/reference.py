"""The readable planners: Dijkstra, A* and bidirectional A* in plain Python with ``heapq``.

They are the test oracle of the compiled planners (:mod:`jaxswarm.exact.kernels`), which must
return the same paths and statistics, and the place to read the algorithms. Instrumented Python
over the cached host adjacency lists: nodes popped with a larger cost than their best known one
are skipped (lazy deletion); a node whose cost improves after it was expanded is pushed again
(re-opening), so the search stays optimal with any admissible heuristic. Ties on f are broken
towards the larger g (deeper nodes first), which saves expansions on grids.

    from jaxswarm.exact import reference
    reference.astar(graph, (0, 0), (9, 9)).stats  # as jaxswarm.exact.astar's
"""
from __future__ import annotations

import dataclasses
import heapq
import math
import time
from typing import Callable

from jaxswarm.exact.host import HostGraph, default_heuristic, host_graph
from jaxswarm.exact.host import heuristic as make_heuristic
from jaxswarm.exact.stats import SearchStats, make_solution
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import Solution, as_node


def dijkstra(graph: Graph, start, goal, *, max_len: int | None = None) -> Solution:
    """:func:`jaxswarm.exact.dijkstra` in plain Python."""
    return astar(graph, start, goal, heuristic="zero", max_len=max_len)


def astar(graph: Graph, start, goal, *, heuristic: str | None = None,
          max_len: int | None = None) -> Solution:
    """:func:`jaxswarm.exact.astar` in plain Python."""
    source, target, host = _endpoints(graph, start, goal)
    h = make_heuristic(default_heuristic(graph, heuristic), host, target)
    began = time.perf_counter()
    nodes, cost, counts = best_first(host, source, target, h)
    stats = SearchStats(*counts, wall_time=time.perf_counter() - began)
    return make_solution(nodes, cost, stats, max_len or graph.num_nodes)


def bidirectional_astar(graph: Graph, start, goal, *, heuristic: str | None = None,
                        max_len: int | None = None, balanced: bool = False) -> Solution:
    """:func:`jaxswarm.exact.bidirectional_astar` in plain Python (``balanced``:
    :func:`jaxswarm.exact.balanced_bidirectional_astar`)."""
    kind = default_heuristic(graph, heuristic)
    source, target, host = _endpoints(graph, start, goal)
    began = time.perf_counter()
    nodes, cost, counts = _bidirectional(host, source, target, kind, balanced)
    stats = SearchStats(*counts, wall_time=time.perf_counter() - began)
    return make_solution(nodes, cost, stats, max_len or graph.num_nodes)


def balanced_bidirectional_astar(graph: Graph, start, goal, *, heuristic: str | None = None,
                                 max_len: int | None = None) -> Solution:
    """:func:`jaxswarm.exact.balanced_bidirectional_astar` in plain Python."""
    return bidirectional_astar(graph, start, goal, heuristic=heuristic, max_len=max_len,
                               balanced=True)


def _endpoints(graph: Graph, start, goal):
    return (as_node(graph, start, name="start"), as_node(graph, goal, name="goal"),
            host_graph(graph))


def best_first(host: HostGraph, source: int, target: int, h):
    """Shortest path from ``source`` to ``target`` ordered by f = g + h.

    Returns:
      (nodes or None, cost, (iterations, expanded, generated)).
    """
    g = {source: 0.0}
    parent = {source: -1}
    heap = [(h(source), -0.0, source)]
    succ = host.succ
    iterations, expanded, generated = 0, 0, 1
    while heap:
        _, neg_g, u = heapq.heappop(heap)
        iterations += 1
        g_u = -neg_g
        if g_u > g[u]:
            continue  # stale entry: u was reached more cheaply since
        if u == target:
            return walk_back(parent, target)[::-1], g_u, (iterations, expanded, generated)
        expanded += 1
        generated += len(relax(u, g_u, succ[u], g, parent, heap, h))
    return None, math.inf, (iterations, expanded, generated)


def relax(u: int, g_u: float, edges: list, g: dict, parent: dict, heap: list, h) -> list[int]:
    """Expand ``u``: every edge (v, w) that improves g[v] updates g and parent and pushes v with
    priority (g + h, -g) (ties towards the larger g). Returns the improved nodes."""
    improved = []
    for v, w in edges:
        g_v = g_u + w
        if g_v < g.get(v, math.inf):
            g[v] = g_v
            parent[v] = u
            heapq.heappush(heap, (g_v + h(v), -g_v, v))
            improved.append(v)
    return improved


def walk_back(parent: dict, node: int) -> list[int]:
    """Nodes from ``node`` back to the root of a parent map (root has parent -1)."""
    nodes = []
    while node != -1:
        nodes.append(node)
        node = parent[node]
    return nodes


@dataclasses.dataclass
class _Direction:
    """One side of a bidirectional search: heuristics towards its target and its root, labels,
    heap (lazy deletion), the nodes it has queued (stale entries aside) and its adjacency."""

    to_target: Callable
    to_root: Callable
    g: dict
    parent: dict
    heap: list
    queued: set
    edges: list

    def key(self, v: int, g_v: float, balanced: bool) -> float:
        """``g + h`` towards the target, or (balanced) ``g`` plus the potential."""
        if balanced:
            return g_v + 0.5 * (self.to_target(v) - self.to_root(v))
        return g_v + self.to_target(v)

    def drop_stale_top(self) -> int:
        """Pop stale entries off the top; returns how many."""
        dropped = 0
        while self.heap and -self.heap[0][1] > self.g[self.heap[0][2]]:
            heapq.heappop(self.heap)
            dropped += 1
        return dropped


def _bidirectional(host, source: int, target: int, kind: str, balanced: bool):
    """Bidirectional A*, the report's (``balanced`` False) or the balanced variant, popping
    exactly what :func:`jaxswarm.exact.kernels.bidirectional` pops: stale entries are dropped
    before each step and do not take a turn."""
    if source == target:
        return [source], 0.0, (0, 0, 1)
    to_target = make_heuristic(kind, host, target)
    to_source = make_heuristic(kind, host, source)
    sides = [_Direction(to_target, to_source, {source: 0.0}, {source: -1}, [], {source},
                        host.succ),
             _Direction(to_source, to_target, {target: 0.0}, {target: -1}, [], {target},
                        host.pred)]
    for side, root in zip(sides, (source, target)):
        side.heap.append((side.key(root, 0.0, balanced), -0.0, root))
    mu, meet = math.inf, -1
    iterations, expanded, generated = 0, 0, 2
    forward_turn = True
    while sides[0].queued and sides[1].queued:
        iterations += sides[0].drop_stale_top() + sides[1].drop_stale_top()
        tops = sides[0].heap[0][0], sides[1].heap[0][0]
        if balanced:
            if tops[0] + tops[1] >= mu:
                break  # no unseen path can beat mu
            forward_turn = len(sides[0].queued) <= len(sides[1].queued)
        elif tops[0] >= mu or tops[1] >= mu:
            break
        side, other = sides if forward_turn else sides[::-1]
        forward_turn = not forward_turn
        _, neg_g, u = heapq.heappop(side.heap)
        iterations += 1
        expanded += 1
        side.queued.discard(u)
        g_u = -neg_g
        for v, w in side.edges[u]:
            g_v = g_u + w
            if g_v >= side.g.get(v, math.inf):
                continue
            side.g[v] = g_v
            side.parent[v] = u
            if g_v + other.g.get(v, math.inf) < mu:
                mu, meet = g_v + other.g[v], v
            if balanced and g_v + side.to_target(v) >= mu:
                side.queued.discard(v)  # no better path runs through v; its entry is stale now
                continue
            heapq.heappush(side.heap, (side.key(v, g_v, balanced), -g_v, v))
            side.queued.add(v)
            generated += 1
    counts = (iterations, expanded, generated)
    if meet < 0:
        return None, math.inf, counts
    forward = walk_back(sides[0].parent, meet)[::-1]
    backward = walk_back(sides[1].parent, meet)[1:]
    return forward + backward, mu, counts
