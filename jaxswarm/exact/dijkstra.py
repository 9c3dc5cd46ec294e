"""Dijkstra's algorithm (best-first search by path cost, stopping when the goal is settled)."""
from __future__ import annotations

from jaxswarm.exact.best_first import search
from jaxswarm.graph import Graph
from jaxswarm.paths import Solution


def dijkstra(graph: Graph, start, goal, *, max_len: int | None = None) -> Solution:
    """Shortest path by Dijkstra's algorithm.

    Args:
      graph: the map (its current ``free``/``open`` state is used).
      start: (x, y) cell, or node index.
      goal: (x, y) cell, or node index.
      max_len: length L of the padded path buffer (default N, the most a simple path can need).

    Returns:
      Solution with path i32[L] (-1 padded), cost f64[] (inf if unreachable), found bool[] and
      ``stats`` (:class:`SearchStats`). An unreachable goal gives ``found=False``.

    Raises:
      ValueError: start or goal off the map or blocked.
    """
    return search(graph, start, goal, heuristic_kind="zero", max_len=max_len)
