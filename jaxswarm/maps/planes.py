"""Planes for the bees: the paper's maps #1 and #2 (ours) and seeded random planes.

The paper's maps #1 and #2 (its Figures 1 and 2) did not survive the text: :func:`paper_plane`
builds ours in their spirit (see :data:`~jaxswarm.maps.planes.PAPER_PLANES`).
"""
from __future__ import annotations

from typing import NamedTuple

import jax
import numpy as np

from jaxswarm.world.plane import Plane, check_point, make_plane, strictly_inside


class PlaneMap(NamedTuple):
    """A plane with its query.

    Attributes:
      label: its name in tables (``map1``, ``random-s3``).
      plane: the :class:`~jaxswarm.world.plane.Plane`.
      start, goal: ``(x, y)`` floats.
    """

    label: str
    plane: Plane
    start: tuple[float, float]
    goal: tuple[float, float]


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
    """The paper's map ``"map1"`` or ``"map2"`` (see :data:`~jaxswarm.maps.planes.PAPER_PLANES`),
    padded to :data:`~jaxswarm.maps.planes.PLANE_CAPACITY` rectangles.

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
    (the goal may still be walled in: :func:`jaxswarm.exact.visibility.shortest_path` then says
    inf).

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
    contains = strictly_inside(np, boxes, np.ones(len(boxes), bool), query).any(axis=0)
    plane = make_plane(boxes[~contains], (extent, extent),
                       capacity=max(num_rectangles, 1) if capacity is None else capacity)
    return PlaneMap("random", plane, check_point(plane, start, name="start"),
                    check_point(plane, goal, name="goal"))
