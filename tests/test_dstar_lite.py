"""D* Lite: every answer after random edits, moves of the start and moves of the goal equals
Dijkstra from scratch on the edited map."""
import dataclasses

import jax
import numpy as np
import pytest

from conftest import MOVINGAI
from graphs import geometric_graph
from jaxswarm.exact import astar, dijkstra, replanner
from jaxswarm.maps.movingai import load_map
from jaxswarm.world.graph import grid_graph


# The map edits of jaxswarm.world.edits, made in NumPy: outside jit, an edit compiles a few
# operations for each new map shape, and nearly every map here has a shape of its own. The edits
# themselves are checked in test_edits.py.
def set_cells(graph, nodes, free: bool):
    """``graph`` with ``free[nodes] = free`` (``block_cells``: False, ``unblock_cells``: True)."""
    cells = np.array(graph.free)
    cells[nodes] = free
    return dataclasses.replace(graph, free=jax.device_put(cells))


def set_edges(graph, nodes, slots, is_open: bool):
    """``graph`` with each edge ``nodes[m] -> nbr[nodes[m], slots[m]]`` and its reverse open
    (``open_edges``: True) or closed (``close_edges``: False); slots without a neighbour are left
    alone."""
    edges = np.array(graph.open)
    nbr, rev = np.asarray(graph.nbr), np.asarray(graph.rev)
    for node, slot in zip(nodes, slots):
        if nbr[node, slot] >= 0:
            edges[node, slot] = is_open
            if rev[node, slot] >= 0:
                edges[nbr[node, slot], rev[node, slot]] = is_open
    return dataclasses.replace(graph, open=jax.device_put(edges))


def check(solution, graph, start, goal):
    expected = dijkstra(graph, start, goal)
    assert bool(solution.found) == bool(expected.found)
    if expected.found:
        assert solution.cost == pytest.approx(expected.cost, rel=1e-12, abs=1e-12)
        nodes = solution.nodes()
        assert nodes[0] == start and nodes[-1] == goal
        assert solution.cost == pytest.approx(astar(graph, start, goal).cost, rel=1e-12)
    else:
        assert np.isinf(solution.cost) and (np.asarray(solution.path) == -1).all()


def random_edits(rng, graph, planner, start, goal, steps):
    """Apply ``steps`` random edits (block or unblock cells, close or open edges, move the
    goal, step the start along its path) and check every answer; returns how many."""
    solution = planner.solve()
    check(solution, graph, start, goal)
    for _ in range(steps):
        free = np.asarray(graph.free)
        move = {}
        kind = rng.integers(6)
        if kind == 0:
            candidates = np.setdiff1d(np.nonzero(free)[0], [start, goal])
            if candidates.size:
                graph = set_cells(graph, rng.choice(candidates, min(candidates.size, 3),
                                                    replace=False), False)
        elif kind == 1 and (~free).any():
            graph = set_cells(graph, rng.choice(np.nonzero(~free)[0], 2), True)
        elif kind == 2:
            nodes = rng.integers(graph.num_nodes, size=3)
            graph = set_edges(graph, nodes, rng.integers(graph.max_degree, size=3), False)
        elif kind == 3:
            nodes = rng.integers(graph.num_nodes, size=3)
            graph = set_edges(graph, nodes, rng.integers(graph.max_degree, size=3), True)
        elif kind == 4:
            goal = int(rng.choice(np.nonzero(free)[0]))
            move["goal"] = goal
        elif solution.found and solution.nodes().size > 1:
            start = int(solution.nodes()[1])
            move["start"] = start
        solution = planner.update(graph, **move)
        check(solution, graph, start, goal)
    return steps


@pytest.mark.parametrize("seed", range(12))
def test_random_edit_sequences_on_random_grids(seed):
    rng = np.random.default_rng(seed)
    height, width = rng.integers(4, 18, size=2)
    obstacles = rng.random((height, width)) < rng.uniform(0.05, 0.35)
    graph = grid_graph(obstacles, connectivity=[4, 8][seed % 2], corner_cutting=seed % 3 == 0)
    free = np.nonzero(np.asarray(graph.free))[0]
    start, goal = (int(v) for v in rng.choice(free, 2))
    random_edits(rng, graph, replanner(graph, start, goal), start, goal, steps=25)


@pytest.mark.parametrize("seed", range(3))
def test_random_edit_sequences_on_directed_general_graphs(seed):
    rng = np.random.default_rng(50 + seed)
    graph = geometric_graph(rng, 30, radius=4.0, density=0.6, stretch=(1.2, 1.2))
    start, goal = (int(v) for v in rng.choice(30, 2, replace=False))
    random_edits(rng, graph, replanner(graph, start, goal), start, goal, steps=25)


@pytest.mark.slow  # every edit sequence on two large maps
@pytest.mark.parametrize("name", ["den312d", "maze-32-32-4"])
def test_random_edit_sequences_on_movingai_maps(movingai_dir, name):
    graph = load_map(MOVINGAI / "mapf" / f"{name}.map")
    rng = np.random.default_rng(7)
    free = np.nonzero(np.asarray(graph.free))[0]
    for _ in range(3):
        start, goal = (int(v) for v in rng.choice(free, 2))
        random_edits(rng, graph, replanner(graph, start, goal), start, goal, steps=12)


def test_repair_touches_less_than_a_fresh_search():
    rng = np.random.default_rng(3)
    obstacles = rng.random((60, 60)) < 0.2
    obstacles[0, 0] = obstacles[-1, -1] = False
    graph = grid_graph(obstacles)
    planner = replanner(graph, (0, 0), (59, 59))
    first = planner.solve()
    assert first.stats.touched > 0 and first.stats.expanded > 0
    on_path = first.nodes()[len(first.nodes()) // 2]
    edited = set_cells(graph, on_path, False)
    repaired = planner.update(edited)
    check(repaired, edited, 0, 59 * 60 + 59)
    assert 0 < repaired.stats.touched < first.stats.touched
    # Nothing changed: nothing to do.
    again = planner.update(edited)
    assert again.stats.iterations == 0 and again.stats.touched == 0
    assert again.cost == repaired.cost


def test_goal_move_restarts_and_start_equals_goal():
    graph = grid_graph(np.zeros((5, 5), bool))
    planner = replanner(graph, (0, 0), (4, 4))
    assert planner.solve().cost == pytest.approx(4 * np.sqrt(2))
    same = planner.update(goal=(0, 0))
    assert same.found and same.cost == 0.0 and same.nodes().tolist() == [0]
    moved = planner.update(goal=(4, 0))
    assert moved.cost == 4.0 and moved.stats.touched >= 5


def test_an_unreachable_goal_becomes_reachable():
    obstacles = np.zeros((5, 5), bool)
    obstacles[:, 2] = True
    graph = grid_graph(obstacles)
    planner = replanner(graph, (0, 0), (4, 4))
    assert not planner.solve().found
    opened = set_cells(graph, [2 * 5 + 2], True)
    check(planner.update(opened), opened, 0, 24)


def test_bad_updates_are_named():
    obstacles = np.zeros((4, 4), bool)
    graph = grid_graph(obstacles)
    planner = replanner(graph, (0, 0), (3, 3))
    with pytest.raises(ValueError, match="start .* is blocked"):
        planner.update(set_cells(graph, [0], False))
    with pytest.raises(ValueError, match="goal .* is blocked"):
        planner.update(set_cells(graph, [5], False), goal=(1, 1))
    with pytest.raises(ValueError, match="same map"):
        planner.update(grid_graph(np.zeros((4, 5), bool)))
    with pytest.raises(ValueError, match="off the 4x4 map"):
        planner.update(start=(7, 0))
    with pytest.raises(ValueError, match="unknown heuristic"):
        replanner(graph, (0, 0), (3, 3), heuristic="manhattan")
    # A refused update leaves the planner as it was.
    assert planner.solve().cost == pytest.approx(3 * np.sqrt(2))
