"""Rectangle reasoning for CBS (jaxswarm.multiagent.rectangle, cbs's ``rectangle``): the barriers
by hand, where the split does not apply, optimality against the joint-state search, every pair of
walks breaking both barriers colliding (brute force), and 50 agents on an empty map that CBSH-TC
does not solve in many more nodes."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

import oracle
from jaxswarm.multiagent import cbs, load_instance, registry, validate
from jaxswarm.multiagent.constraints import Constraints
from jaxswarm.multiagent.plan import pack
from jaxswarm.multiagent.rectangle import Rectangles
from jaxswarm.world.graph import grid_graph
from jaxswarm.world.paths import as_node


def _split(graph, cells_a, cells_b, step):
    """Rectangles' split of two agents on the paths of ``cells_a`` and ``cells_b`` ((x, y)
    lists, from start to goal) colliding at ``step``."""
    paths = tuple(np.array([as_node(graph, cell) for cell in cells], np.int32)
                  for cells in (cells_a, cells_b))
    return Rectangles(graph).split((Constraints(), Constraints()), paths, step,
                                   pack(list(paths))[0])


def test_the_barriers_of_two_agents_crossing_an_open_grid_by_hand():
    graph = grid_graph(np.zeros((5, 5), bool), connectivity=4)
    node = lambda x, y: as_node(graph, (x, y))  # noqa: E731
    # Agent 0 crosses rows 0 -> 4 within columns 1..3, agent 1 columns 0 -> 4 within rows 1..3;
    # both meet (1, 1) at step 1. The rectangle is x, y in 1..3: agent 0 leaves it through row 3
    # and agent 1 through column 3, each at the step its start's distance gives.
    down = [(1, 0), (1, 1), (2, 1), (2, 2), (3, 2), (3, 3), (3, 4)]
    across = [(0, 1), (1, 1), (1, 2), (2, 2), (2, 3), (3, 3), (4, 3)]
    first, second = _split(graph, down, across, step=1)
    assert first == Constraints(vertex=frozenset({(3, node(1, 3)), (4, node(2, 3)),
                                                  (5, node(3, 3))}))
    assert second == Constraints(vertex=frozenset({(3, node(3, 1)), (4, node(3, 2)),
                                                   (5, node(3, 3))}))
    # The same split with the agents' order swapped, and mirrored left to right.
    assert _split(graph, across, down, step=1) == (second, first)
    mirror = lambda cells: [(4 - x, y) for x, y in cells]  # noqa: E731
    flipped = _split(graph, mirror(down), mirror(across), step=1)
    assert flipped[0].vertex == {(t, node(4 - v % 5, v // 5)) for t, v in first.vertex}


def test_no_rectangle_for_a_swap_a_head_on_meeting_or_moves_that_are_not_four_way():
    graph = grid_graph(np.zeros((3, 5), bool), connectivity=4)
    left, right = [(0, 1), (1, 1), (2, 1), (3, 1)], [(3, 1), (2, 1), (1, 1), (0, 1)]
    assert _split(graph, left, right, step=2) is None  # they swap between steps 1 and 2
    assert _split(graph, left[:3], [(4, 1), (3, 1), (2, 1)], step=2) is None  # head-on
    assert not Rectangles(grid_graph(np.zeros((3, 5), bool), connectivity=8)).usable


# Random small grids (as :func:`_small_instance` draws them) whose CBS search takes a rectangle
# split.
SPLIT_SEEDS = [9, 23, 31, 62, 70, 88, 114, 118, 175, 196]


def _small_instance(seed: int):
    """``(blocked, starts, goals)``: a random grid of 3 to 6 x 3 to 5 cells with 2 or 3
    agents."""
    rng = np.random.default_rng(seed)
    width, height = int(rng.integers(3, 7)), int(rng.integers(3, 6))
    blocked = rng.random((height, width)) < 0.08
    free = [(x, y) for y in range(height) for x in range(width) if not blocked[y, x]]
    agents = int(rng.integers(2, 4))
    picks = rng.choice(len(free), size=2 * agents, replace=False)
    return blocked, [free[i] for i in picks[:agents]], [free[i] for i in picks[agents:]]


@pytest.mark.parametrize("seed", SPLIT_SEEDS)
def test_rectangle_reasoning_is_optimal_on_small_grids_where_it_splits(seed):
    blocked, starts, goals = _small_instance(seed)
    graph = grid_graph(blocked, connectivity=4)
    optimum = oracle.mapf_optimum(oracle.grid_adjacency(blocked.tolist(), connectivity=4),
                                  starts, goals)
    split = False
    for wdg, target in itertools.product((False, True), repeat=2):
        plan = cbs(graph, starts, goals, prioritize=True, bypass=True, rectangle=True, wdg=wdg,
                   target=target)
        assert plan.solved and plan.sum_of_costs == optimum == plan.stats["lower_bound"]
        assert validate(graph, plan.paths, starts, goals, plan.lengths) == []
        split |= plan.stats["rectangles"] > 0
    assert split


def _every_walk(blocked: np.ndarray, start: tuple[int, int], steps: int) -> np.ndarray:
    """i64[P, steps + 1] the node (y * width + x) of every walk of ``steps`` moves or waits from
    ``start`` on the free cells of ``blocked``."""
    height, width = blocked.shape
    moves = np.array([(0, 0), (1, 0), (-1, 0), (0, 1), (0, -1)])
    choice = np.array(list(itertools.product(range(5), repeat=steps))).reshape(-1, steps)
    cells = np.concatenate([np.broadcast_to(start, (len(choice), 1, 2)),
                            start + np.cumsum(moves[choice], axis=1)], axis=1)
    x, y = cells[..., 0], cells[..., 1]
    inside = ((x >= 0) & (x < width) & (y >= 0) & (y < height)).all(axis=1)
    x, y = x[inside], y[inside]
    free = ~blocked[y, x].any(axis=1)
    return (y * width + x)[free]


def _breaks(walks: np.ndarray, barrier: frozenset) -> np.ndarray:
    """bool[P]: the walks (i64[P, T]) on a barrier's node at its step."""
    return np.any([walks[:, t] == v for t, v in barrier], axis=0)


def _cluttered_instance(seed: int):
    """``(blocked, starts, goals)``: a random grid of 4 to 6 x 4 or 5 cells, a quarter of them
    blocked, with 2 agents."""
    rng = np.random.default_rng(seed)
    width, height = int(rng.integers(4, 7)), int(rng.integers(4, 6))
    blocked = rng.random((height, width)) < 0.25
    free = [(x, y) for y in range(height) for x in range(width) if not blocked[y, x]]
    picks = rng.choice(len(free), size=4, replace=False)
    return blocked, [free[i] for i in picks[:2]], [free[i] for i in picks[2:]]


# The cluttered seeds are grids where barriers without the shortest-path conditions (every
# cell of the side at its Manhattan step from the entry) let two walks break both and not
# collide.
@pytest.mark.parametrize("instance", [_small_instance(seed) for seed in SPLIT_SEEDS]
                         + [_cluttered_instance(seed) for seed in (143, 916)],
                         ids=[f"small-{seed}" for seed in SPLIT_SEEDS]
                         + [f"cluttered-{seed}" for seed in (143, 916)])
def test_two_walks_that_both_break_their_barriers_collide(instance, monkeypatch):
    # Every rectangle split the search makes, checked against every pair of walks of the two
    # agents up to the barriers' last step: none that breaks both barriers is collision-free,
    # so every solution keeps one child's constraints.
    blocked, starts, goals = instance
    graph = grid_graph(blocked, connectivity=4)
    splits, split = [], Rectangles.split

    def recorded(self, constraints, paths, step, padded):
        both = split(self, constraints, paths, step, padded)
        if both is not None:
            splits.append(([int(path[0]) for path in paths],
                           [both[i].vertex - constraints[i].vertex for i in (0, 1)]))
        return both

    monkeypatch.setattr(Rectangles, "split", recorded)
    assert cbs(graph, starts, goals, prioritize=True, bypass=True, rectangle=True).solved
    assert splits
    width = blocked.shape[1]
    for start_nodes, barriers in splits:
        steps = max(t for barrier in barriers for t, _ in barrier)
        walks = [_every_walk(blocked, (s % width, s // width), steps) for s in start_nodes]
        first, second = (walks[i][_breaks(walks[i], barriers[i])] for i in (0, 1))
        assert len(first) and len(second)
        on_one_node = (first[:, None, :] == second[None, :, :]).any(axis=2)
        swapping = ((first[:, None, :-1] == second[None, :, 1:])
                    & (first[:, None, 1:] == second[None, :, :-1])).any(axis=2)
        assert (on_one_node | swapping).all()


def test_rectangles_solve_fifty_agents_on_an_empty_map_in_few_nodes(movingai_dir):
    # CBSH-RTC needs 37 nodes here; CBSH-TC ran out of 30 s (7,310 nodes).
    mapf = movingai_dir / "mapf"
    instance = load_instance(mapf / "empty-32-32.map", mapf / "empty-32-32-random-1.scen", 50)
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    reasoned = registry.plan("cbsh_rtc", graph, starts, goals, time_limit=60)
    assert reasoned.solved and reasoned.stats["rectangles"] > 0
    assert reasoned.sum_of_costs == reasoned.stats["lower_bound"]
    assert validate(graph, reasoned.paths, starts, goals, reasoned.lengths) == []
    without = registry.plan("cbsh_tc", graph, starts, goals, max_nodes=5 * reasoned.stats["nodes"])
    assert not without.solved
