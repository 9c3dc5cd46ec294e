import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.sparse.csgraph as csgraph

from jaxswarm.world.graph import dense_graph, grid_graph, path_map_graph
from jaxswarm.world.lattice import (DIRECTIONS, OPPOSITE, move_lengths, slot_lengths, slot_offsets,
                              total_length)
from jaxswarm.world.relax import lowest_neighbour, relax
from oracle import grid_adjacency

# The functions under test, jitted: one program per map shape instead of each of their
# operations applied on its own.
total = jax.jit(total_length)
per_move = jax.jit(move_lengths)
cheapest = jax.jit(lowest_neighbour)
settle = jax.jit(relax, static_argnames=("update", "max_sweeps", "sweeps_per_check"))


def edges_of(graph):
    """{(u, v): length} of the valid edges, via to_dense()."""
    dense = graph.to_dense()
    rows, cols = np.nonzero(np.isfinite(dense) & (dense > 0))
    return {(int(u), int(v)): float(dense[u, v]) for u, v in zip(rows, cols)}


def oracle_edges(obstacles, **options):
    width = obstacles.shape[1]
    adjacency = grid_adjacency(obstacles.tolist(), **options)
    return {(y * width + x, v[1] * width + v[0]): w
            for (x, y), out in adjacency.items() for v, w in out}


@pytest.mark.parametrize("connectivity", [4, 8])
@pytest.mark.parametrize("corner_cutting", [False, True])
def test_grid_edges_match_independent_rules(connectivity, corner_cutting):
    obstacles = np.random.default_rng(3).random((7, 9)) < 0.35
    graph = grid_graph(obstacles, connectivity=connectivity, corner_cutting=corner_cutting)
    assert graph.max_degree == connectivity and graph.num_nodes == 63 and graph.shape == (7, 9)
    ours = edges_of(graph)
    theirs = oracle_edges(obstacles, connectivity=connectivity, corner_cutting=corner_cutting)
    assert ours.keys() == theirs.keys()
    for edge, length in theirs.items():
        assert ours[edge] == pytest.approx(length, rel=1e-6)


def test_no_corner_cutting_blocks_diagonal_past_one_obstacle():
    graph = grid_graph(np.array([[0, 1], [0, 0]]))
    assert not np.isfinite(graph.to_dense()[0, 3])  # (0,0) -> (1,1) squeezes past (1,0)
    cut = grid_graph(np.array([[0, 1], [0, 0]]), corner_cutting=True)
    assert cut.to_dense()[0, 3] == pytest.approx(math.sqrt(2))


def test_directions_and_reverse_slots_are_consistent():
    graph = grid_graph(np.zeros((4, 5), bool))
    nbr, rev, xy = map(np.asarray, (graph.nbr, graph.rev, graph.xy))
    for i in range(graph.num_nodes):
        for k in range(8):
            j = nbr[i, k]
            if j < 0:
                assert rev[i, k] == -1
                continue
            np.testing.assert_array_equal(xy[j] - xy[i], DIRECTIONS[k])
            assert rev[i, k] == OPPOSITE[k] and nbr[j, rev[i, k]] == i


@pytest.mark.parametrize("make", [lambda: grid_graph(np.zeros((4, 5), bool), connectivity=4),
                                  lambda: grid_graph(np.zeros((4, 5), bool)),
                                  lambda: path_map_graph(np.ones((4, 5, 8)))])
def test_slot_offsets_and_lengths_describe_the_lattice(make):
    graph = make()
    nbr, cost = np.asarray(graph.nbr), np.asarray(graph.cost)
    rows, slots = np.nonzero(nbr >= 0)
    np.testing.assert_array_equal(nbr[rows, slots], rows + slot_offsets(graph)[slots])
    np.testing.assert_array_equal(cost[rows, slots], slot_lengths(graph)[slots])
    assert slot_offsets(graph).shape == slot_lengths(graph).shape == (graph.max_degree,)


def test_total_length_does_not_depend_on_the_order_of_the_moves():
    graph = grid_graph(np.zeros((30, 30), bool))
    rng = np.random.default_rng(0)
    moves = rng.integers(0, 8, 200)
    orders = np.stack([moves, rng.permutation(moves), np.sort(moves)])
    slots = np.concatenate([orders, np.full((3, 20), -1)], axis=1).astype(np.int16)
    nodes = np.zeros(slots.shape, np.int32)  # grid lengths do not depend on the node
    lengths = np.asarray(total(graph, nodes, slots))
    assert lengths[0] == lengths[1] == lengths[2]
    expected = np.sum((moves < 4) * 1.0 + (moves >= 4) * math.sqrt(2))
    assert lengths[0] == pytest.approx(expected, rel=1e-6)
    np.testing.assert_allclose(np.asarray(per_move(graph, nodes, slots)).sum(axis=1), lengths,
                               rtol=1e-6)


def test_total_length_on_a_general_graph_sums_the_edge_costs():
    weights = np.array([[0, 1.5, np.inf], [np.inf, 0, 0.25], [2.0, np.inf, 0]])
    graph = dense_graph(weights)
    nbr = np.asarray(graph.nbr)
    slot = {(u, int(v)): k for u in range(3) for k, v in enumerate(nbr[u]) if v >= 0}
    nodes = np.array([[0, 1, 2, 0]], np.int32)
    slots = np.array([[slot[0, 1], slot[1, 2], slot[2, 0], -1]], np.int16)
    assert float(np.asarray(total(graph, nodes, slots))[0]) == pytest.approx(1.5 + 0.25 + 2.0)
    with pytest.raises(ValueError, match="general graph"):
        slot_offsets(graph)
    with pytest.raises(ValueError, match="general graph"):
        slot_lengths(graph)


def test_path_map_walls_close_both_ways_unless_directed():
    conn = np.ones((2, 3, 8), np.uint8)
    conn[0, 0, 0] = 0  # (0,0) says: no move east
    undirected = edges_of(path_map_graph(conn))
    assert (0, 1) not in undirected and (1, 0) not in undirected
    directed = edges_of(path_map_graph(conn, directed=True))
    assert (0, 1) not in directed and (1, 0) in directed
    # No corner rule on path maps: every lattice diagonal is present.
    assert (0, 4) in undirected and undirected[(0, 4)] == pytest.approx(math.sqrt(2))


def test_dense_graph_round_trip_and_shortest_paths_match_scipy():
    rng = np.random.default_rng(0)
    weights = np.where(rng.random((12, 12)) < 0.3, rng.uniform(0.5, 3.0, (12, 12)), np.inf)
    graph = dense_graph(weights)
    dense = graph.to_dense()
    expected = weights.copy()
    np.fill_diagonal(expected, 0.0)
    np.testing.assert_allclose(dense, expected, rtol=1e-6)
    ours = csgraph.shortest_path(np.where(np.isfinite(dense), dense, 0), directed=True)
    theirs = csgraph.shortest_path(np.where(np.isfinite(weights), weights, 0), directed=True)
    np.testing.assert_allclose(ours, theirs, rtol=1e-6)


SMALL_MAPS = pytest.mark.parametrize("make", [
    lambda rng: grid_graph(rng.random((6, 11)) < 0.3),
    lambda rng: grid_graph(rng.random((9, 4)) < 0.3, connectivity=4),
    lambda rng: path_map_graph(rng.random((5, 7, 8)) < 0.7),
    lambda rng: dense_graph(np.where(rng.random((12, 12)) < 0.4, rng.random((12, 12)) + 0.5,
                                     np.inf)),
], ids=["grid8", "grid4", "path_map", "dense"])


@SMALL_MAPS
def test_lowest_neighbour_is_the_cheapest_valid_edge(make):
    rng = np.random.default_rng(11)
    graph = make(rng)
    values = rng.random(graph.num_nodes).astype(np.float32) * 10
    lengths = np.where(np.asarray(graph.valid_edges()), np.asarray(graph.cost), np.inf)
    expected = np.full(graph.num_nodes, np.inf)
    for (u, v), length in edges_of(graph).items():
        expected[u] = min(expected[u], values[v] + length)
    np.testing.assert_allclose(cheapest(graph, values, lengths), expected, rtol=1e-6)


def raise_pits(here, lowest):
    """The update of RFD*'s settling: a node above 1 whose cheapest neighbour is higher rises to
    it."""
    pit = (here > 1) & (lowest > here) & jnp.isfinite(lowest)
    return jnp.where(pit, lowest, here), pit


@SMALL_MAPS
@pytest.mark.parametrize("per_check", [1, 3])
def test_relax_matches_jacobi_sweeps_over_the_edge_list(make, per_check):
    # Sweeps of "raise a node with value above 1 to its cheapest neighbour, if that is higher"
    # (RFD*'s settling), against plain Python sweeps over the edge list.
    rng = np.random.default_rng(5)
    graph = make(rng)
    # Filled ground at 2, about a tenth of the nodes unfilled (below 1): the outlets.
    start = np.where(rng.random(graph.num_nodes) < 0.1, rng.random(graph.num_nodes),
                     2.0).astype(np.float32)
    # One outlet in every connected part, else filled ground there rises at every sweep.
    dense = graph.to_dense()
    _, part = csgraph.connected_components(np.isfinite(dense) & (dense > 0), directed=False)
    start[np.unique(part, return_index=True)[1]] = 0.5
    rise = (np.where(np.asarray(graph.valid_edges()), np.asarray(graph.cost), np.inf)
            * 0.25).astype(np.float32)
    edges = edges_of(graph)

    def python_sweeps(values, most):
        for sweep in range(most):
            lowest = np.full(graph.num_nodes, np.inf, np.float32)
            for (u, v), length in edges.items():
                lowest[u] = min(lowest[u], values[v] + np.float32(length * 0.25))
            pit = (values > 1) & (lowest > values) & np.isfinite(lowest)
            if not pit.any():
                return values, sweep + 1
            values = np.where(pit, lowest, values)
        return values, most

    expected, sweeps = python_sweeps(start, 10_000)
    assert sweeps >= 2  # some ground rose
    settled, ran = settle(graph, start, rise, raise_pits, max_sweeps=10_000,
                          sweeps_per_check=per_check)
    np.testing.assert_allclose(settled, expected, rtol=1e-6)
    raising = sweeps - 1  # the last Python sweep found nothing to raise
    assert int(ran) == (-(-raising // per_check) + 1) * per_check  # stops after a quiet check
    capped, ran = settle(graph, start, rise, raise_pits, max_sweeps=2)
    np.testing.assert_allclose(capped, python_sweeps(start, 2)[0], rtol=1e-6)
    assert int(ran) == 2


def test_graph_is_a_pytree_with_static_shape():
    graph = grid_graph(np.zeros((3, 4), bool))
    leaves, treedef = jax.tree_util.tree_flatten(graph)
    assert len(leaves) == 7
    rebuilt = jax.tree_util.tree_unflatten(treedef, leaves)
    assert rebuilt.shape == (3, 4)
    count = jax.jit(lambda g: g.valid_edges().sum())(graph)
    assert int(count) == len(edges_of(graph))


@pytest.mark.parametrize("bad, message", [
    (np.zeros((0, 3)), "non-empty"),
    (np.zeros(5), "2-D"),
    (np.full((2, 2), 2), "0/1"),
])
def test_grid_graph_rejects_bad_input(bad, message):
    with pytest.raises(ValueError, match=message):
        grid_graph(bad)


def test_bad_connectivity_and_weights_are_named():
    with pytest.raises(ValueError, match="connectivity"):
        grid_graph(np.zeros((2, 2)), connectivity=6)
    with pytest.raises(ValueError, match="NaN"):
        dense_graph(np.array([[0, np.nan], [1, 0]]))
    with pytest.raises(ValueError, match="non-negative"):
        dense_graph(np.array([[0, -1.0], [1, 0]]))
    with pytest.raises(ValueError, match="square"):
        dense_graph(np.ones((2, 3)))
    with pytest.raises(ValueError, match=r"\[H, W, 8\]"):
        path_map_graph(np.ones((2, 2, 4)))
    with pytest.raises(ValueError, match="xy"):
        dense_graph(np.ones((3, 3)), xy=np.zeros((2, 2)))
