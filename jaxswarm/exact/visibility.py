"""The exact planner of a plane: the shortest collision-free path over its visibility graph.

A shortest path among polygons bends only at their convex corners, so Dijkstra over the
visibility graph of the start, the goal and the rectangles' corners that no rectangle contains is
exact.
"""
from __future__ import annotations

import numpy as np

from jaxswarm.exact.dijkstra import dijkstra
from jaxswarm.world.graph import dense_graph
from jaxswarm.world.paths import trim
from jaxswarm.world.plane import Plane, check_point, segment_crosses, strictly_inside


def shortest_path(plane: Plane, start, goal) -> tuple[float, np.ndarray]:
    """Host-side: the shortest collision-free path from ``start`` to ``goal``.

    Dijkstra (:func:`jaxswarm.exact.dijkstra`) over the visibility graph whose nodes are the
    start, the goal and every rectangle corner that lies in the plane and in no rectangle, with
    an edge between two nodes when the segment joining them crosses no rectangle
    (:func:`jaxswarm.world.plane.crossings`). The length is summed in float64 from the waypoints.

    Args:
      plane: the plane.
      start, goal: ``(x, y)``.

    Returns:
      ``(length, waypoints)``: float (inf when no path exists) and f64[K, 2] from start to goal
      (empty when no path exists).

    Raises:
      ValueError: start or goal off the plane or inside a rectangle.
    """
    start = check_point(plane, start, name="start")
    goal = check_point(plane, goal, name="goal")
    if start == goal:
        return 0.0, np.asarray([start])
    boxes = plane.obstacles()
    real = np.ones(len(boxes), bool)
    corners = np.unique(boxes[:, [0, 1, 2, 1, 2, 3, 0, 3]].reshape(-1, 2), axis=0)
    corners = corners[~strictly_inside(np, boxes, real, corners).any(axis=-1)
                      & (corners >= 0).all(-1) & (corners <= np.asarray(plane.extent)).all(-1)]
    points = np.concatenate([np.asarray([start, goal]), corners])
    a, b = np.broadcast_arrays(points[:, None], points[None, :])
    blocked = segment_crosses(np, boxes, real, a, b).any(axis=-1)
    distance = np.linalg.norm(a - b, axis=-1)
    weights = np.where(~blocked & (distance > 0), distance, np.inf)
    solution = dijkstra(dense_graph(weights, points), 0, 1)
    if not bool(solution.found):
        return float("inf"), np.zeros((0, 2))
    waypoints = points[trim(solution.path)]
    return float(np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=-1))), waypoints
