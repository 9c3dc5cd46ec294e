"""Dijkstra's algorithm (best-first search by path cost, stopping when the goal is settled)."""
from __future__ import annotations

from jaxswarm.exact.search import best_first_search
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import Solution, path_length


def dijkstra(graph: Graph, start, goal, *, max_len: int | None = None) -> Solution:
    """Shortest path by Dijkstra's algorithm.

    Args:
      graph: the map (its current ``free``/``open`` state is used).
      start: (x, y) cell, or node index.
      goal: (x, y) cell, or node index.
      max_len: length L of the padded path buffer (default N, the most a simple path can need).

    Returns:
      Solution with path i32[L] (-1 padded), cost f64[] (inf if unreachable), found bool[] and
      ``stats`` (:class:`~jaxswarm.exact.stats.SearchStats`). An unreachable goal gives
      ``found=False``.

    Raises:
      ValueError: start or goal off the map or blocked.
    """
    return best_first_search(graph, start, goal, heuristic="zero", max_len=max_len)


def optimal_length(graph: Graph, start, goal) -> float:
    """The optimum as the swarms measure their paths: Dijkstra's shortest path, its length
    summed in float32 by :func:`jaxswarm.world.paths.path_length` (moves counted by kind on grids
    and path maps). A swarm path is never shorter, so a gap to it is never negative; inf where the
    goal cannot be reached.

    Raises:
      ValueError: start or goal off the map or blocked.
    """
    solution = dijkstra(graph, start, goal)
    return float(path_length(graph, solution.path)) if solution.found else float("inf")
