import jax
import numpy as np

from jaxswarm.world import edits
from jaxswarm.exact import distance_field
from jaxswarm.world.graph import grid_graph, path_map_graph
from jaxswarm.world.paths import as_node


def test_block_and_unblock_cells_change_contents_not_shapes():
    graph = grid_graph(np.zeros((5, 5), bool))
    center = as_node(graph, (2, 2))
    blocked = edits.block_cells(graph, [center])  # outside jit (under jit: the last test)
    free = np.asarray(blocked.free)
    assert not free[center] and free.sum() == 24
    assert not np.asarray(blocked.valid_edges())[center].any()
    # No edge into the blocked cell and no diagonal squeezing past it.
    valid = np.asarray(blocked.valid_edges())
    nbr = np.asarray(blocked.nbr)
    assert not ((nbr == center) & valid).any()
    assert not valid[as_node(graph, (1, 2)), 7]  # (1,2) -> NE (2,1) squeezes past (2,2)
    restored = edits.unblock_cells(blocked, center)
    np.testing.assert_array_equal(restored.valid_edges(), graph.valid_edges())
    for before, after in zip(jax.tree_util.tree_leaves(graph), jax.tree_util.tree_leaves(blocked)):
        assert before.shape == after.shape and before.dtype == after.dtype


def test_close_edges_closes_both_directions_and_open_restores():
    graph = path_map_graph(np.ones((3, 3, 8), np.uint8))
    closed = edits.close_edges(graph, [0], [0])  # wall between (0,0) and (1,0)
    valid = np.asarray(closed.valid_edges())
    assert not valid[0, 0] and not valid[1, 2]
    assert int(valid.sum()) == int(np.asarray(graph.valid_edges()).sum()) - 2
    reopened = edits.open_edges(closed, [1], [2])  # reopen from the other side
    np.testing.assert_array_equal(reopened.valid_edges(), graph.valid_edges())


def test_edges_off_the_lattice_are_ignored_not_wrapped():
    graph = path_map_graph(np.ones((2, 2, 8), np.uint8))
    last = graph.num_nodes - 1
    # Node 0 has no west neighbour (slot 2): nothing may change, in particular not the last node.
    closed = edits.close_edges(graph, [0], [2])
    np.testing.assert_array_equal(closed.open, graph.open)
    opened = edits.open_edges(edits.close_edges(graph, [last], [3]), [0], [2])
    is_open = np.asarray(opened.open)
    assert not is_open[0, 2]
    assert not is_open[last, 3]  # a wrapped -1 would have reopened the last node


def test_edits_under_jit_compile_once():
    traces = []

    @jax.jit
    def blocked_distance(graph, cell):
        traces.append(1)
        return distance_field(edits.block_cells(graph, cell), 0)

    graph = grid_graph(np.zeros((6, 6), bool))
    far = [np.asarray(blocked_distance(graph, cell))[35] for cell in (7, 14, 21, 28)]
    assert len(traces) == 1
    assert all(np.isfinite(far))
    wall = np.array([as_node(graph, (x, 3)) for x in range(6)])  # another shape: traced again
    assert not np.isfinite(np.asarray(blocked_distance(graph, wall))[35])
