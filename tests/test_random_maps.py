import numpy as np
import pytest

from jaxswarm.exact import dijkstra
from jaxswarm.maps.random import random_grid, random_path_map
from jaxswarm.world.graph import grid_graph, path_map_graph
from jaxswarm.world.lattice import OPPOSITE


@pytest.mark.parametrize("size", [2, 10, 37])
def test_random_grid_has_corner_to_corner_path(size):
    for seed in range(5):
        grid = random_grid(size, seed, density=0.45)
        assert grid.start == (0, 0) and grid.goal == (size - 1, size - 1)
        assert dijkstra(grid_graph(grid.obstacles), grid.start, grid.goal).found


def test_random_grid_is_seeded_and_dense_enough():
    a, b, c = random_grid(40, 1), random_grid(40, 1), random_grid(40, 2)
    np.testing.assert_array_equal(a.obstacles, b.obstacles)
    assert (a.obstacles != c.obstacles).any()
    assert 0.2 < a.obstacles.mean() < 0.3  # density 0.3 minus the cleared staircase
    assert not a.obstacles.flags.writeable


def test_random_path_map_is_symmetric_connected_and_seeded():
    conn = random_path_map(12, 7, seed=4, extra=0.1)
    assert conn.shape == (7, 12, 8)
    np.testing.assert_array_equal(conn, random_path_map(12, 7, seed=4, extra=0.1))
    graph = path_map_graph(conn, directed=True)
    valid = np.asarray(graph.valid_edges())
    nbr, rev = np.asarray(graph.nbr), np.asarray(graph.rev)
    rows, slots = np.nonzero(valid)
    assert valid[nbr[rows, slots], rev[rows, slots]].all()  # every open move can be undone
    assert (rev[rows, slots] == OPPOSITE[slots]).all()
    # Every cell is reachable from cell 0 (the spanning tree), and walls exist (extra < 1).
    assert all(dijkstra(graph, 0, target).found for target in range(graph.num_nodes))
    assert valid.sum() < (np.asarray(graph.nbr) >= 0).sum()


@pytest.mark.parametrize("call, message", [
    (lambda: random_grid(1, 0), "size"),
    (lambda: random_grid(5, 0, density=1.0), "density"),
    (lambda: random_path_map(1, 1, 0), "at least 2 cells"),
    (lambda: random_path_map(3, 3, 0, extra=1.5), "extra"),
])
def test_bad_arguments(call, message):
    with pytest.raises(ValueError, match=message):
        call()
