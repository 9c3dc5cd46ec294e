"""Continuous worlds: a rectangle of the plane with axis-aligned rectangular obstacles (the bees'
world, constrained ABC paper section III).

A :class:`Plane` is a pytree of fixed-shape arrays: ``R`` rectangles padded with a mask, and the
plane's extent ``[0, width] x [0, height]``. Planes of the same capacity ``R`` share compiled code
whatever their rectangles. Points are ``(x, y)`` floats.

The geometry conventions are used everywhere (the swarm, the exact optimum, the checks):

* A point **violates** a rectangle when it lies strictly inside it; the boundary is free, so a
  path may run along an obstacle's side or touch its corner (as the shortest path does).
* A segment **crosses** a rectangle when some point of it lies strictly inside. The test clips the
  segment to the closed rectangle and asks whether the clipped chord's midpoint is strictly inside:
  for a convex set the chord meets the interior exactly when its midpoint does.
* The optimum (:func:`shortest_path`) is the shortest collision-free path: Dijkstra over the
  visibility graph of the start, the goal and the rectangles' corners that no rectangle contains
  (a shortest path among polygons bends only at their convex corners).

The paper's maps #1 and #2 (its Figures 1 and 2) did not survive the text: :func:`paper_plane`
builds ours in their spirit (see :data:`PAPER_PLANES`).
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.exact.dijkstra import dijkstra
from jaxswarm.graph import dense_graph
from jaxswarm.paths import trim


@dataclasses.dataclass(frozen=True)
class Plane:
    """A plane of rectangular obstacles (a JAX pytree).

    Attributes:
      rectangles: f32[R, 4] ``(x_min, y_min, x_max, y_max)`` per obstacle; padding rows are zeros.
      mask: bool[R] which rows are obstacles.
      extent: f32[2] ``(width, height)``: the plane is ``[0, width] x [0, height]``.
    """

    rectangles: jax.Array
    mask: jax.Array
    extent: jax.Array

    @property
    def capacity(self) -> int:
        """R, the number of rectangle slots (the static shape)."""
        return self.rectangles.shape[0]

    def obstacles(self) -> np.ndarray:
        """Host-side: the real rectangles, f64[r, 4]."""
        return np.asarray(self.rectangles, np.float64)[np.asarray(self.mask)]


jax.tree_util.register_dataclass(Plane, data_fields=["rectangles", "mask", "extent"],
                                 meta_fields=[])


class PlaneMap(NamedTuple):
    """A plane with its query.

    Attributes:
      label: its name in tables (``map1``, ``random-s3``).
      plane: the :class:`Plane`.
      start, goal: ``(x, y)`` floats.
    """

    label: str
    plane: Plane
    start: tuple[float, float]
    goal: tuple[float, float]


def make_plane(rectangles, extent=(50.0, 50.0), *, capacity: int | None = None) -> Plane:
    """Host-side: a Plane from a list of rectangles, checked.

    Args:
      rectangles: ``(x_min, y_min, x_max, y_max)`` rows (f[r, 4]; an empty list is an empty plane).
      extent: ``(width, height)``, both positive.
      capacity: R, the rectangle slots (default r, at least 1); more slots than rectangles pad the
        plane so that planes with different numbers of rectangles share compiled code.

    Raises:
      ValueError: naming the rectangle that is empty, inverted or reaches outside the plane, or
        a capacity below the number of rectangles.
    """
    boxes = np.asarray(rectangles, np.float64).reshape(-1, 4)
    width, height = (float(v) for v in extent)
    if not (np.isfinite([width, height]).all() and width > 0 and height > 0):
        raise ValueError(f"extent must be two positive numbers, got {extent!r}")
    for i, (x0, y0, x1, y1) in enumerate(boxes):
        box = tuple(float(v) for v in boxes[i])
        if not np.isfinite(box).all() or not (x0 < x1 and y0 < y1):
            raise ValueError(f"rectangle {i} = {box}: needs x_min < x_max and y_min < y_max")
        if x0 < 0 or y0 < 0 or x1 > width or y1 > height:
            raise ValueError(f"rectangle {i} = {box} reaches outside the plane "
                             f"[0, {width:g}] x [0, {height:g}]")
    size = max(len(boxes), 1) if capacity is None else capacity
    if size < max(len(boxes), 1):
        raise ValueError(f"capacity {capacity} is less than the {len(boxes)} rectangles")
    padded = np.zeros((size, 4), np.float32)
    padded[:len(boxes)] = boxes
    mask = np.arange(size) < len(boxes)
    return Plane(rectangles=jnp.asarray(padded), mask=jnp.asarray(mask),
                 extent=jnp.asarray([width, height], jnp.float32))


def violations(plane: Plane, points: jax.Array) -> jax.Array:
    """i32[...]: how many rectangles contain each point strictly (eq. 6's violated constraints).

    Args:
      plane: the plane.
      points: f32[..., 2].
    """
    return jnp.sum(_strictly_inside(jnp, plane.rectangles, plane.mask, points), axis=-1,
                   dtype=jnp.int32)


def crossings(plane: Plane, a: jax.Array, b: jax.Array) -> jax.Array:
    """i32[...]: how many rectangles the segment from ``a`` to ``b`` passes through (f32[..., 2]
    each, broadcast together)."""
    a, b = jnp.broadcast_arrays(jnp.asarray(a, jnp.float32), jnp.asarray(b, jnp.float32))
    return jnp.sum(_crossed(jnp, plane.rectangles, plane.mask, a, b), axis=-1, dtype=jnp.int32)


def in_plane(plane: Plane, points: jax.Array) -> jax.Array:
    """bool[...]: whether points (f32[..., 2]) lie in ``[0, width] x [0, height]``."""
    return jnp.all((points >= 0) & (points <= plane.extent), axis=-1)


def trajectory_length(waypoints: jax.Array) -> jax.Array:
    """f32[]: the length of a polyline f32[L, 2] padded with NaN rows (padding ends it)."""
    segments = jnp.linalg.norm(waypoints[1:] - waypoints[:-1], axis=-1)
    return jnp.sum(jnp.where(jnp.isnan(segments), 0.0, segments))


def check_point(plane: Plane, point, *, name: str = "point") -> tuple[float, float]:
    """Host-side: ``point`` as an ``(x, y)`` float pair, in the plane and not inside an obstacle.

    Raises:
      ValueError: naming ``name`` when it is not two finite numbers, is off the plane or lies
        inside a rectangle (the message names the rectangle).
    """
    xy = np.asarray(point, np.float64)
    if xy.shape != (2,) or not np.isfinite(xy).all():
        raise ValueError(f"{name} must be an (x, y) pair of finite numbers, got {point!r}")
    pair = float(xy[0]), float(xy[1])
    width, height = np.asarray(plane.extent, np.float64)
    if not (0 <= xy[0] <= width and 0 <= xy[1] <= height):
        raise ValueError(f"{name} {pair} is off the plane [0, {width:g}] x [0, {height:g}]")
    boxes = plane.obstacles()
    (inside,) = np.nonzero(_strictly_inside(np, boxes, np.ones(len(boxes), bool), xy))
    if inside.size:
        raise ValueError(f"{name} {pair} lies inside rectangle {int(inside[0])} = "
                         f"{tuple(float(v) for v in boxes[inside[0]])}")
    return pair


def shortest_path(plane: Plane, start, goal) -> tuple[float, np.ndarray]:
    """Host-side: the shortest collision-free path from ``start`` to ``goal``.

    Dijkstra (:func:`jaxswarm.exact.dijkstra`) over the visibility graph whose nodes are the
    start, the goal and every rectangle corner that lies in the plane and in no rectangle, with
    an edge between two nodes when the segment joining them crosses no rectangle
    (:func:`crossings`). The length is summed in float64 from the waypoints.

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
    corners = corners[~_strictly_inside(np, boxes, real, corners).any(axis=-1)
                      & (corners >= 0).all(-1) & (corners <= np.asarray(plane.extent)).all(-1)]
    points = np.concatenate([np.asarray([start, goal]), corners])
    a, b = np.broadcast_arrays(points[:, None], points[None, :])
    blocked = _crossed(np, boxes, real, a, b).any(axis=-1)
    distance = np.linalg.norm(a - b, axis=-1)
    weights = np.where(~blocked & (distance > 0), distance, np.inf)
    solution = dijkstra(dense_graph(weights, points), 0, 1)
    if not bool(solution.found):
        return float("inf"), np.zeros((0, 2))
    waypoints = points[trim(solution.path)]
    return float(np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=-1))), waypoints

PLANE_CAPACITY = 64
"""Rectangle slots of the paper planes (both share one compiled program)."""

PAPER_PLANES: dict[str, dict] = {
    # Map #1: 56 rectangles of sides 2 to 7, at least 2 apart, scattered over the whole plane
    # (drawn once from a seeded generator and written out): many routes, and sides facing the
    # goal wide enough to hold a greedy vehicle.
    "map1": dict(start=(3.0, 3.0), goal=(47.0, 47.0), rectangles=(
    (34, 42, 38, 47), (40, 20, 43, 23), (12, 18, 15, 24), (20, 37, 26, 40), (6, 21, 8, 24),
    (17, 19, 24, 21), (22, 13, 29, 16), (3, 13, 5, 19), (6, 45, 10, 49), (4, 31, 10, 38),
    (43, 13, 46, 18), (14, 46, 20, 48), (14, 6, 18, 11), (33, 25, 37, 27), (38, 12, 41, 17),
    (27, 22, 31, 29), (43, 34, 49, 39), (36, 34, 38, 40), (22, 4, 26, 7), (41, 1, 46, 4),
    (17, 30, 22, 32), (40, 27, 46, 30), (40, 46, 45, 48), (22, 9, 24, 11), (31, 17, 33, 19),
    (28, 5, 34, 8), (24, 46, 27, 48), (30, 38, 32, 40), (10, 3, 12, 5), (39, 7, 46, 10),
    (5, 3, 7, 8), (17, 24, 20, 28), (22, 23, 25, 26), (15, 35, 17, 41), (46, 20, 48, 23),
    (5, 26, 10, 29), (8, 40, 10, 42), (42, 41, 46, 43), (7, 12, 9, 17), (26, 31, 29, 33),
    (22, 42, 24, 44), (12, 13, 15, 16), (9, 7, 12, 10), (30, 1, 36, 3), (33, 10, 35, 13),
    (1, 22, 4, 24), (15, 2, 18, 4), (13, 30, 15, 33), (1, 43, 4, 48), (29, 45, 31, 48),
    (33, 30, 38, 32), (17, 14, 20, 16), (12, 26, 15, 28), (1, 5, 3, 11), (33, 21, 36, 23),
    (1, 26, 3, 28),
    )),
    # Map #2: fewer rectangles, and a trap in front of the goal: two walls meeting in a corner
    # (x in [24, 42] below y = 42, y in [24, 41] left of x = 42; they overlap, so no slit is left
    # between them) that open towards the start. A vehicle drawn straight at the goal ends in the
    # corner and must move away from the goal, along a wall, to get round it.
    "map2": dict(start=(3.0, 3.0), goal=(47.0, 47.0), rectangles=(
    (24, 40, 42, 42), (40, 24, 42, 41), (5, 14, 12, 17), (21, 4, 25, 10), (37, 3, 44, 6),
    (9, 31, 14, 34), (12, 7, 15, 12), (20, 18, 25, 23), (10, 19, 14, 26), (20, 26, 24, 33),
    (30, 15, 32, 21), (15, 36, 18, 43), (32, 44, 36, 48), (47, 24, 49, 30), (37, 14, 39, 16),
    (43, 17, 49, 21), (27, 1, 33, 6), (41, 10, 48, 12), (32, 10, 35, 12), (20, 12, 24, 15),
    (6, 46, 11, 48), (1, 7, 3, 14), (7, 36, 12, 38), (5, 1, 12, 4), (38, 44, 40, 47),
    (8, 6, 10, 8), (46, 36, 49, 39), (3, 31, 5, 36), (46, 2, 48, 8), (44, 32, 49, 34),
    (6, 24, 8, 27), (2, 20, 4, 27),
    )),
}
"""The paper's maps #1 and #2 as we built them: start, goal and rectangles (50 x 50 planes)."""


def paper_plane(name: str) -> PlaneMap:
    """The paper's map ``"map1"`` or ``"map2"`` (see :data:`PAPER_PLANES`), padded to
    :data:`PLANE_CAPACITY` rectangles.

    Raises:
      ValueError: an unknown name (the message lists the known ones).
    """
    if name not in PAPER_PLANES:
        raise ValueError(f"unknown paper plane {name!r}; known: {', '.join(PAPER_PLANES)}")
    spec = PAPER_PLANES[name]
    plane = make_plane(spec["rectangles"], (50.0, 50.0), capacity=PLANE_CAPACITY)
    return PlaneMap(name, plane, spec["start"], spec["goal"])


RANDOM_RECTANGLES = 40
"""Rectangles of a random plane unless told otherwise."""


def random_plane(key: jax.Array, *, num_rectangles: int = RANDOM_RECTANGLES,
                 extent: float = 50.0, sides: tuple[float, float] = (2.0, 8.0),
                 start=(2.5, 2.5), goal=(47.5, 47.5),
                 capacity: int | None = None) -> PlaneMap:
    """A seeded random plane: ``num_rectangles`` axis-aligned rectangles with sides uniform in
    ``sides``, placed uniformly in an ``extent`` x ``extent`` plane; rectangles that would contain
    the start or the goal are left out (their slots stay padding), so the query is always valid
    (the goal may still be walled in: :func:`shortest_path` then says inf).

    Args:
      key: a JAX PRNG key (the plane is a function of it alone).
      num_rectangles: rectangles drawn (>= 0).
      extent: the plane's side.
      sides: the least and the greatest side of a rectangle, ``0 < low <= high < extent``.
      start, goal: ``(x, y)`` in the plane.
      capacity: rectangle slots (default ``num_rectangles``).

    Returns:
      A :class:`PlaneMap` labelled ``random``.

    Raises:
      ValueError: a bad count, extent, side range or query.
    """
    low, high = (float(s) for s in sides)
    if num_rectangles < 0:
        raise ValueError(f"num_rectangles must be non-negative, got {num_rectangles}")
    if not 0 < low <= high < extent:
        raise ValueError(f"sides must satisfy 0 < low <= high < extent, got {sides!r}")
    size_key, place_key = jax.random.split(key)
    size = np.asarray(jax.random.uniform(size_key, (num_rectangles, 2), minval=low, maxval=high))
    corner = np.asarray(jax.random.uniform(place_key, (num_rectangles, 2))) * (extent - size)
    boxes = np.concatenate([corner, corner + size], axis=1).astype(np.float64)
    query = np.asarray([start, goal], np.float64)
    contains = _strictly_inside(np, boxes, np.ones(len(boxes), bool), query).any(axis=0)
    plane = make_plane(boxes[~contains], (extent, extent),
                       capacity=max(num_rectangles, 1) if capacity is None else capacity)
    return PlaneMap("random", plane, check_point(plane, start, name="start"),
                    check_point(plane, goal, name="goal"))


def _strictly_inside(xp, rectangles, mask, points):
    """bool[..., R]: point (f[..., 2]) strictly inside rectangle r (and r is real); ``xp`` is
    jax.numpy in the swarm, numpy (float64) on the host."""
    p = points[..., None, :]
    return mask & xp.all((rectangles[:, :2] < p) & (p < rectangles[:, 2:]), axis=-1)


def _crossed(xp, rectangles, mask, a, b):
    """bool[..., R]: the segment a -> b (f[..., 2] each, same shape) meets rectangle r's
    interior; ``xp`` as in :func:`_strictly_inside`."""
    low, high = rectangles[:, :2], rectangles[:, 2:]
    origin = a[..., None, :]
    direction = (b - a)[..., None, :]
    # Liang-Barsky: the parameters where the segment is inside each slab, then the chord.
    still = direction == 0
    safe = xp.where(still, 1.0, direction)
    t_low, t_high = (low - origin) / safe, (high - origin) / safe
    enter = xp.max(xp.where(still, -xp.inf, xp.minimum(t_low, t_high)), axis=-1)
    leave = xp.min(xp.where(still, xp.inf, xp.maximum(t_low, t_high)), axis=-1)
    t0, t1 = xp.maximum(enter, 0.0), xp.minimum(leave, 1.0)
    middle = origin + 0.5 * (t0 + t1)[..., None] * direction
    return mask & (t0 <= t1) & xp.all((low < middle) & (middle < high), axis=-1)
