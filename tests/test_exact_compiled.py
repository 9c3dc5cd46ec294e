"""The compiled planners against the readable heapq ones (same paths, same work), and batches."""
import numba
import numpy as np
import pytest

from graphs import geometric_graph
from jaxswarm.exact import (astar, balanced_bidirectional_astar, bidirectional_astar, dijkstra,
                            dstar_lite, kernels, reference, shortest_lengths, warm_up)
from jaxswarm.exact.search import workspace
from jaxswarm.maps.random import random_path_map
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.graph import grid_graph, path_map_graph

PAIRS = [(dijkstra, reference.dijkstra), (astar, reference.astar),
         (bidirectional_astar, reference.bidirectional_astar),
         (balanced_bidirectional_astar, reference.balanced_bidirectional_astar)]
BIDIRECTIONAL = (bidirectional_astar, balanced_bidirectional_astar)


def assert_same_search(fast, slow, *, bidirectional):
    """Same cost and path bit for bit, same expansions and relaxations. The compiled planners
    re-key queued nodes instead of leaving stale entries, so they pop only what they expand
    (and A* the goal)."""
    assert fast.cost == slow.cost
    np.testing.assert_array_equal(fast.path, slow.path)
    assert (fast.stats.expanded, fast.stats.generated) == (slow.stats.expanded,
                                                           slow.stats.generated)
    popped_goal = 0 if bidirectional else int(fast.found)
    if not (bidirectional and fast.nodes().size == 1):
        assert fast.stats.iterations == fast.stats.expanded + popped_goal
    assert slow.stats.iterations >= fast.stats.iterations


@pytest.mark.parametrize("seed", range(8))
def test_grids_same_paths_and_statistics_as_reference(seed):
    rng = np.random.default_rng(300 + seed)
    height, width = rng.integers(6, 30, size=2)
    obstacles = rng.random((height, width)) < rng.uniform(0.1, 0.4)
    graph = grid_graph(obstacles, connectivity=[4, 8][seed % 2], corner_cutting=seed % 3 == 0)
    free = np.argwhere(~obstacles)
    for _ in range(12):
        (sy, sx), (gy, gx) = free[rng.integers(len(free), size=2)]
        start, goal = (int(sx), int(sy)), (int(gx), int(gy))
        for fast, slow in PAIRS:
            assert_same_search(fast(graph, start, goal), slow(graph, start, goal),
                               bidirectional=fast in BIDIRECTIONAL)


@pytest.mark.parametrize("seed", range(4))
def test_general_graphs_and_path_maps_same_as_reference(seed):
    rng = np.random.default_rng(400 + seed)
    graphs = [geometric_graph(rng, 40, radius=3.0, density=0.7, stretch=(1.0, 1.5)),
              path_map_graph(random_path_map(8, 6, seed, extra=0.3))]
    for graph in graphs:
        for source, target in rng.integers(graph.num_nodes, size=(15, 2)):
            for fast, slow in PAIRS:
                for heuristic in (["euclidean", "zero"] if fast is not dijkstra else [None]):
                    options = {} if heuristic is None else {"heuristic": heuristic}
                    assert_same_search(fast(graph, int(source), int(target), **options),
                                       slow(graph, int(source), int(target), **options),
                                       bidirectional=fast in BIDIRECTIONAL)


@pytest.mark.parametrize("heuristic", [None, "zero", "euclidean"])
def test_batch_equals_one_query_at_a_time(heuristic):
    rng = np.random.default_rng(8)
    obstacles = rng.random((25, 35)) < 0.3
    graph = grid_graph(obstacles)
    free = np.argwhere(~obstacles)[:, ::-1]  # (x, y)
    starts, goals = free[rng.integers(len(free), size=40)], free[rng.integers(len(free), size=40)]
    batch = shortest_lengths(graph, starts, goals, heuristic=heuristic)
    assert batch.cost.shape == batch.found.shape == batch.stats.expanded.shape == (40,)
    for q in range(40):
        one = astar(graph, tuple(starts[q]), tuple(goals[q]), heuristic=heuristic)
        assert batch.cost[q] == one.cost and batch.found[q] == one.found
        assert batch.stats.expanded[q] == one.stats.expanded
        assert batch.stats.generated[q] == one.stats.generated
    # Node indices work as well as cells.
    width = graph.shape[1]
    by_node = shortest_lengths(graph, starts[:, 1] * width + starts[:, 0],
                               goals[:, 1] * width + goals[:, 0], heuristic=heuristic)
    np.testing.assert_array_equal(by_node.cost, batch.cost)


def test_batch_errors_name_the_query():
    obstacles = np.zeros((4, 5), bool)
    obstacles[2, 3] = True
    graph = grid_graph(obstacles)
    with pytest.raises(ValueError, match=r"goals\[1\] \[3, 2\] is blocked"):
        shortest_lengths(graph, np.array([[0, 0], [1, 1]]), np.array([[4, 3], [3, 2]]))
    with pytest.raises(ValueError, match=r"starts\[0\] \(5, 0\) is off the 5x4 map"):
        shortest_lengths(graph, np.array([[5, 0]]), np.array([[0, 0]]))
    with pytest.raises(ValueError, match="as many queries"):
        shortest_lengths(graph, np.array([[0, 0]]), np.array([[1, 1], [2, 2]]))
    with pytest.raises(ValueError, match=r"i\[Q, 2\]"):
        shortest_lengths(graph, np.zeros((2, 3), int), np.zeros((2, 3), int))


def test_unreachable_goals_in_a_batch():
    obstacles = np.zeros((5, 5), bool)
    obstacles[:, 2] = True
    batch = shortest_lengths(grid_graph(obstacles), np.array([[0, 0], [0, 0]]),
                             np.array([[4, 4], [1, 4]]))
    assert not batch.found[0] and np.isinf(batch.cost[0])
    assert batch.found[1]
    assert batch.cost[1] == astar(grid_graph(obstacles), (0, 0), (1, 4)).cost


def test_labels_are_cleared_when_the_stamps_run_out():
    graph = grid_graph(np.zeros((6, 6), bool))
    work = workspace(edge_arrays(graph))
    before = astar(graph, (0, 0), (5, 5))
    work.stamp = np.iinfo(np.int32).max - 1  # the next search must clear the labels first
    after = astar(graph, (0, 0), (5, 5))
    assert after.cost == before.cost and after.stats.expanded == before.stats.expanded
    assert work.stamp == 1


def test_warm_up_compiles_every_planner():
    """Every compiled search loop of the exact planners (numba dispatchers not inlined into
    another) has a compiled signature once ``warm_up`` returns."""
    seconds = warm_up()
    loops = {f"{module.__name__}.{name}": dispatcher
             for module in (kernels, dstar_lite) for name, dispatcher in vars(module).items()
             if isinstance(dispatcher, numba.core.dispatcher.Dispatcher)
             and dispatcher.targetoptions.get("inline") != "always"}
    assert len(loops) >= 6, sorted(loops)
    assert not [name for name, loop in loops.items() if not loop.signatures]
    assert 0.0 < seconds < 600.0
