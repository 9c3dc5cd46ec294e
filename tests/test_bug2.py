import numpy as np
import pytest
from jitted import bug2_path

from jaxswarm.exact import dijkstra
from jaxswarm.maps.random import random_grid, random_path_map
from jaxswarm.world.graph import grid_graph, path_map_graph
from jaxswarm.world.paths import is_valid_path, path_length



@pytest.mark.parametrize("seed", range(8))
def test_bug2_ant_reaches_the_goal_on_random_path_maps_without_looping(seed):
    width, height = [(10, 10), (20, 20), (40, 25)][seed % 3]
    graph = path_map_graph(random_path_map(width, height, seed, extra=0.15))
    goal = graph.num_nodes - 1
    path, cost, found = bug2_path(graph, 0, goal)
    assert bool(found) and dijkstra(graph, 0, goal).found
    nodes = np.asarray(path)[np.asarray(path) >= 0]
    assert len(set(nodes.tolist())) == len(nodes)  # no loops
    assert bool(is_valid_path(graph, path, 0, goal))
    assert float(cost) == pytest.approx(float(path_length(graph, path)))
    assert float(cost) >= dijkstra(graph, 0, goal).cost * (1 - 1e-6)


def test_bug2_ant_goes_straight_on_an_empty_grid_and_reports_unreachable_goals():
    graph = grid_graph(np.zeros((6, 6), bool))
    path, cost, found = bug2_path(graph, 0, 35)
    np.testing.assert_array_equal(np.asarray(path)[:6], [0, 7, 14, 21, 28, 35])
    assert float(cost) == pytest.approx(5 * np.sqrt(2))
    walled = np.zeros((6, 6), bool)
    walled[:, 3] = True
    path, cost, found = bug2_path(grid_graph(walled), 0, 35)
    assert not bool(found) and np.isinf(float(cost)) and (np.asarray(path) == -1).all()


def test_bug2_ant_finds_a_way_through_random_grids_whenever_one_exists():
    for seed in range(5):
        grid = random_grid(25, seed, density=0.4)
        graph = grid_graph(grid.obstacles)
        _, _, found = bug2_path(graph, 0, graph.num_nodes - 1)
        assert bool(found)
