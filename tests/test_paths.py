import math

import jax
import numpy as np
import pytest

from jaxswarm.world import edits
from jaxswarm.world import paths as paths_module
from jaxswarm.world.graph import dense_graph, grid_graph
from jaxswarm.world.paths import as_node, is_valid_path, node_index, pad, path_length, trim

LENGTH = 8
"""The padded length of the paths checked one at a time, so that they share the programs of
``path_length`` and ``is_valid_path``."""
block_cells = jax.jit(edits.block_cells)
""":func:`~jaxswarm.world.edits.block_cells` as one program, rather than op by op."""
node_xy = jax.jit(paths_module.node_xy)
""":func:`~jaxswarm.world.paths.node_xy` as one program, rather than op by op."""


@pytest.fixture
def grid():
    obstacles = np.zeros((4, 4), bool)
    obstacles[1, 1] = True
    return grid_graph(obstacles)


def test_length_and_validity_of_a_known_path(grid):
    # (0,0) E (1,0) SE? no: (1,0)->(2,1) squeezes past blocked (1,1): invalid.
    path = pad([0, 1, 6], LENGTH)
    assert float(path_length(grid, path)) == pytest.approx(1 + math.sqrt(2))
    assert not bool(is_valid_path(grid, path))
    good = pad([0, 1, 2, 6, 10], LENGTH)
    assert float(path_length(grid, good)) == pytest.approx(4 + 0)
    assert bool(is_valid_path(grid, good, start=0, goal=10))
    assert not bool(is_valid_path(grid, good, start=0, goal=6))


def test_non_edges_holes_and_blocked_nodes_are_invalid(grid):
    jump = pad([0, 2], LENGTH)
    assert math.isinf(float(path_length(grid, jump)))
    assert not bool(is_valid_path(grid, jump))
    hole = pad([0, -1, 2], LENGTH)
    assert not bool(is_valid_path(grid, hole))
    through_obstacle = pad([0, 5, 10], LENGTH)
    assert not bool(is_valid_path(grid, through_obstacle))
    assert math.isinf(float(path_length(grid, np.full(LENGTH, -1, np.int32))))
    single = pad([3], LENGTH)
    assert float(path_length(grid, single)) == 0.0
    assert bool(is_valid_path(grid, single, start=3, goal=3))


def test_validity_follows_edits(grid):
    path = pad([0, 1, 2, 3], LENGTH)
    assert bool(is_valid_path(grid, path))
    assert not bool(is_valid_path(block_cells(grid, 2), path))


def test_path_functions_vmap_over_paths(grid):
    paths = np.stack([pad([0, 1, 2], 5), pad([0, 4, 8, 12], 5), pad([0, 5], 5)])
    lengths = jax.vmap(path_length, in_axes=(None, 0))(grid, paths)
    valid = jax.jit(jax.vmap(is_valid_path, in_axes=(None, 0)))(grid, paths)
    np.testing.assert_allclose(lengths, [2.0, 3.0, math.sqrt(2)], rtol=1e-6)
    np.testing.assert_array_equal(valid, [True, True, False])


def test_node_conversions(grid):
    assert int(node_index(grid, 3, 2)) == 11
    # NaN for padding; assert_array_equal takes NaN for equal to NaN.
    np.testing.assert_array_equal(node_xy(grid, np.array([11, 0, -1])),
                                  [[3, 2], [0, 0], [np.nan, np.nan]])
    assert as_node(grid, (3, 2)) == 11 and as_node(grid, 11) == 11
    np.testing.assert_array_equal(trim(pad([4, 5], 5)), [4, 5])
    with pytest.raises(ValueError, match="does not fit"):
        pad([1, 2, 3], 2)


@pytest.mark.parametrize("point, message", [
    ((4, 0), "off the 4x4 map"), ((-1, 2), "off the"), ((1, 1), "blocked"), (16, "off the map"),
    ((1.5, 0), "off the"), ((1, 2, 3), r"\(x, y\) pair"),
])
def test_as_node_errors_name_the_problem(grid, point, message):
    with pytest.raises(ValueError, match=message):
        as_node(grid, point, name="start")


def test_as_node_on_general_graph_uses_coordinates():
    graph = dense_graph(np.ones((3, 3)), xy=[[0, 0], [1, 0], [1, 0]])
    assert as_node(graph, (0, 0)) == 0
    with pytest.raises(ValueError, match="names 2 nodes"):
        as_node(graph, (1, 0))
    with pytest.raises(ValueError, match="general graph"):
        node_index(graph, 0, 0)
