import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.sparse.csgraph as csgraph

import oracle
from jaxswarm.exact import (astar, balanced_bidirectional_astar, bidirectional_astar, dijkstra,
                            distance_field, optimum)
from jaxswarm.maps.random import random_path_map
from jaxswarm.world.graph import dense_graph, grid_graph, path_map_graph
from jaxswarm.world.paths import is_valid_path, path_length

PLANNERS = [dijkstra, astar, bidirectional_astar, balanced_bidirectional_astar]


def check_solution(graph, solution, source, target, expected):
    if math.isinf(expected):
        assert not solution.found and math.isinf(solution.cost)
        assert (np.asarray(solution.path) == -1).all()
        return
    assert solution.found
    # Grid lengths are exact; general-graph weights are stored as float32.
    assert solution.cost == pytest.approx(expected, rel=1e-6, abs=1e-9)
    nodes = solution.nodes()
    assert nodes[0] == source and nodes[-1] == target
    assert bool(is_valid_path(graph, solution.path, source, target))
    assert float(path_length(graph, solution.path)) == pytest.approx(expected, rel=1e-5)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("planner", PLANNERS, ids=lambda p: p.__name__)
def test_grids_match_heapq_oracle(seed, planner):
    rng = np.random.default_rng(seed)
    height, width = rng.integers(5, 25, size=2)
    connectivity = [4, 8][seed % 2]
    corner_cutting = seed % 3 == 0
    obstacles = rng.random((height, width)) < rng.uniform(0.1, 0.45)
    graph = grid_graph(obstacles, connectivity=connectivity, corner_cutting=corner_cutting)
    adjacency = oracle.grid_adjacency(obstacles.tolist(), connectivity=connectivity,
                                      corner_cutting=corner_cutting)
    free = np.argwhere(~obstacles)
    for _ in range(15):
        (sy, sx), (gy, gx) = free[rng.integers(len(free), size=2)]
        expected = oracle.dijkstra(adjacency, (sx, sy), (gx, gy))
        solution = planner(graph, (int(sx), int(sy)), (int(gx), int(gy)))
        check_solution(graph, solution, sy * width + sx, gy * width + gx, expected)


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("planner", PLANNERS, ids=lambda p: p.__name__)
def test_directed_general_graphs_match_oracle_and_scipy(seed, planner):
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(5, 40))
    weights = np.where(rng.random((n, n)) < 4 / n, rng.uniform(0.1, 5.0, (n, n)), 0.0)
    graph = dense_graph(weights)
    scipy_dist = csgraph.shortest_path(weights, directed=True)
    adjacency = oracle.matrix_adjacency(weights)
    for source, target in rng.integers(n, size=(20, 2)):
        expected = oracle.dijkstra(adjacency, int(source), int(target))
        assert expected == pytest.approx(scipy_dist[source, target], rel=1e-9)
        check_solution(graph, planner(graph, int(source), int(target)), source, target, expected)


@pytest.mark.parametrize("planner", [astar, bidirectional_astar, balanced_bidirectional_astar],
                         ids=lambda p: p.__name__)
def test_euclidean_heuristic_on_geometric_graph_is_optimal(planner):
    rng = np.random.default_rng(7)
    n = 60
    xy = rng.uniform(0, 10, (n, 2))
    span = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
    weights = np.where(span < 2.5, span * rng.uniform(1.0, 1.5, (n, n)), 0.0)
    graph = dense_graph(weights, xy=xy)
    dist = csgraph.shortest_path(weights, directed=True)
    for source, target in rng.integers(n, size=(25, 2)):
        solution = planner(graph, int(source), int(target), heuristic="euclidean")
        if np.isinf(dist[source, target]):
            assert not solution.found
        else:
            assert solution.cost == pytest.approx(dist[source, target], rel=1e-5)


@pytest.mark.parametrize("seed", range(3))
def test_path_maps_match_scipy(seed):
    graph = path_map_graph(random_path_map(9, 7, seed, extra=0.2))
    dist = csgraph.shortest_path(np.where(np.isfinite(graph.to_dense()), graph.to_dense(), 0))
    for planner in PLANNERS:
        for target in (62, 30, 8):
            solution = planner(graph, 0, target)
            assert solution.cost == pytest.approx(dist[0, target], rel=1e-5)


def test_unreachable_goal_is_not_found_and_no_exception():
    obstacles = np.zeros((5, 5), bool)
    obstacles[:, 2] = True
    graph = grid_graph(obstacles)
    for planner in PLANNERS:
        solution = planner(graph, (0, 0), (4, 4))
        assert not solution.found and math.isinf(solution.cost)
        assert (np.asarray(solution.path) == -1).all() and solution.path.shape == (25,)
        # A one-sided search proves the goal unreachable by expanding the start's whole
        # component (the 10 cells left of the wall); a two-sided one stops as soon as one side
        # runs out, having expanded at most both components.
        if planner in (bidirectional_astar, balanced_bidirectional_astar):
            assert 10 <= solution.stats.expanded <= 20
        else:
            assert solution.stats.expanded == 10


def test_start_equals_goal_and_max_len():
    graph = grid_graph(np.zeros((4, 4), bool))
    for planner in PLANNERS:
        solution = planner(graph, (2, 2), (2, 2), max_len=3)
        assert solution.found and solution.cost == 0.0
        np.testing.assert_array_equal(solution.path, [10, -1, -1])


@pytest.mark.parametrize("planner", PLANNERS, ids=lambda p: p.__name__)
@pytest.mark.parametrize("start, goal, message", [
    ((1, 1), (3, 3), "start .* is blocked"),
    ((0, 0), (1, 1), "goal .* is blocked"),
    ((9, 0), (3, 3), "start .* off the 4x4 map"),
    ((0, 0), (0, -1), "goal .* off the"),
])
def test_bad_endpoints_raise_value_error(planner, start, goal, message):
    obstacles = np.zeros((4, 4), bool)
    obstacles[1, 1] = True
    with pytest.raises(ValueError, match=message):
        planner(grid_graph(obstacles), start, goal)


def test_unknown_heuristic_is_named():
    with pytest.raises(ValueError, match="unknown heuristic 'manhattan'"):
        astar(grid_graph(np.zeros((3, 3), bool)), 0, 8, heuristic="manhattan")


def test_statistics_are_consistent_and_heuristics_save_work():
    rng = np.random.default_rng(11)
    totals = {planner.__name__: 0 for planner in PLANNERS}
    for seed in range(10):
        obstacles = rng.random((30, 30)) < 0.25
        obstacles[0, 0] = obstacles[-1, -1] = False
        graph = grid_graph(obstacles)
        for planner in PLANNERS:
            stats = planner(graph, (0, 0), (29, 29)).stats
            assert stats.iterations >= stats.expanded > 0
            assert stats.generated >= stats.expanded and stats.wall_time > 0
            totals[planner.__name__] += stats.expanded
    assert totals["astar"] < totals["dijkstra"]


def test_distance_field_matches_scipy_and_vmaps_over_goals_and_maps():
    rng = np.random.default_rng(5)
    maps = [rng.random((12, 15)) < 0.3 for _ in range(3)]
    graphs = [grid_graph(m) for m in maps]
    goals = jnp.array([0, 77, 179])
    batch = jax.tree_util.tree_map(lambda *leaves: jnp.stack(leaves), *graphs)
    fields = jax.jit(jax.vmap(jax.vmap(distance_field, in_axes=(None, 0)), in_axes=(0, None)))(
        batch, goals)
    assert fields.shape == (3, 3, 180) and fields.dtype == jnp.float32
    for m, graph in enumerate(graphs):
        dense = graph.to_dense()
        # distance_field(goal)[i] is the distance i -> goal: shortest paths on the reversed graph.
        to_goal = csgraph.shortest_path(np.where(np.isfinite(dense), dense, 0).T,
                                        indices=np.asarray(goals))
        expected = np.where(np.asarray(graph.free)[None, :] | (np.arange(180) == goals[:, None]),
                            to_goal, np.inf)
        np.testing.assert_allclose(fields[m], expected, rtol=1e-5)


def test_optimum_agrees_with_dijkstra_on_directed_graph():
    rng = np.random.default_rng(9)
    weights = np.where(rng.random((20, 20)) < 0.2, rng.uniform(0.5, 2.0, (20, 20)), 0.0)
    graph = dense_graph(weights)
    for source, target in rng.integers(20, size=(15, 2)):
        expected = dijkstra(graph, int(source), int(target)).cost
        got = float(optimum(graph, int(source), int(target)))
        assert got == pytest.approx(expected, rel=1e-5) or (
            math.isinf(got) and math.isinf(expected))
