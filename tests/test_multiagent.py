"""Multi-agent planning: the report's printed examples, the validator and its batched conflict
check against an all-pairs oracle, and every planner against the validator, a joint-state
optimum and each other."""
from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

import oracle
from jaxswarm.maps.movingai import MovingAIFormatError
from jaxswarm.multiagent import (UNREACHABLE, cbs, find_conflicts, hop_fields, load_instance,
                                 lower_bound, pack, prioritized, registry, report_scheme,
                                 validate)
from jaxswarm.multiagent import conflicts as conflicts_module
from jaxswarm.multiagent.agents import distance_fields
from jaxswarm.multiagent.plan import arrival_steps
from jaxswarm.multiagent.prioritized import priority_order
from jaxswarm.multiagent.report import report_example
from jaxswarm.world.graph import grid_graph

PLANNERS = {name: registry.make_planner(name) for name in registry.registered()}
"""Every registered planner with its default options."""


def cells(graph, path):
    xy = np.asarray(graph.xy).astype(int)
    return [tuple(int(c) for c in xy[v]) for v in path]


def nodes(graph, points):
    width = graph.shape[1]
    return [y * width + x for x, y in points]


# --- the report's printed examples (shared/papers/004, section 5) ---------------------------

MAP1_ROBOT1 = [(0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (4, 4), (5, 5), (6, 6), (7, 7), (8, 8),
               (9, 9)]
MAP1_ROBOT2 = [(9, 9), (8, 8), (7, 7), (6, 6), (5, 5), (4, 5), (4, 4), (3, 3), (2, 2), (1, 1),
               (0, 0)]
MAP1_LOG = """\
robot1 initialized path : [(0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (5, 5), (6, 6), (7, 7), (8, 8), (9, 9)]
robot2 initialized path : [(9, 9), (8, 8), (7, 7), (6, 6), (5, 5), (4, 4), (3, 3), (2, 2), (1, 1), (0, 0)]
collision state at 5
before collision states of robot are robot2_state:(4, 4), robot1_state = (5, 5)
found possible move for robot2 state : [(4, 5), (6, 6)]
no collision found"""
MAP2_ROBOT1 = [(4, 0), (5, 1), (5, 2), (5, 3), (5, 4), (5, 5), (5, 6), (5, 7), (5, 8), (4, 9)]
MAP2_ROBOT2 = [(6, 9), (5, 8), (5, 7), (5, 6), (5, 5), (5, 4), (5, 3), (5, 2), (5, 1), (6, 0)]


def test_report_first_example_side_step_and_wait():
    graph, starts, goals = report_example("map1")
    plan = report_scheme(graph, starts, goals)
    assert plan.solved
    assert "\n".join(plan.log) == MAP1_LOG
    assert cells(graph, plan.paths[0]) == MAP1_ROBOT1
    assert cells(graph, plan.paths[1]) == MAP1_ROBOT2
    assert validate(graph, plan.paths, starts, goals, plan.lengths) == []


def test_report_second_example_robot_two_moves_first():
    graph, starts, goals = report_example("map2")
    plan = report_scheme(graph, starts, goals)
    assert plan.solved
    assert plan.log[:2] == (f"robot1 initialized path : {MAP2_ROBOT1}".replace("'", ""),
                            f"robot2 initialized path : {MAP2_ROBOT2}".replace("'", ""))
    assert plan.log[-3:] == ("robot1_path_possible", "can not synchronize, robot 2 move first",
                             f"robot2 path planning:{MAP2_ROBOT2}")
    # Robot 2 keeps its path; robot 1 holds its start until robot 2 is at its goal.
    assert cells(graph, plan.paths[1][:len(MAP2_ROBOT2)]) == MAP2_ROBOT2
    assert cells(graph, plan.paths[0]) == [MAP2_ROBOT1[0]] * 9 + MAP2_ROBOT1
    assert plan.lengths.tolist() == [18, 9]
    assert validate(graph, plan.paths, starts, goals, plan.lengths) == []


def test_report_scheme_names_the_pair_it_cannot_separate():
    corridor = grid_graph(np.zeros((1, 4), bool), connectivity=4)
    plan = report_scheme(corridor, [(0, 0), (3, 0)], [(3, 0), (0, 0)])
    assert not plan.solved and "agents 0 and 1" in plan.reason


# --- the solution format and the validator --------------------------------------------------

def test_arrival_steps_count_until_the_last_arrival():
    paths = np.array([[0, 1, 2, 2, 2], [5, 5, 5, 5, 5], [3, 4, 3, 4, 4]])
    assert arrival_steps(paths, [2, 5, 4]).tolist() == [2, 0, 3]
    padded, lengths = pack([[0, 1, 2], [5], [3, 4, 3, 4]], goals=[2, 5, 4])
    assert padded.tolist() == [[0, 1, 2, 2], [5, 5, 5, 5], [3, 4, 3, 4]]
    assert lengths.tolist() == [2, 0, 3]


@pytest.fixture(scope="module")
def open_grid():
    """A 4 x 4 grid, 4-connected, with the obstacle (1, 1)."""
    blocked = np.zeros((4, 4), bool)
    blocked[1, 1] = True
    return grid_graph(blocked, connectivity=4)


def test_validator_accepts_a_valid_solution(open_grid):
    # Agent 0 goes along the top row while agent 1 waits for it to pass (0, 2) -> (0, 0).
    starts, goals = [(0, 0), (3, 3)], [(3, 0), (0, 3)]
    paths = [nodes(open_grid, [(0, 0), (1, 0), (2, 0), (3, 0)]),
             nodes(open_grid, [(3, 3), (2, 3), (1, 3), (0, 3)])]
    padded, lengths = pack(paths, nodes(open_grid, goals))
    assert validate(open_grid, padded, starts, goals, lengths) == []


@pytest.mark.parametrize("kind, paths, starts, goals", [
    ("vertex", [[(0, 0), (1, 0), (2, 0)], [(2, 0), (1, 0), (0, 0)]], [(0, 0), (2, 0)],
     [(2, 0), (0, 0)]),
    ("swap", [[(0, 0), (1, 0)], [(1, 0), (0, 0)]], [(0, 0), (1, 0)], [(1, 0), (0, 0)]),
    ("move", [[(0, 0), (2, 0)], [(3, 3), (3, 3)]], [(0, 0), (3, 3)], [(2, 0), (3, 3)]),
    ("move", [[(0, 0), (1, 1), (2, 2)], [(3, 3), (3, 3), (3, 3)]], [(0, 0), (3, 3)],
     [(2, 2), (3, 3)]),
    ("goal", [[(0, 0), (1, 0), (2, 0), (1, 0)], [(3, 3)]], [(0, 0), (3, 3)], [(2, 0), (3, 3)]),
    ("start", [[(1, 0), (2, 0)], [(3, 3)]], [(0, 0), (3, 3)], [(2, 0), (3, 3)]),
])
def test_validator_catches_a_planted_violation(open_grid, kind, paths, starts, goals):
    padded, _ = pack([nodes(open_grid, p) for p in paths])
    found = validate(open_grid, padded, starts, goals)
    assert kind in {v.kind for v in found}, found
    assert all(str(v) for v in found)


def test_validator_catches_an_agent_leaving_its_goal_after_its_length(open_grid):
    starts, goals = [(0, 0), (3, 3)], [(2, 0), (3, 3)]
    path = nodes(open_grid, [(0, 0), (1, 0), (2, 0), (3, 0), (2, 0)])
    padded, _ = pack([path, nodes(open_grid, [(3, 3)])])
    assert validate(open_grid, padded, starts, goals) == []  # it may leave and come back...
    found = validate(open_grid, padded, starts, goals, lengths=[2, 0])  # ...but not at cost 2
    assert [(v.kind, v.agents, v.step) for v in found] == [("goal", (0,), 3)]


def test_validator_names_both_agents_of_a_conflict(open_grid):
    starts, goals = [(0, 0), (2, 0)], [(2, 0), (0, 0)]
    padded, _ = pack([nodes(open_grid, [(0, 0), (1, 0), (2, 0)]),
                      nodes(open_grid, [(2, 0), (1, 0), (0, 0)])])
    vertex = [v for v in validate(open_grid, padded, starts, goals) if v.kind == "vertex"]
    assert [(v.agents, v.step) for v in vertex] == [((0, 1), 1)]
    assert "agents 0 and 1" in str(vertex[0])


@pytest.mark.parametrize("table_entries", [1 << 19, 64])
def test_batched_conflicts_match_all_pairs(monkeypatch, table_entries):
    """Random walks with many collisions on a 6 x 6 grid; 64 table entries force one step per
    chunk and a padded last chunk."""
    monkeypatch.setattr(conflicts_module, "TABLE_ENTRIES", table_entries)
    graph, walks = _colliding_walks()
    found = find_conflicts(walks, graph.num_nodes)
    vertex, swap = oracle.pairwise_conflicts(walks.tolist())
    assert {(int(t), int(a)) for t, a in zip(*np.nonzero(found.vertex))} == vertex
    assert vertex and swap, "the walks should collide"
    # A swap partner is reported unless the partner shares its node with a third agent.
    reported = {(int(t), int(a), int(found.swap[t, a])) for t, a in zip(*np.nonzero(
        found.swap >= 0))}
    assert reported <= swap
    assert {s for s in swap if (s[0], s[2]) not in vertex} <= reported


def test_pair_collisions_are_each_pairs_vertex_or_swap_steps():
    _, walks = _colliding_walks()
    first = conflicts_module.pair_collisions(walks)
    for a, b in itertools.permutations(range(len(walks)), 2):
        here, there = walks[a], walks[b]
        steps = [t for t in range(walks.shape[1]) if here[t] == there[t]
                 or (t > 0 and here[t - 1] == there[t] and here[t] == there[t - 1]
                     and here[t] != here[t - 1])]
        assert first[a, b] == (steps[0] if steps else -1), (a, b)
        assert conflicts_module.pair_collision_steps(walks, a, b) == steps, (a, b)
    assert (first >= 0).sum() > 20 and (first[~np.eye(len(walks), dtype=bool)] < 0).any()
    assert (conflicts_module.pair_collisions(walks, [7, 3]) == first[[7, 3]]).all()


def _colliding_walks():
    """A 6 x 6 grid and 12 random walks of 23 steps on it (i64[12, 23]), colliding often."""
    rng = np.random.default_rng(3)
    graph = grid_graph(np.zeros((6, 6), bool), connectivity=4)
    nbr = np.asarray(graph.nbr)
    walks = np.empty((12, 23), np.int64)
    walks[:, 0] = rng.permutation(36)[:12]
    for t in range(1, walks.shape[1]):
        options = np.concatenate([walks[:, t - 1:t], nbr[walks[:, t - 1]]], axis=1)
        pick = rng.integers(0, 5, size=12)
        step = options[np.arange(12), pick]
        walks[:, t] = np.where(step >= 0, step, walks[:, t - 1])
    return graph, walks


# --- the planners ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def instances(movingai_dir):
    mapf = movingai_dir / "mapf"
    return {name: load_instance(mapf / f"{name}.map", mapf / f"{name}-random-1.scen", 10)
            for name in ("random-32-32-10", "room-32-32-4")}


@pytest.fixture(scope="module")
def plans(instances):
    return {(name, planner): PLANNERS[planner](i.graph, i.starts, i.goals)
            for name, i in instances.items() for planner in PLANNERS}


def test_every_planner_solution_is_valid(instances, plans):
    for (name, planner), plan in plans.items():
        instance = instances[name]
        assert plan.solved, (name, planner, plan.reason)
        assert validate(instance.graph, plan.paths, instance.starts, instance.goals,
                        plan.lengths) == [], (name, planner)
        assert plan.sum_of_costs >= lower_bound(instance.graph, instance.starts,
                                                instance.goals)


def test_cbs_is_never_worse_than_the_others(instances, plans):
    for name in instances:
        for planner in PLANNERS:
            assert plans[name, "cbs"].sum_of_costs <= plans[name, planner].sum_of_costs


def test_lower_bound_is_the_sum_of_breadth_first_distances(instances):
    instance = instances["room-32-32-4"]
    blocked = ~np.asarray(instance.graph.free).reshape(instance.graph.shape)
    adjacency = oracle.grid_adjacency(blocked.tolist(), connectivity=4)
    expected = sum(oracle.dijkstra(adjacency, s, g) for s, g in zip(instance.starts,
                                                                     instance.goals))
    assert lower_bound(instance.graph, instance.starts, instance.goals) == expected


TINY = [  # (obstacle rows, starts, goals): 4 x 4 grids, 4-connected
    (["....", ".#..", "....", "...."], [(0, 0), (2, 0)], [(2, 0), (0, 0)]),
    (["....", "##.#", "....", "...."], [(0, 0), (3, 0), (2, 3)], [(3, 0), (0, 0), (2, 0)]),
    (["#..#", "#.##", "#...", "...."], [(1, 0), (0, 3)], [(3, 2), (2, 0)]),
    (["....", "....", "....", "...."], [(0, 0), (1, 0), (2, 0)], [(2, 0), (0, 0), (1, 0)]),
]


@pytest.mark.parametrize("rows, starts, goals", TINY)
def test_cbs_matches_the_joint_state_optimum(rows, starts, goals):
    blocked = np.array([[c == "#" for c in row] for row in rows])
    graph = grid_graph(blocked, connectivity=4)
    optimum = oracle.mapf_optimum(oracle.grid_adjacency(blocked.tolist(), connectivity=4),
                                  [tuple(s) for s in starts], [tuple(g) for g in goals])
    plan = cbs(graph, starts, goals)
    assert plan.solved and plan.sum_of_costs == optimum
    assert validate(graph, plan.paths, starts, goals, plan.lengths) == []
    ranked = prioritized(graph, starts, goals)
    if ranked.solved:
        assert ranked.sum_of_costs >= optimum


def test_each_prioritized_path_is_the_fewest_steps_around_those_before_it():
    """Space-time A* (with its static tail after the last reservation) against breadth-first
    search over (cell, step), agent by agent, on random 5 x 5 instances."""
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(6):
        blocked = rng.random((5, 5)) < 0.2
        free = [(x, y) for y in range(5) for x in range(5) if not blocked[y, x]]
        picks = rng.permutation(len(free))[:8]
        starts, goals = [free[i] for i in picks[:4]], [free[i] for i in picks[4:]]
        graph = grid_graph(blocked, connectivity=4)
        if lower_bound(graph, starts, goals) >= UNREACHABLE:
            continue
        plan = prioritized(graph, starts, goals, order="random", seed=int(rng.integers(100)))
        adjacency = oracle.grid_adjacency(blocked.tolist(), connectivity=4)
        before = []
        for agent in plan.stats["order"].tolist():
            expected = oracle.spacetime_steps(adjacency, starts[agent], goals[agent], before)
            if expected is None:
                assert not plan.solved and plan.agent == agent
                break
            assert plan.lengths[agent] == expected
            path = cells(graph, plan.paths[agent][:expected + 1])
            before.append(path)
            checked += 1
        else:
            assert validate(graph, plan.paths, starts, goals, plan.lengths) == []
    assert checked >= 12


def test_priority_orders():
    distances = np.array([3, 9, 3, 7])
    assert priority_order("given", distances).tolist() == [0, 1, 2, 3]
    assert priority_order("distance", distances).tolist() == [1, 3, 0, 2]
    assert (priority_order("random", distances, seed=5).tolist()
            == priority_order("random", distances, seed=5).tolist())
    assert sorted(priority_order("random", distances, seed=5).tolist()) == [0, 1, 2, 3]
    with pytest.raises(ValueError, match="permutation"):
        priority_order([0, 0, 1, 2], distances)
    with pytest.raises(ValueError, match="unknown order"):
        priority_order("longest", distances)


def test_prioritized_is_incomplete_where_cbs_is_not():
    """A corridor (0..2, 0) with a pocket (1, 1): agent 1 can only pass while agent 0 hides in
    the pocket, which no agent planned alone (first or second) does."""
    blocked = np.array([[False, False, False], [True, False, True]])
    graph = grid_graph(blocked, connectivity=4)
    starts, goals = [(2, 0), (0, 0)], [(1, 0), (2, 0)]
    for order, stuck in (([0, 1], 1), ([1, 0], 0)):
        plan = prioritized(graph, starts, goals, order=order)
        assert not plan.solved and plan.agent == stuck
        assert plan.reason.startswith(f"agent {stuck} could not be planned")
    optimal = cbs(graph, starts, goals)
    assert optimal.solved and optimal.sum_of_costs == oracle.mapf_optimum(
        oracle.grid_adjacency(blocked.tolist(), connectivity=4), starts, goals) == 6
    assert validate(graph, optimal.paths, starts, goals, optimal.lengths) == []


def test_prioritized_time_limit_ends_cleanly():
    graph = grid_graph(np.zeros((4, 4), bool), connectivity=4)
    plan = prioritized(graph, [(0, 0), (3, 3)], [(3, 3), (0, 0)], time_limit=0.0)
    assert not plan.solved and plan.agent == 0
    assert plan.reason == "agent 0 not planned (priority 0): reached the time limit (0 s)"


def test_cbs_limit_ends_cleanly():
    corridor = grid_graph(np.zeros((1, 3), bool), connectivity=4)
    plan = cbs(corridor, [(0, 0), (2, 0)], [(2, 0), (0, 0)], max_nodes=50)
    assert not plan.solved and "agents 0 and 1" in plan.reason


@pytest.mark.parametrize("planner", PLANNERS)
def test_bad_instances(planner):
    blocked = np.zeros((3, 3), bool)
    blocked[1, 1] = True
    blocked[0, 2] = blocked[1, 2] = blocked[2, 2] = False
    walled = blocked.copy()
    walled[:, 1] = True  # column 2 cut off from column 0
    graph, cut = grid_graph(blocked, connectivity=4), grid_graph(walled, connectivity=4)
    plan = PLANNERS[planner]
    with pytest.raises(ValueError, match="agents 0 and 1 have one start"):
        plan(graph, [(0, 0), (0, 0)], [(2, 2), (2, 0)])
    with pytest.raises(ValueError, match="agents 0 and 1 have one goal"):
        plan(graph, [(0, 0), (0, 2)], [(2, 2), (2, 2)])
    with pytest.raises(ValueError, match="agent 1's start .* blocked"):
        plan(graph, [(0, 0), (1, 1)], [(2, 2), (2, 0)])
    with pytest.raises(ValueError, match="agent 0's goal .* off"):
        plan(graph, [(0, 0), (0, 2)], [(5, 2), (2, 0)])
    unreachable = plan(cut, [(0, 0), (0, 2)], [(0, 1), (2, 0)])
    assert not unreachable.solved and unreachable.agent == 1 and "agent 1" in unreachable.reason


def test_load_instance_errors(movingai_dir):
    mapf = movingai_dir / "mapf"
    with pytest.raises(MovingAIFormatError, match="maze-32-32-2-random-1.scen.*1000 agents"):
        load_instance(mapf / "maze-32-32-2.map", mapf / "maze-32-32-2-random-1.scen", 1000)


def test_hop_fields_count_steps_not_lengths():
    graph = grid_graph(np.zeros((3, 3), bool), connectivity=8)
    fields = hop_fields(graph, np.array([0]))
    assert fields[0, 8] == 2  # two diagonal steps, not 2 sqrt 2


def test_hop_fields_are_the_jax_distance_fields_of_unit_moves(instances):
    # The breadth-first fields against the batched JAX relaxation on the graph whose every
    # edge is one step long (and UNREACHABLE where it gives inf).
    graph = instances["room-32-32-4"].graph
    goals = np.array([0, 37, 500, 1023], np.int32)
    unit = dataclasses.replace(graph, cost=(np.asarray(graph.nbr) >= 0).astype(np.float32))
    relaxed = distance_fields(unit, goals)
    expected = np.full(relaxed.shape, UNREACHABLE, np.int64)
    expected[np.isfinite(relaxed)] = relaxed[np.isfinite(relaxed)]
    np.testing.assert_array_equal(hop_fields(graph, goals), expected)


@pytest.mark.parametrize("planner", PLANNERS)
def test_agents_given_as_node_indices(planner):
    walled = np.zeros((3, 3), bool)
    walled[1, :] = True
    graph = grid_graph(walled, connectivity=4)
    plan = PLANNERS[planner](graph, [0], [6])
    assert not plan.solved and "agent 0" in plan.reason
    with pytest.raises(ValueError, match=r"agents 0 and 1 have one goal \(2, 0\)"):
        PLANNERS[planner](graph, [0, 1], [2, 2])


@pytest.mark.slow
@pytest.mark.parametrize("name", ["empty-32-32", "random-32-32-10", "room-32-32-4",
                                  "maze-32-32-2", "den312d"])
def test_every_solution_on_the_study_maps_is_valid(movingai_dir, name):
    """50 agents of each study map: every planner's solution validates and none beats the lower
    bound or a solved CBS."""
    mapf = movingai_dir / "mapf"
    instance = load_instance(mapf / f"{name}.map", mapf / f"{name}-random-1.scen", 50)
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    bound = lower_bound(graph, starts, goals)
    plans = [report_scheme(graph, starts, goals), cbs(graph, starts, goals, time_limit=5)]
    plans += [prioritized(graph, starts, goals, order=order, seed=seed)
              for order, seed in (("given", 0), ("distance", 0), ("random", 1), ("random", 2))]
    solved = [plan for plan in plans if plan.solved]
    assert any(plan.planner == "prioritized" for plan in solved), name
    for plan in solved:
        assert validate(graph, plan.paths, starts, goals, plan.lengths) == [], plan.planner
        assert plan.sum_of_costs >= bound
        if plans[1].solved:
            assert plans[1].sum_of_costs <= plan.sum_of_costs
    for plan in plans:
        if not plan.solved:
            assert plan.reason and "agent" in plan.reason, plan.planner
