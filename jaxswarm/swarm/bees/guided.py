"""The guided function of the constrained ABC paper (eq. 4) and its constraints (eq. 6).

``Phi(x) = w1 f1(x) + w2 f2(x) + w3 f3(x)`` (:func:`guided`) scores a candidate next position
``x`` of the vehicle, which stands at ``here`` and came from ``previous``:

* ``f1`` (eq. 1, :func:`goal_distance`): the distance from ``x`` to the goal;
* ``f2`` (pushback, :func:`pushback`): the sum of ``reach - d`` over four rays from ``x`` along
  +x, -x, +y and -y, ``reach`` (half the sensor window) long, ``d`` where each first meets the
  rectangles' parts inside the window (``reach`` if none): in ``[0, 4 reach]``;
* ``f3`` (smoothness, :func:`turn_angle`): the turn from the last move to ``here -> x``, 0 before
  the first, in ``turn_unit`` (:data:`TURN_UNITS`): degrees by default, as in radians a turn
  weighs less than a step towards the goal and f3 changes nothing;
* ``w4 f4`` (ours, the paper's future work; :func:`revisits`): how many sensor windows of the
  vehicle's earlier positions contain ``x``.

:func:`constraint_violations` counts eq. 6's violations, with ``forbid_crossing`` (ours) also the
rectangles the move passes through. The text lost f2's and f3's formulas; ``docs/papers.md`` says
how we read them and what each unit of f3 gives.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.world.plane import Plane, crossings, violations


def goal_distance(points: jax.Array, goal: jax.Array) -> jax.Array:
    """f1, eq. 1: f32[N], the distance of each point (f32[N, 2]) to the goal (f32[2])."""
    return jnp.hypot(points[:, 0] - goal[0], points[:, 1] - goal[1])


def visible_rectangles(plane: Plane, lower: jax.Array, upper: jax.Array):
    """The obstacles' parts inside the window ``[lower, upper]`` (f32[2] each).

    Returns:
      ``(boxes f32[R, 4], seen bool[R])``: each rectangle clipped to the window, and whether
      anything of it is left.
    """
    low = jnp.maximum(plane.rectangles[:, :2], lower)
    high = jnp.minimum(plane.rectangles[:, 2:], upper)
    seen = plane.mask & jnp.all(low <= high, axis=-1)
    return jnp.concatenate([low, high], axis=-1), seen


def ray_distances(points: jax.Array, boxes: jax.Array, seen: jax.Array,
                  reach: jax.Array) -> jax.Array:
    """f32[N, 4]: how far each point (f32[N, 2]) sees along +x, -x, +y and -y before it meets a
    seen box (f32[R, 4], bool[R]), at most ``reach`` (0 when the point is inside a box)."""
    x, y = points[:, 0:1], points[:, 1:2]
    x0, y0, x1, y1 = (boxes[None, :, i] for i in range(4))
    across_x = seen & (y0 <= y) & (y <= y1)  # boxes a horizontal ray can meet
    across_y = seen & (x0 <= x) & (x <= x1)
    far = jnp.inf
    right = jnp.where(across_x & (x1 >= x), jnp.maximum(x0 - x, 0.0), far)
    left = jnp.where(across_x & (x0 <= x), jnp.maximum(x - x1, 0.0), far)
    up = jnp.where(across_y & (y1 >= y), jnp.maximum(y0 - y, 0.0), far)
    down = jnp.where(across_y & (y0 <= y), jnp.maximum(y - y1, 0.0), far)
    nearest = jnp.stack([jnp.min(d, axis=-1) for d in (right, left, up, down)], axis=-1)
    return jnp.minimum(nearest, reach)


def pushback(points: jax.Array, plane: Plane, lower: jax.Array, upper: jax.Array,
             reach: jax.Array) -> jax.Array:
    """f2: f32[N], ``sum over the four rays of (reach - distance)`` (see the module docstring)."""
    boxes, seen = visible_rectangles(plane, lower, upper)
    return ordered_sum(reach - ray_distances(points, boxes, seen, reach), axis=-1)


TURN_UNITS = ("degrees", "radians")
"""The units f3 may measure the turn in (the option ``turn_unit``)."""


def check_turn_unit(turn_unit: str) -> None:
    """Host-side check of the option ``turn_unit``.

    Raises:
      ValueError: naming ``turn_unit`` when it is not one of :data:`TURN_UNITS`.
    """
    if turn_unit not in TURN_UNITS:
        raise ValueError(f"unknown turn_unit {turn_unit!r}; choose one of {', '.join(TURN_UNITS)}")


def turn_angle(points: jax.Array, here: jax.Array, previous: jax.Array, has_turn: jax.Array, *,
               turn_unit: str) -> jax.Array:
    """f3: f32[N], the angle (0 to 180 degrees or 0 to pi radians, by ``turn_unit``) between the
    move ``previous -> here`` (f32[2] each) and each move ``here -> point`` (f32[N, 2]); 0 where
    ``has_turn`` (bool[]) is False or a move has no length.

    Raises:
      ValueError: ``turn_unit`` is not one of :data:`TURN_UNITS`.
    """
    check_turn_unit(turn_unit)
    last = here - previous
    moves = points - here
    # Products written out, not a matmul: the same elementwise code alone and under vmap (a
    # batched dot may be lowered differently).
    cross = last[0] * moves[:, 1] - last[1] * moves[:, 0]
    dot = last[0] * moves[:, 0] + last[1] * moves[:, 1]
    angle = jnp.arctan2(jnp.abs(cross), dot)
    if turn_unit == "degrees":
        angle = jnp.degrees(angle)
    degenerate = jnp.all(last == 0) | jnp.all(moves == 0, axis=-1) | ~has_turn
    return jnp.where(degenerate, 0.0, angle)


def revisits(points: jax.Array, waypoints: jax.Array, count: jax.Array,
             reach: jax.Array) -> jax.Array:
    """f4: f32[N], for each point (f32[N, 2]), how many windows of half-side ``reach`` round the
    vehicle's earlier positions contain it: ``waypoints[:count - 1]`` (f32[L, 2]; the current
    position, ``waypoints[count - 1]``, and the NaN padding do not count)."""
    earlier = jnp.arange(waypoints.shape[0]) < count - 1
    inside = jnp.all(jnp.abs(points[:, None, :] - waypoints[None]) <= reach, axis=-1)
    return jnp.sum(inside & earlier, axis=-1).astype(jnp.float32)


def guided(points: jax.Array, weights: jax.Array, plane: Plane, goal: jax.Array,
           here: jax.Array, previous: jax.Array, has_turn: jax.Array, lower: jax.Array,
           upper: jax.Array, reach: jax.Array, *, turn_unit: str) -> jax.Array:
    """Phi, eq. 4: f32[N] for candidate points f32[N, 2].

    Args:
      points: f32[N, 2] candidates.
      weights: f32[3] ``(w1, w2, w3)``.
      plane: the world; goal: f32[2].
      here, previous: f32[2] the vehicle's position and the one before (``has_turn`` bool[]:
        whether there was one).
      lower, upper: f32[2] the sensor window; reach: f32[] the rays' length.
      turn_unit: f3's unit, one of :data:`TURN_UNITS`.

    Raises:
      ValueError: ``turn_unit`` is not one of :data:`TURN_UNITS`.
    """
    return (weights[0] * goal_distance(points, goal)
            + weights[1] * pushback(points, plane, lower, upper, reach)
            + weights[2] * turn_angle(points, here, previous, has_turn,
                                    turn_unit=turn_unit))


def constraint_violations(points: jax.Array, plane: Plane, here: jax.Array, *,
                          forbid_crossing: bool) -> jax.Array:
    """Eq. 6: i32[N], the rectangles each candidate (f32[N, 2]) lies inside, plus (with
    ``forbid_crossing``) those the move from ``here`` (f32[2]) to it passes through."""
    count = violations(plane, points)
    if forbid_crossing:
        count = count + crossings(plane, here, points)
    return count
