"""Best-first search with a heap: the engine behind Dijkstra and A*.

Plain, instrumented Python over the cached host adjacency lists. Nodes popped with a larger cost
than their best known one are skipped (lazy deletion); a node whose cost improves after it was
expanded is pushed again (re-opening), so the search stays optimal with any admissible heuristic.
Ties on f are broken towards the larger g (deeper nodes first), which saves expansions on grids.
"""
from __future__ import annotations

import heapq
import math
import time

from jaxswarm.exact._host import HostGraph, heuristic, host_graph
from jaxswarm.exact.stats import SearchStats, make_solution
from jaxswarm.graph import Graph
from jaxswarm.paths import Solution, as_node


def search(graph: Graph, start, goal, *, heuristic_kind: str, max_len: int | None) -> Solution:
    """Resolve the endpoints, run :func:`best_first` and package a Solution (see astar)."""
    source = as_node(graph, start, name="start")
    target = as_node(graph, goal, name="goal")
    host = host_graph(graph)
    h = heuristic(heuristic_kind, host, target)
    began = time.perf_counter()
    nodes, cost, counts = best_first(host, source, target, h)
    stats = SearchStats(*counts, wall_time=time.perf_counter() - began)
    return make_solution(nodes, cost, stats, max_len or graph.num_nodes)


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
