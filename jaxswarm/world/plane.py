"""The plane: a rectangle of the plane with axis-aligned rectangular obstacles (the bees' world,
constrained ABC paper section III), and its geometry.

A :class:`Plane` is a pytree of fixed-shape arrays: ``R`` rectangles padded with a mask, and the
plane's extent ``[0, width] x [0, height]``. Planes of the same capacity ``R`` share compiled code
whatever their rectangles. Points are ``(x, y)`` floats.

The geometry conventions are used everywhere (the swarm, the exact optimum, the checks):

* A point **violates** a rectangle when it lies strictly inside it; the boundary is free, so a
  path may run along an obstacle's side or touch its corner (as the shortest path does).
* A segment **crosses** a rectangle when some point of it lies strictly inside. The test clips the
  segment to the closed rectangle and asks whether the clipped chord's midpoint is strictly inside:
  for a convex set the chord meets the interior exactly when its midpoint does.

Where planes come from: :mod:`jaxswarm.maps.planes`; their optimum:
:func:`jaxswarm.exact.visibility.shortest_path`.
"""
from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.arithmetic import ordered_sum


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
    return jnp.sum(strictly_inside(jnp, plane.rectangles, plane.mask, points), axis=-1,
                   dtype=jnp.int32)


def crossings(plane: Plane, a: jax.Array, b: jax.Array) -> jax.Array:
    """i32[...]: how many rectangles the segment from ``a`` to ``b`` passes through (f32[..., 2]
    each, broadcast together)."""
    a, b = jnp.broadcast_arrays(jnp.asarray(a, jnp.float32), jnp.asarray(b, jnp.float32))
    return jnp.sum(segment_crosses(jnp, plane.rectangles, plane.mask, a, b), axis=-1,
                   dtype=jnp.int32)


def in_plane(plane: Plane, points: jax.Array) -> jax.Array:
    """bool[...]: whether points (f32[..., 2]) lie in ``[0, width] x [0, height]``."""
    return jnp.all((points >= 0) & (points <= plane.extent), axis=-1)


def trajectory_length(waypoints: jax.Array) -> jax.Array:
    """f32[]: the length of a polyline f32[L, 2] padded with NaN rows (padding ends it)."""
    segments = jnp.linalg.norm(waypoints[1:] - waypoints[:-1], axis=-1)
    return ordered_sum(jnp.where(jnp.isnan(segments), 0.0, segments))


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
    (inside,) = np.nonzero(strictly_inside(np, boxes, np.ones(len(boxes), bool), xy))
    if inside.size:
        raise ValueError(f"{name} {pair} lies inside rectangle {int(inside[0])} = "
                         f"{tuple(float(v) for v in boxes[inside[0]])}")
    return pair


def strictly_inside(xp, rectangles, mask, points):
    """bool[..., R]: whether each point (f[..., 2]) lies strictly inside rectangle r (f[R, 4])
    and r is real (``mask``, bool[R]); ``xp`` is ``jax.numpy`` in the swarm, ``numpy``
    (float64) on the host."""
    p = points[..., None, :]
    return mask & xp.all((rectangles[:, :2] < p) & (p < rectangles[:, 2:]), axis=-1)


def segment_crosses(xp, rectangles, mask, a, b):
    """bool[..., R]: whether the segment ``a -> b`` (f[..., 2] each, same shape) meets the
    interior of rectangle r (f[R, 4]) and r is real (``mask``, bool[R]); ``xp`` as in
    :func:`strictly_inside`."""
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
