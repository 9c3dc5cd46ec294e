"""PIBT and LaCAM: PIBT's step by hand and against the rules of a configuration, LaCAM against
the joint-state search on tiny instances (a solution exactly when one exists; "no solution" only
when there is none), LaCAM* to the joint-state optimum, and both on benchmark instances against
the validator."""
from __future__ import annotations

import collections
import heapq
import itertools
import math

import numpy as np
import pytest

import oracle
from jaxswarm.multiagent import (hop_fields, lacam, load_instance, lower_bound, pibt,
                                 prioritized, validate)
from jaxswarm.multiagent.constraint_trees import NONE, ConstraintTrees, gather, plant, take
from jaxswarm.multiagent.pibt import Moves, Workspace, by_priority, configuration
from jaxswarm.world.graph import grid_graph

NOTHING = np.zeros(0, np.int32)


def grid(rows):
    blocked = np.array([[c == "#" for c in row] for row in rows])
    return grid_graph(blocked, connectivity=4), oracle.grid_adjacency(blocked.tolist(),
                                                                       connectivity=4)


def step(graph, current, goals, order, fixed=NOTHING, fixed_to=NOTHING, seed=0, swap=False):
    current, goals = np.asarray(current, np.int32), np.asarray(goals, np.int32)
    moves = Moves.build(graph, goals, hop_fields(graph, goals))
    following = np.empty_like(current)
    ok = configuration(moves, Workspace(moves, seed), current, np.asarray(order, np.int32),
                       np.asarray(fixed, np.int32), np.asarray(fixed_to, np.int32), following,
                       swap=swap)
    return ok, following.tolist()


def test_a_pushed_agent_inherits_the_priority_and_steps_aside():
    # A corridor 0-1-2 with a pocket 4 under node 1. Agent 0 (first) at 0 is bound for 2;
    # agent 1 rests at its goal 1. Agent 0 takes 1, so agent 1 must leave: back to 0 would swap
    # with agent 0, so it goes on to 2 or into the pocket (as near its goal, a keyed tie).
    graph, _ = grid(["...", "#.#"])
    ok, following = step(graph, [0, 1], [2, 1], order=[0, 1])
    assert ok and following[0] == 1 and following[1] in (2, 4)
    # With agent 1 first, it keeps its goal and agent 0 waits.
    ok, following = step(graph, [0, 1], [2, 1], order=[1, 0])
    assert ok and following == [0, 1]


@pytest.mark.parametrize("swap", [False, True])
def test_a_step_is_a_configuration_on_random_instances(swap):
    rng = np.random.default_rng(4)
    graph, _ = grid(["......", ".#..#.", "......", "..##..", "......"])
    free = np.nonzero(np.asarray(graph.free))[0]
    nbr = np.asarray(graph.nbr)
    for trial in range(40):
        picks = rng.permutation(free)
        agents = int(rng.integers(2, 12))
        current, goals = picks[:agents], rng.permutation(free)[:agents]
        ok, following = step(graph, current, goals, rng.permutation(agents), seed=trial,
                             swap=swap)
        following = np.array(following)
        assert ok
        assert len(set(following.tolist())) == agents  # no two on one node
        for a in range(agents):
            assert following[a] == current[a] or following[a] in nbr[current[a]]  # a move
            for b in range(agents):
                assert not (a != b and following[a] == current[b]
                            and following[b] == current[a])  # no swap


def test_fixed_moves_are_kept_and_colliding_ones_refused():
    graph, _ = grid(["...."])
    ok, following = step(graph, [0, 2], [3, 0], order=[0, 1], fixed=[1], fixed_to=[1])
    assert ok and following[1] == 1 and following[0] == 0  # agent 0 gives way
    ok, _ = step(graph, [0, 2], [3, 0], order=[0, 1], fixed=[0, 1], fixed_to=[1, 1])
    assert not ok  # two agents on node 1
    ok, _ = step(graph, [0, 1], [1, 0], order=[0, 1], fixed=[0, 1], fixed_to=[1, 0])
    assert not ok  # a swap
    ok, _ = step(graph, [0, 1], [3, 0], order=[1, 0], fixed=[1], fixed_to=[0])
    assert not ok  # agent 0 has nowhere to go but node 1, swapping with agent 1


def test_priorities_put_the_longest_waiting_first():
    assert by_priority(np.array([0.5, 2.25, 2.25, 1.0])).tolist() == [1, 2, 3, 0]


def test_a_constraint_tree_enumerates_every_combination_of_moves_once_breadth_first():
    # Nodes 0 1 2 / 3 # 5. The tree orders the agents by priority (agent 1, then 0 and 2, tied,
    # by number); a constraint at depth d fixes the first d of them, each to its neighbours or
    # its own node, and the root's children come in the order NumPy's Generator.shuffle gives
    # the list of the first agent's candidates.
    graph, adjacency = grid(["...", ".#."])
    current = np.array([0, 2, 3], np.int32)
    moves = Moves.build(graph, current, hop_fields(graph, current))
    trees = ConstraintTrees(agents=3)
    trees.reserve(1, 64)
    tree = plant(trees.arrays, np.array([0.5, 2.0, 0.5]))
    assert trees.order[tree].tolist() == [1, 0, 2]
    rng = np.random.default_rng(3)
    options, who, where = (np.empty(n, np.int32) for n in (moves.candidates, 3, 3))
    taken = collections.defaultdict(list)  # depth: the nodes of each constraint taken
    depths = []
    while (constraint := take(trees.arrays, tree, moves.indptr, moves.heads, current, options,
                              rng)) != NONE:
        depth = gather(trees.arrays, constraint, who, where)
        assert who[:depth].tolist() == [1, 0, 2][:depth]
        taken[depth].append(tuple(where[:depth].tolist()))
        depths.append(depth)
    assert depths == sorted(depths)
    candidates = [[y * 3 + x for (x, y), _ in adjacency[(u % 3, u // 3)]] + [u]
                  for u in current[[1, 0, 2]].tolist()]
    for depth in range(4):
        combinations = list(itertools.product(*candidates[:depth]))
        assert sorted(taken[depth]) == sorted(combinations)  # each once
    first = moves.heads[moves.indptr[2]:moves.indptr[3]].tolist() + [2]
    np.random.default_rng(3).shuffle(first)
    assert [nodes[0] for nodes in taken[1]] == first


TINY = [  # (obstacle rows, starts, goals): the joint-state search's instances of test_multiagent
    (["....", ".#..", "....", "...."], [(0, 0), (2, 0)], [(2, 0), (0, 0)]),
    (["....", "##.#", "....", "...."], [(0, 0), (3, 0), (2, 3)], [(3, 0), (0, 0), (2, 0)]),
    (["#..#", "#.##", "#...", "...."], [(1, 0), (0, 3)], [(3, 2), (2, 0)]),
    (["....", "....", "....", "...."], [(0, 0), (1, 0), (2, 0)], [(2, 0), (0, 0), (1, 0)]),
    (["...", "#.#"], [(2, 0), (0, 0)], [(1, 0), (2, 0)]),  # prioritised fails in both orders
]


@pytest.mark.parametrize("rows, starts, goals", TINY)
def test_lacam_solves_and_lacam_star_reaches_the_joint_state_optimum(rows, starts, goals):
    graph, adjacency = grid(rows)
    optimum = oracle.mapf_optimum(adjacency, starts, goals)
    first = lacam(graph, starts, goals)
    assert first.solved and validate(graph, first.paths, starts, goals, first.lengths) == []
    assert first.sum_of_costs >= optimum
    refined = lacam(graph, starts, goals, refine=30.0)
    assert refined.solved and refined.stats["optimal"]  # the search ran out: nothing better
    assert refined.sum_of_costs == optimum <= refined.stats["first_soc"]
    assert validate(graph, refined.paths, starts, goals, refined.lengths) == []


def test_lacam_solves_where_prioritized_planning_fails_in_both_orders():
    graph, _ = grid(["...", "#.#"])
    starts, goals = [(2, 0), (0, 0)], [(1, 0), (2, 0)]
    assert not any(prioritized(graph, starts, goals, order=o).solved for o in ([0, 1], [1, 0]))
    assert lacam(graph, starts, goals).solved


def test_lacam_proves_there_is_no_solution():
    graph, adjacency = grid(["...."])  # two agents swapping ends of a corridor
    starts, goals = [(0, 0), (3, 0)], [(3, 0), (0, 0)]
    assert oracle.mapf_optimum(adjacency, starts, goals) is None
    plan = lacam(graph, starts, goals)
    assert not plan.solved and plan.reason.startswith("no solution: every configuration")
    assert plan.stats["configurations"] == 6  # ({0..3} choose 2 with 0 left of 1)


@pytest.mark.parametrize("swap", [False, True])
def test_lacam_finds_a_solution_exactly_when_the_joint_state_search_does(swap):
    rng = np.random.default_rng(1)
    solved = unsolvable = 0
    for _ in range(40):
        height, width = rng.integers(2, 4, size=2)
        blocked = rng.random((height, width)) < 0.25
        free = [(x, y) for y in range(height) for x in range(width) if not blocked[y, x]]
        agents = int(rng.integers(2, 4))
        if len(free) <= agents:
            continue
        starts = [free[i] for i in rng.permutation(len(free))[:agents]]
        goals = [free[i] for i in rng.permutation(len(free))[:agents]]
        graph = grid_graph(blocked, connectivity=4)
        optimum = oracle.mapf_optimum(oracle.grid_adjacency(blocked.tolist(), connectivity=4),
                                      starts, goals)
        plan = lacam(graph, starts, goals, swap=swap)
        assert plan.solved == (optimum is not None), (blocked, starts, goals, plan.reason)
        if plan.solved:
            assert validate(graph, plan.paths, starts, goals, plan.lengths) == []
            assert plan.sum_of_costs >= optimum
            solved += 1
        else:
            unsolvable += 1
    assert solved >= 15 and unsolvable >= 5


def test_a_limit_ends_lacam_cleanly_and_a_seed_replays():
    graph, _ = grid(["....", ".#..", "....", "...."])
    starts, goals = [(0, 0), (2, 0), (3, 3)], [(2, 0), (0, 0), (0, 3)]
    limited = lacam(graph, starts, goals, max_configurations=2)
    assert not limited.solved and limited.reason == "reached the limit of 2 configurations"
    again = [lacam(graph, starts, goals, seed=7).paths for _ in range(2)]
    assert np.array_equal(*again)
    with pytest.raises(ValueError, match="refine must be at least 0, got -1"):
        lacam(graph, starts, goals, refine=-1)


def test_pibt_reaches_the_goals_on_an_open_map_and_stops_at_its_limit():
    graph, _ = grid(["......"] * 6)
    starts = [(x, 0) for x in range(6)]
    goals = [(5 - x, 5) for x in range(6)]
    plan = pibt(graph, starts, goals)
    assert plan.solved and validate(graph, plan.paths, starts, goals, plan.lengths) == []
    assert plan.sum_of_costs >= lower_bound(graph, starts, goals)
    corridor, _ = grid(["...."])
    stuck = pibt(corridor, [(0, 0), (3, 0)], [(3, 0), (0, 0)], max_steps=20)
    assert not stuck.solved and "after 20 steps" in stuck.reason
    assert stuck.paths.shape[1] == 21


@pytest.mark.parametrize("name, agents", [("random-32-32-10", 100), ("room-32-32-4", 100)])
def test_lacam_and_pibt_on_benchmark_instances_validate(movingai_dir, name, agents):
    mapf = movingai_dir / "mapf"
    instance = load_instance(mapf / f"{name}.map", mapf / f"{name}-random-1.scen", agents)
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    bound = lower_bound(graph, starts, goals)
    plan = lacam(graph, starts, goals, time_limit=60)
    assert plan.solved and validate(graph, plan.paths, starts, goals, plan.lengths) == []
    assert plan.sum_of_costs >= bound and plan.stats["field_seconds"] > 0
    stepped = pibt(graph, starts, goals)
    if stepped.solved:
        assert validate(graph, stepped.paths, starts, goals, stepped.lengths) == []


def test_two_agents_head_on_in_a_corridor_swap_where_it_widens():
    # A corridor 0..4 that widens at node 3 (a side cell under it). Agent 0 at 2 is bound for the
    # dead end 0, agent 1 at 1 for 4: head on, they can only pass at node 3. With the swap
    # operation agent 0 (first) steps back to 3 and pulls agent 1 onto 2; plain PIBT pushes
    # agent 1 into the dead end instead.
    graph, _ = grid([".....", "###.#"])
    ok, following = step(graph, [2, 1], [0, 4], order=[0, 1], swap=True)
    assert ok and following == [3, 2]
    ok, following = step(graph, [2, 1], [0, 4], order=[0, 1])
    assert ok and following == [1, 0]
    starts, goals = [(2, 0), (1, 0)], [(0, 0), (4, 0)]
    plain, swapped = (lacam(graph, starts, goals, swap=s) for s in (False, True))
    assert plain.solved and swapped.solved and swapped.planner == "lacam_star"
    for plan in (plain, swapped):
        assert validate(graph, plan.paths, starts, goals, plan.lengths) == []


@pytest.mark.parametrize("option, value, error, message", [
    ("time_limit", -1, ValueError, "time_limit must be positive, got -1"),
    ("time_limit", float("nan"), ValueError, "time_limit must be positive, got nan"),
    ("time_limit", "5", TypeError, "time_limit must be a number of seconds, got '5'"),
    ("refine", float("nan"), ValueError, "refine must be at least 0, got nan"),
    ("refine", None, TypeError, "refine must be a number, got None"),
    ("max_configurations", 2.5, TypeError, "max_configurations must be an integer, got 2.5"),
    ("max_configurations", 0, ValueError, "max_configurations must be at least 1, got 0"),
    ("seed", -1, ValueError, "seed must be at least 0, got -1"),
    ("seed", 1.5, TypeError, "seed must be an integer, got 1.5"),
    ("swap", "yes", TypeError, "swap must be True or False, got 'yes'"),
    ("restart_rate", 2, ValueError, "restart_rate must be between 0 and 1, got 2"),
])
def test_lacam_refuses_a_bad_option_naming_it_before_any_search(option, value, error, message):
    graph, _ = grid(["...."])
    with pytest.raises(error, match=f"^{message}$"):
        lacam(graph, [(0, 0)], [(3, 0)], **{option: value})


def sum_of_loss(paths, goals):
    """Agents not resting at their goals, summed over the steps of ``paths`` (i32[A, T])."""
    paths, goals = np.asarray(paths), np.asarray(goals)[:, None]
    return int(((paths[:, :-1] != goals) | (paths[:, 1:] != goals)).sum())


def is_a_solution(blocked, paths, starts, goals):
    """Whether ``paths`` (i32[A, T], node indices ``y * width + x``) go from the starts to the
    goals on free cells of ``blocked``, one orthogonal move or a wait per step, with no two agents
    on one cell and no two exchanging cells (the rules written out again, in NumPy)."""
    width = blocked.shape[1]
    paths = np.asarray(paths)
    y, x = np.divmod(paths, width)
    before, after = paths[:, :-1], paths[:, 1:]
    exchanged = (before[:, None] == after[None, :]) & (after[:, None] == before[None, :])
    exchanged &= ~np.eye(len(paths), dtype=bool)[:, :, None]
    return bool(paths[:, 0].tolist() == list(starts) and paths[:, -1].tolist() == list(goals)
                and not blocked[y, x].any()
                and (np.abs(np.diff(y)) + np.abs(np.diff(x)) <= 1).all()
                and all(len(set(column)) == len(column) for column in paths.T.tolist())
                and not exchanged.any())


def least_sum_of_loss(blocked, starts, goals):
    """The least sum of loss by Dijkstra over configurations (node tuples), or None.

    Written apart from LaCAM: every agent waits or takes one of its 4 neighbours per step; no two
    agents on one node, no two exchanging nodes; a step costs the agents not resting at their
    goals through it (on the node before and the node after). ``starts``, ``goals``: node indices
    ``y * width + x``."""
    height, width = blocked.shape

    def moves(node):
        y, x = divmod(node, width)
        out = [node]
        for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
            if 0 <= y + dy < height and 0 <= x + dx < width and not blocked[y + dy, x + dx]:
                out.append((y + dy) * width + x + dx)
        return out

    def successors(here):  # every next configuration, by one agent at a time
        following = []

        def place(agent):
            if agent == len(here):
                yield tuple(following)
                return
            for node in moves(here[agent]):
                if node in following or any(following[b] == here[agent] and here[b] == node
                                            for b in range(agent)):
                    continue
                following.append(node)
                yield from place(agent + 1)
                following.pop()

        yield from place(0)

    start, goal = tuple(starts), tuple(goals)
    best = {start: 0}
    queue = [(0, start)]
    while queue:
        cost, here = heapq.heappop(queue)
        if here == goal:
            return cost
        if cost > best[here]:
            continue
        for there in successors(here):
            through = cost + sum(a != g or b != g for a, b, g in zip(here, there, goal))
            if through < best.get(there, math.inf):
                best[there] = through
                heapq.heappush(queue, (through, there))
    return None


def test_the_least_sum_of_loss_by_hand():
    # A corridor 0-1-2: agent 0 from 0 to 2 and agent 1 resting at 1 cannot pass.
    assert least_sum_of_loss(np.zeros((1, 3), bool), [0, 1], [2, 1]) is None
    # A corridor 0-1-2-3 with a pocket 6 under node 2 where agent 1 rests; agent 0 goes from 0
    # to 3. Agent 1 waits at its goal (loss 0) while agent 0 takes node 1 (1), steps into the
    # pocket as agent 0 takes node 2 (2) and back as agent 0 arrives (2): 5. The sum of costs
    # counts agent 1's wait before it leaves: 3 + 3.
    blocked = np.array([[0, 0, 0, 0], [1, 1, 0, 1]], bool)
    assert least_sum_of_loss(blocked, [0, 2], [3, 2]) == 5
    assert oracle.mapf_optimum(oracle.grid_adjacency(blocked.tolist(), connectivity=4),
                               [(0, 0), (2, 0)], [(3, 0), (2, 0)]) == 6


def tiny_instances(count, seed):
    """``count`` random instances ``(blocked bool[H, W], starts, goals)`` on 2x4 and 3x3 grids
    with about one cell in five blocked and 2-4 agents (node indices)."""
    rng = np.random.default_rng(seed)
    instances = []
    while len(instances) < count:
        height, width = (2, 4) if rng.random() < 0.5 else (3, 3)
        blocked = rng.random((height, width)) < 0.2
        free = np.flatnonzero(~blocked)
        agents = int(rng.integers(2, 5))
        if len(free) > agents:
            instances.append((blocked, rng.permutation(free)[:agents].tolist(),
                              rng.permutation(free)[:agents].tolist()))
    return instances


def assert_optimum_claims(instances, seeds):
    """LaCAM* with ``refine`` on every instance and seed (odd seeds with ``swap``): solved exactly
    when the joint-state search finds a solution, never below its sum of loss, and equal to it
    whenever ``stats["optimal"]`` says so. Returns the number of runs that claimed it."""
    claimed = 0
    for blocked, starts, goals in instances:
        optimum = least_sum_of_loss(blocked, starts, goals)
        graph = grid_graph(blocked, connectivity=4)
        for seed in seeds:
            plan = lacam(graph, starts, goals, refine=30.0, swap=seed % 2 == 1, seed=seed)
            instance = (blocked.astype(int).tolist(), starts, goals, seed)
            assert plan.solved == (optimum is not None), instance
            if not plan.solved:
                continue
            assert is_a_solution(blocked, plan.paths, starts, goals), instance
            loss = sum_of_loss(plan.paths, goals)
            assert plan.stats["sum_of_loss"] == loss >= optimum, instance
            assert plan.stats["first_sum_of_loss"] >= loss, instance
            if plan.stats["optimal"]:
                assert loss == optimum, instance
                claimed += 1
    return claimed


def test_lacam_star_claims_an_optimum_only_when_the_joint_state_search_agrees():
    """The twin of the slow test below: the two instances where LaCAM* claimed an optimum it had
    not found (sum of loss 17 over 15, the issue's; 14 over 13, seed 3), then a few random ones."""
    found = [(np.array([[0, 0, 0, 0], [0, 0, 1, 1]], bool), [4, 3, 0, 1], [3, 1, 5, 4]),
             (np.array([[0, 0, 0], [0, 0, 1], [0, 0, 0]], bool), [6, 8, 7, 1], [7, 2, 1, 4])]
    assert assert_optimum_claims(found, seeds=range(4)) == 8
    assert assert_optimum_claims(tiny_instances(12, seed=7), seeds=range(2)) >= 12


def test_lacam_star_reaches_the_optimum_past_its_stores_first_capacity():
    """2,727 configurations (the stores grow from 1,024 rows, their hash tables rebuilt) and
    still the joint-state optimum, sum of loss 20."""
    found = [(np.array([[0, 1, 0, 0, 0], [0, 0, 0, 0, 0]], bool), [5, 8, 2, 9, 7],
              [2, 5, 4, 7, 6])]
    assert assert_optimum_claims(found, seeds=[0]) == 1
    blocked, starts, goals = found[0]
    plan = lacam(grid_graph(blocked, connectivity=4), starts, goals, refine=30.0)
    assert plan.stats["configurations"] > 2048 and plan.stats["sum_of_loss"] == 20


@pytest.mark.slow
def test_lacam_star_claims_an_optimum_only_when_the_joint_state_search_agrees_at_large():
    """300 random tiny instances, 4 seeds each (twin: the test above)."""
    assert assert_optimum_claims(tiny_instances(300, seed=65), seeds=range(4)) >= 850
