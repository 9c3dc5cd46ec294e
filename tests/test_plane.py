"""Planes of rectangles: containment, crossing and the visibility-graph optimum, against shapely
and networkx (an independent geometry and an independent shortest path), and hand computations."""
import itertools
import math

import jax
import numpy as np
import pytest

from jaxswarm.exact.visibility import shortest_path
from jaxswarm.maps.planes import PAPER_PLANES, paper_plane, random_plane
from jaxswarm.world.plane import check_point, crossings, in_plane, make_plane, trajectory_length, violations

shapely = pytest.importorskip("shapely")
nx = pytest.importorskip("networkx")
INTERIOR = 1e-6
"""Shapely's boxes are shrunk by this much: touching a side or a corner is free."""

# The geometry under test, jitted: one program per plane capacity and shape of points instead of
# each of their operations applied on its own.
count_violations = jax.jit(violations)
count_crossings = jax.jit(crossings)
on_plane = jax.jit(in_plane)
polyline_length = jax.jit(trajectory_length)


def interiors(plane):
    return [shapely.box(*box).buffer(-INTERIOR, join_style="mitre") for box in plane.obstacles()]


def shapely_crossings(plane, a, b) -> int:
    segment = shapely.LineString([a, b])
    return sum(inside.intersects(segment) for inside in interiors(plane))


def shapely_shortest(plane, start, goal) -> float:
    """Visibility graph built with shapely's intersections, solved by networkx."""
    boxes = plane.obstacles()
    corners = [(x, y) for x0, y0, x1, y1 in boxes for x, y in ((x0, y0), (x1, y0), (x1, y1),
                                                                  (x0, y1))]
    blocked = np.asarray(interiors(plane))
    points = [tuple(start), tuple(goal)] + [
        c for c in set(corners) if not any(b.contains(shapely.Point(c)) for b in blocked)]
    pairs = list(itertools.combinations(points, 2))
    segments = shapely.linestrings(np.asarray(pairs, np.float64))
    free = ~shapely.intersects(segments[:, None], blocked[None, :]).any(axis=1)
    graph = nx.Graph()
    for (p, q), clear in zip(pairs, free):
        if clear:
            graph.add_edge(p, q, weight=math.dist(p, q))
    try:
        return nx.dijkstra_path_length(graph, tuple(start), tuple(goal))
    except (nx.NetworkXNoPath, nx.NodeNotFound):
        return math.inf


def test_a_point_violates_the_rectangles_it_lies_strictly_inside():
    plane = make_plane([(1, 1, 4, 4), (3, 3, 6, 6)], (10, 10), capacity=4)
    points = np.asarray([[2, 2], [3.5, 3.5], [1, 2], [4, 4], [8, 8], [6, 5]], np.float32)
    # (4, 4) is a corner of the first and inside the second; (6, 5) on the second's side.
    assert count_violations(plane, points).tolist() == [1, 2, 0, 1, 0, 0]
    assert on_plane(plane, np.asarray([[0, 10], [10.5, 1], [-1, 3]], np.float32)).tolist() == [
        True, False, False]


def test_a_segment_crosses_a_rectangle_only_through_its_interior():
    plane = make_plane([(10, 10, 20, 20)], (30, 30))
    cases = [  # (from, to, crossings)
        ((0, 15), (30, 15), 1),  # through the middle
        ((0, 15), (30, 10), 1),  # dipping into it
        ((0, 15), (30, 25), 1),
        ((10, 10), (20, 20), 1),  # its diagonal
        ((0, 15), (15, 0), 0),  # below it
        ((0, 15), (9, 15), 0),  # short of it
        ((0, 20), (30, 20), 0),  # along its top side
        ((0, 10), (20, 30), 0),  # touching its corner (10, 20) only
        ((0, 30), (10, 20), 0),  # ending at that corner
    ]
    a, b, expected = (np.asarray(column, np.float32) for column in zip(*cases))
    assert count_crossings(plane, a, b).tolist() == expected.tolist()


def test_crossings_agree_with_shapely_on_random_segments():
    plane = random_plane(jax.random.key(4), num_rectangles=12, extent=20.0, sides=(1.0, 6.0),
                         start=(0.5, 0.5), goal=(19.5, 19.5)).plane
    ends = np.asarray(jax.random.uniform(jax.random.key(5), (300, 2, 2))) * 20
    ours = np.asarray(count_crossings(plane, ends[:, 0], ends[:, 1]))
    assert ours.tolist() == [shapely_crossings(plane, a, b) for a, b in ends]
    assert ours.max() >= 2 and (ours == 0).any()


def test_the_shortest_path_round_one_rectangle_is_the_hand_computed_one():
    plane = make_plane([(10, 10, 20, 20)], (30, 30))
    length, waypoints = shortest_path(plane, (0, 15), (30, 15))
    assert length == pytest.approx(10 + 2 * math.hypot(10, 5))
    assert np.allclose(waypoints[[0, -1]], [[0, 15], [30, 15]])
    assert shortest_path(plane, (0, 5), (30, 5))[0] == pytest.approx(30)  # in plain sight
    assert shortest_path(plane, (3, 3), (3, 3)) [0] == 0.0


@pytest.mark.parametrize("seed", range(4))
def test_the_shortest_path_matches_shapely_and_networkx(seed):
    chosen = random_plane(jax.random.key(seed), num_rectangles=14, extent=20.0, sides=(1.0, 6.0),
                          start=(0.5, 0.5), goal=(19.5, 19.5))
    length, waypoints = shortest_path(chosen.plane, chosen.start, chosen.goal)
    assert length == pytest.approx(shapely_shortest(chosen.plane, chosen.start, chosen.goal),
                                   rel=1e-9)
    if math.isfinite(length):
        assert sum(shapely_crossings(chosen.plane, a, b)
                   for a, b in zip(waypoints[:-1], waypoints[1:])) == 0


def test_a_walled_in_goal_has_no_path():
    ring = [(3.5, 4, 6.5, 5), (3.5, 7, 6.5, 8), (3, 4, 4, 8), (6, 4, 7, 8)]  # overlapping
    plane = make_plane(ring, (10, 10))
    length, waypoints = shortest_path(plane, (1, 1), (5, 6))
    assert math.isinf(length) and waypoints.shape == (0, 2)


@pytest.mark.parametrize("name", sorted(PAPER_PLANES))
def test_paper_planes_share_a_shape_and_their_optimum_is_shapelys(name):
    chosen = paper_plane(name)
    assert chosen.plane.rectangles.shape == paper_plane("map1").plane.rectangles.shape
    assert np.asarray(chosen.plane.mask).sum() == len(PAPER_PLANES[name]["rectangles"])
    length, _ = shortest_path(chosen.plane, chosen.start, chosen.goal)
    assert length == pytest.approx(shapely_shortest(chosen.plane, chosen.start, chosen.goal))
    assert length > math.dist(chosen.start, chosen.goal)  # obstacles are in the way


def test_map2s_trap_holds_a_vehicle_that_only_approaches_the_goal():
    """The inner corner (40, 40) of map #2's walls is a local minimum of the goal distance: no
    free point of the sensor window around it (side 2) is nearer the goal."""
    chosen = paper_plane("map2")
    corner = np.asarray([40.0, 40.0])
    axis = np.linspace(-1.0, 1.0, 81)
    grid = corner + np.stack(np.meshgrid(axis, axis), -1).reshape(-1, 2)
    free = np.asarray(count_violations(chosen.plane, grid.astype(np.float32))) == 0
    distance = np.linalg.norm(grid - chosen.goal, axis=1)
    assert distance[free].min() == pytest.approx(np.linalg.norm(corner - chosen.goal))
    assert (distance[~free] < distance[free].min()).any()  # the way to the goal is walled


def test_random_planes_are_a_function_of_the_key_and_keep_the_query_free():
    a = random_plane(jax.random.key(3), num_rectangles=30)
    b = random_plane(jax.random.key(3), num_rectangles=30)
    c = random_plane(jax.random.key(4), num_rectangles=30)
    assert np.array_equal(a.plane.rectangles, b.plane.rectangles)
    assert not np.array_equal(a.plane.rectangles, c.plane.rectangles)
    assert a.plane.capacity == 30
    for chosen in (a, c):
        points = np.asarray([chosen.start, chosen.goal], np.float32)
        assert count_violations(chosen.plane, points).tolist() == [0, 0]


def test_trajectory_length_stops_at_the_padding():
    waypoints = np.asarray([[0, 0], [3, 4], [3, 5], [np.nan, np.nan]], np.float32)
    assert float(polyline_length(waypoints)) == 6.0


@pytest.mark.parametrize("rectangles, extent, capacity, message", [
    ([(1, 1, 1, 2)], (5, 5), None, r"rectangle 0 = \(1.0, 1.0, 1.0, 2.0\): needs x_min < x_max"),
    ([(1, 1, 2, 2), (4, 4, 6, 5)], (5, 5), None, r"rectangle 1 .* reaches outside the plane"),
    ([(1, 1, 2, 2)], (0, 5), None, "extent must be two positive numbers"),
    ([(1, 1, 2, 2), (3, 3, 4, 4)], (5, 5), 1, "capacity 1 is less than the 2 rectangles"),
])
def test_bad_planes_are_named(rectangles, extent, capacity, message):
    with pytest.raises(ValueError, match=message):
        make_plane(rectangles, extent, capacity=capacity)


def test_bad_points_are_named():
    plane = make_plane([(1, 1, 3, 3)], (5, 5))
    with pytest.raises(ValueError, match=r"goal \(2.0, 2.0\) lies inside rectangle 0"):
        check_point(plane, (2, 2), name="goal")
    with pytest.raises(ValueError, match=r"start \(6.0, 1.0\) is off the plane \[0, 5\] x"):
        check_point(plane, (6, 1), name="start")
    with pytest.raises(ValueError, match="start must be an \\(x, y\\) pair"):
        check_point(plane, (1, 2, 3), name="start")
    with pytest.raises(ValueError, match="lies inside rectangle 0"):
        shortest_path(plane, (0, 0), (2.5, 1.5))
