"""The host's CSR arrays of a graph's edges (jaxswarm.world.edges) against edges counted by hand."""
import math

import numpy as np

from jaxswarm.world.edges import edge_arrays, lattice_arrays
from jaxswarm.world.graph import dense_graph, grid_graph

RING = grid_graph(np.array([[0, 0, 0], [0, 1, 0], [0, 0, 0]], bool))
"""A 3 x 3 grid whose centre is blocked: no corner cutting leaves only the ring's 8 cells joined
by their 16 orthogonal moves (every diagonal squeezes past the centre or ends on it)."""


def _edges(arrays):
    """{(tail, head): length} of the forward arrays, and of the reverse ones."""
    tails = np.repeat(np.arange(arrays.num_nodes), np.diff(arrays.indptr))
    forward = dict(zip(zip(tails.tolist(), arrays.heads.tolist()), arrays.lengths.tolist()))
    heads = np.repeat(np.arange(arrays.num_nodes), np.diff(arrays.rev_indptr))
    backward = dict(zip(zip(arrays.rev_tails.tolist(), heads.tolist()),
                        arrays.rev_lengths.tolist()))
    return forward, backward


def test_the_valid_edges_of_a_ring_are_its_orthogonal_moves():
    arrays = edge_arrays(RING)
    ring = [0, 1, 2, 5, 8, 7, 6, 3]  # node = y * 3 + x, around the centre
    expected = {(a, b): 1.0 for a, b in zip(ring, ring[1:] + ring[:1])}
    expected.update({(b, a): 1.0 for a, b in expected})
    forward, backward = _edges(arrays)
    assert forward == expected == backward
    assert arrays.indptr.dtype == arrays.rev_indptr.dtype == arrays.rev_edge.dtype == np.int64
    assert arrays.heads.dtype == arrays.rev_tails.dtype == np.int32
    assert arrays.lengths.dtype == arrays.x.dtype == np.float64
    np.testing.assert_array_equal(arrays.rev_lengths, arrays.lengths[arrays.rev_edge])
    np.testing.assert_array_equal(arrays.free, np.arange(9) != 4)
    np.testing.assert_array_equal(arrays.x, np.arange(9) % 3)
    np.testing.assert_array_equal(arrays.y, np.arange(9) // 3)
    assert edge_arrays(RING) is arrays  # cached per Graph


def test_the_lattice_arrays_keep_every_move_of_the_grid():
    forward, backward = _edges(lattice_arrays(RING))
    # 12 orthogonal neighbour pairs and 8 diagonal ones (two per 2 x 2 block), both ways.
    assert len(forward) == 2 * (12 + 8) and forward == backward
    assert forward[(0, 4)] == math.sqrt(2.0) and forward[(4, 1)] == 1.0  # the centre's moves too


def test_a_general_graphs_lengths_are_its_weights():
    weights = np.array([[0, 2.5, 0], [0, 0, 0.75], [4, 0, 0]], np.float32)
    forward, backward = _edges(edge_arrays(dense_graph(weights)))
    assert forward == backward == {(0, 1): 2.5, (1, 2): 0.75, (2, 0): 4.0}
