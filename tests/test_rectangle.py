"""Rectangle reasoning for CBS (jaxswarm.multiagent.rectangle, cbs's ``rectangle``): the barriers
by hand, where the split does not apply, optimality against the joint-state search, and 50 agents
on an empty map that CBSH-TC does not solve in many more nodes."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

import oracle
from jaxswarm.multiagent import PLANNERS, cbs, load_instance, validate
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


# Random small grids (as drawn below) whose CBS search takes a rectangle split.
SPLIT_SEEDS = [9, 23, 31, 62, 70, 88, 114, 118, 175, 196]


@pytest.mark.parametrize("seed", SPLIT_SEEDS)
def test_rectangle_reasoning_is_optimal_on_small_grids_where_it_splits(seed):
    rng = np.random.default_rng(seed)
    width, height = int(rng.integers(3, 7)), int(rng.integers(3, 6))
    blocked = rng.random((height, width)) < 0.08
    free = [(x, y) for y in range(height) for x in range(width) if not blocked[y, x]]
    agents = int(rng.integers(2, 4))
    picks = rng.choice(len(free), size=2 * agents, replace=False)
    starts, goals = [free[i] for i in picks[:agents]], [free[i] for i in picks[agents:]]
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


def test_rectangles_solve_fifty_agents_on_an_empty_map_in_few_nodes(movingai_dir):
    # CBSH-RTC needs 37 nodes here; CBSH-TC ran out of 30 s (7,310 nodes).
    mapf = movingai_dir / "mapf"
    instance = load_instance(mapf / "empty-32-32.map", mapf / "empty-32-32-random-1.scen", 50)
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    reasoned = PLANNERS["cbsh_rtc"](graph, starts, goals, time_limit=60)
    assert reasoned.solved and reasoned.stats["rectangles"] > 0
    assert reasoned.sum_of_costs == reasoned.stats["lower_bound"]
    assert validate(graph, reasoned.paths, starts, goals, reasoned.lengths) == []
    without = PLANNERS["cbsh_tc"](graph, starts, goals, max_nodes=5 * reasoned.stats["nodes"])
    assert not without.solved
