"""The conformance checks catch a swarm that breaks them, and RFD's own rules (every swarm's
conformance: ``test_conformance.py``)."""
import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import sizes
from conformance import maze  # noqa: F401 (fixture)
from jitted import erode_banks, graded_transition, rows_log, settle

from jaxswarm.exact import dijkstra
from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import Swarm, make, make_task, rfd, run
from jaxswarm.swarm.core import StepInfo, keep_best
from jaxswarm.swarm.testing import (Compilations, batched_params, check_reproducible,
                                     check_valid_results, run_batch)
from jaxswarm.swarm.walking import Walk
from jaxswarm.swarm.walking.log import from_rows
from jaxswarm.world.graph import grid_graph
from jaxswarm.world.paths import Solution

SMALL = sizes.CONFIG
ITERATIONS = sizes.ITERATIONS



@pytest.mark.slow  # about 25 s
def test_the_conformance_suite_catches_a_swarm_that_breaks_it(maze):
    graph, task, optimum = maze
    swarm = make("rfd_graded", **SMALL)
    # A swarm whose best path claims a cost below its length, and one that ignores its key.
    lying = dataclasses.replace(swarm, best=lambda state: dataclasses.replace(
        swarm.best(state), cost=swarm.best(state).cost - 1.0))
    with pytest.raises(AssertionError, match="cost is not the path's length"):
        check_valid_results(lying, graph, task, optimum)
    fixed = dataclasses.replace(swarm, step=lambda state, *a: swarm.step(
        dataclasses.replace(state, key=jax.random.key(0)), *a))
    with pytest.raises(AssertionError, match="two keys gave the same run"):
        check_reproducible(fixed, graph, task)


def test_rfd_star_sweep_over_p_base_and_alpha_compiles_once():
    # A batch of sizes.RUNS runs, each of another p_base and alpha (the batch program the
    # conformance checks build), and a batch of other values of both.
    graph, task = sizes.maze()
    swarm = make("rfd_star", **SMALL)
    grid = batched_params(swarm.default_params, sizes.RUNS)._replace(
        p_base=jnp.array([5.0, 50.0, 200.0]), alpha=jnp.array([1.0, 2.0, 4.0]))
    other = jax.tree_util.tree_map(lambda x: x * 1.01, grid)
    keys = jax.random.split(jax.random.key(1), sizes.RUNS)
    with Compilations() as built:
        run_batch(swarm, keys, graph, task, grid, iterations=ITERATIONS)
        run_batch(swarm, keys, graph, task, other, iterations=ITERATIONS)
    assert built.count == 1, built.names


def iterate(swarm, graph, task, params, state=None, budget=1, seed=0):
    """``(state, trace)`` of ``budget`` iterations of ``swarm``, from fresh memory or from
    ``state``, by ``run`` at the shared iteration count with a traced budget: one program per
    swarm and map shape, whatever the budget, the params and the state's values. A swarm of the
    shared size on the shared map's shape runs the programs test_conformance.py (fresh memory)
    and test_dynamic.py (from a state) build."""
    return run(swarm, jax.random.key(seed), graph, task, params, iterations=ITERATIONS,
               state=state, budget=budget)


def fresh_altitudes(graph, task, params):
    """A river swarm's altitudes in fresh memory, as its ``init`` sets them (without a program):
    ``initial_height``, the goal at 0 (f32[N], NumPy)."""
    altitude = np.full(graph.num_nodes, float(params.initial_height), np.float32)
    altitude[int(task.goal)] = 0.0
    return altitude


@pytest.mark.parametrize("law", ["linear", "exponential"])
def test_no_erosion_and_no_sediment_leave_altitudes_alone(law):
    graph, task = sizes.maze()
    swarm = make("rfd_star", erosion_law=law, **SMALL)
    params = swarm.default_params._replace(erosion=jnp.float32(0.0), sediment=jnp.float32(0.0))
    state, _ = iterate(swarm, graph, task, params, budget=ITERATIONS)
    np.testing.assert_array_equal(state.altitude, fresh_altitudes(graph, task, params))


@pytest.fixture(scope="module")
def corridor():
    """A corridor from (0, 0) to (4, 0) in the shared map's shape, every other cell blocked:
    every drop walks the same four unit edges. N, the graph's node count, counts the blocked
    cells too."""
    graph = sizes.cut_out([[True] * 5])
    return graph, make_task(graph, (0, 0), (4, 0))


def one_iteration(swarm, graph, task, state=None, **params):
    """The state after one iteration of ``swarm`` with ``params`` (the others default), from
    fresh memory or from ``state``, in which every drop arrived."""
    params = swarm.default_params._replace(**{k: jnp.float32(v) for k, v in params.items()})
    state, trace = iterate(swarm, graph, task, params, state)
    assert np.asarray(trace.arrived)[0] == 1.0
    return state


def test_linear_erosion_is_eqs_4_and_5(corridor):
    # Only edge 3 -> 4 has a gradient (1 - 0) / 1: node 3 loses E / (N - 1) summed over the D
    # drops, 1 / 4 with E = (N - 1) / 4; eq. 5 then gives every node, blocked ones too, that
    # total / (N - 1); the goal is reset to 0.
    graph, task = corridor
    n = graph.num_nodes
    swarm = make("rfd_star", erosion_law="linear", **SMALL)
    state = one_iteration(swarm, graph, task, initial_height=1.0, erosion=(n - 1) / 4,
                          sediment=0.0)
    expected = np.full(n, 1 + 1 / (4 * (n - 1)))
    expected[3:5] = 1 - 1 / 4 + 1 / (4 * (n - 1)), 0.0
    np.testing.assert_allclose(state.altitude, expected, rtol=1e-6)


def test_exponential_erosion_erodes_no_node_below_the_node_it_drains_to(corridor):
    # p_base ** gradient asks 1 on the three flat edges and p_base = 2 on the last one, each
    # times E / ((N - 1) D) = 1 / (4 D) per drop (E = (N - 1) / 4). A flat move's node would
    # sink below the node it goes to: it gives nothing. Node 3 asks D / (4 D) * 2 = 1 / 2 and
    # drains to the goal (0): it gives it. Eq. 5: every node, blocked ones too, gains
    # (1 / 2) / (N - 1).
    graph, task = corridor
    n = graph.num_nodes
    swarm = make("rfd_star", erosion_law="exponential", **SMALL)
    state = one_iteration(swarm, graph, task, p_base=2.0, initial_height=1.0,
                          erosion=(n - 1) / 4, sediment=0.0)
    expected = np.full(n, 1 + 1 / (2 * (n - 1)))
    expected[3:5] = 1 - 1 / 2 + 1 / (2 * (n - 1)), 0.0
    np.testing.assert_allclose(state.altitude, expected, rtol=1e-6)


def test_graded_erosion_cuts_the_bed_to_slope_times_the_remaining_length(corridor):
    graph, task = corridor
    swarm = make("rfd_graded", **SMALL)
    bed = np.full(graph.num_nodes, 100.0)  # the blocked cells stay on the plateau
    bed[:5] = [2.0, 1.5, 1.0, 0.5, 0.0]
    state = one_iteration(swarm, graph, task, erosion=0.5, initial_height=100.0)
    np.testing.assert_allclose(state.altitude, bed)
    # A higher slope cuts less deep, and the bed never rises: min(old, new) per node.
    state = one_iteration(swarm, graph, task, state, erosion=2.0, initial_height=100.0)
    np.testing.assert_allclose(state.altitude, bed)


def test_graded_carving_drains_into_a_river_without_arriving():
    # Nodes 2, 3 and 4 of a 1 x 6 corridor are carved; the drops may walk 2 steps (the swarm of
    # test_ground_explored_in_vain_rises_towards_the_frontier), so they stop on node 2 without
    # reaching the goal and carve 0-1 to slope x (walked to 2 + depth of 2).
    graph = grid_graph(np.zeros((1, 6), bool))
    task = make_task(graph, (0, 0), (5, 0))
    swarm = make("rfd_graded", num_agents=4, max_steps=2)
    params = swarm.default_params._replace(erosion=jnp.float32(0.5))
    plateau = float(params.initial_height)
    state = swarm.init(jax.random.key(0), graph, task, params)
    state = dataclasses.replace(state, altitude=np.array([plateau] * 2 + [1.5, 1.0, 0.5, 0.0],
                                                         np.float32))
    state, trace = iterate(swarm, graph, task, params, state)
    assert np.asarray(trace.arrived)[0] == 0.0
    np.testing.assert_allclose(state.altitude, [2.5, 2.0, 1.5, 1.0, 0.5, 0.0])


WALK_NODES = 10
"""The nodes of a fake walk's path, -1 padded: one shape for every fake walk (the longest has 8
cells), so one program of :func:`blind_alleys` for all of them."""


def fake_walk(graph, cells, stuck=True):
    """A one-drop Walk along ``cells`` ((x, y) pairs) that stopped at the last one."""
    width = graph.shape[1]
    nodes = [y * width + x for x, y in cells]
    path = np.full((1, WALK_NODES), -1, np.int32)
    path[0, :len(nodes)] = nodes
    visited = np.zeros((1, (graph.num_nodes + 31) // 32), np.uint32)
    for node in nodes:
        visited[0, node // 32] |= np.uint32(1 << (node % 32))
    moves = np.array([len(nodes) - 1], np.int32)
    log = rows_log(path, np.full((1, WALK_NODES - 1), -1, np.int16), moves, np.int32(nodes[0]),
                   WALK_NODES - 1)
    return Walk(log=log, length=np.zeros(1, np.float32), arrived=np.zeros(1, bool),
                stuck=np.array([stuck]), position=np.array([nodes[-1]], np.int32),
                visited=visited, moves=moves, lane_steps=np.int32(len(nodes) - 1))


@jax.jit
def blind_alleys(graph, task, altitude, walk_, params):
    """bool[N]: :func:`rfd.blind_alleys` of ``walk_`` on rfd_graded's table for ``altitude``,
    in one program."""
    return rfd.blind_alleys(graph, rfd.graded_transition(graph, task, altitude, params), walk_)


def filled_cells(graph, task, walk_):
    params = make("rfd_graded").default_params
    filled = np.flatnonzero(np.asarray(blind_alleys(
        graph, task, fresh_altitudes(graph, task, params), walk_, params)))
    return sorted((int(v) % graph.shape[1], int(v) // graph.shape[1]) for v in filled)


def test_a_stuck_drop_fills_its_blind_alley_back_to_the_junction():
    obstacles = np.array([[0, 0, 0, 0, 0],
                          [1, 1, 0, 1, 1],
                          [1, 1, 0, 1, 1]], bool)  # a dead end hangs below (2, 0)
    graph = grid_graph(obstacles)
    task = make_task(graph, (0, 0), (4, 0))
    into_the_alley = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2)]
    assert filled_cells(graph, task, fake_walk(graph, into_the_alley)) == [(2, 1), (2, 2)]
    # (2, 0) leads on to (3, 0). A drop that ran out of steps in the alley fills nothing.
    assert filled_cells(graph, task, fake_walk(graph, into_the_alley, stuck=False)) == []


def test_a_drop_trapped_by_its_own_trail_fills_only_where_it_stopped():
    obstacles = np.zeros((3, 5), bool)
    obstacles[:, 3:] = True  # an open 3 x 3, in the previous test's 3 x 5 (the same programs)
    graph = grid_graph(obstacles)
    task = make_task(graph, (0, 0), (2, 2))
    spiral = [(0, 0), (1, 0), (2, 0), (2, 1), (1, 2), (0, 2), (0, 1), (1, 1)]
    assert filled_cells(graph, task, fake_walk(graph, spiral)) == [(1, 1)]


def test_graded_gradients_between_bed_and_plateau_are_clipped():
    graph = grid_graph(np.zeros((2, 3), bool))  # nodes 0 1 2 / 3 4 5, goal 2
    task = make_task(graph, (0, 0), (2, 0))
    params = make("rfd_graded").default_params
    plateau = float(params.initial_height)
    altitude = np.array([2.0, 1.0, 0.0, plateau, plateau + 5, plateau], np.float32)
    table = np.asarray(graded_transition(graph, task, altitude, params))
    nbr = np.asarray(graph.nbr)
    log_p, alpha = math.log(float(params.p_base)), float(params.alpha)

    def logw(i, j):
        return table[i, list(nbr[i]).index(j)]

    # Carved node 0 -> plateau node 3: the uphill gradient is floored at -climb.
    expected = -float(params.climb) * log_p - alpha * math.log(math.hypot(2, 1))
    assert logw(0, 3) == pytest.approx(expected, rel=1e-5)
    assert logw(0, 1) == pytest.approx(1.0 * log_p - alpha * math.log(1.0), rel=1e-5)
    # Plateau node 3 -> carved node 0: the bank looks no steeper than the bed itself (erosion).
    assert logw(3, 0) == pytest.approx(float(params.erosion) * log_p - alpha * math.log(2.0),
                                       rel=1e-5)
    # Uncarved node 3 -> the deposit hill at 4 (5 higher): too steep, banned.
    assert logw(3, 4) == -np.inf
    # Uncarved 5 -> the hill at 4 is banned too; the goal is forced whenever adjacent.
    assert logw(5, 4) == -np.inf and logw(1, 2) > 1e29


STRIP = 200
"""The length of the one-row maps the altitude rules are checked on, a shorter map being cut out
of one by obstacles: one program of each rule for all of them."""


def strip(free_cells: int, altitudes):
    """A 1 x STRIP map whose first ``free_cells`` cells are free (the others blocked), and
    f32[STRIP] altitudes: ``altitudes`` on its first cells, 100 (the plateau of these tests)
    on the others."""
    obstacles = np.ones((1, STRIP), bool)
    obstacles[0, :free_cells] = False
    altitude = np.full(STRIP, 100.0, np.float32)
    altitude[:len(altitudes)] = altitudes
    return grid_graph(obstacles), altitude


def test_settling_leaves_no_filled_pit():
    # A corridor (0, 0)..(5, 0), and (6, 0) joined to (5, 0) only.
    graph, altitude = strip(7, [101.0, 100.5, 101.0, 100.0, 99.0, 0.0, 102.0])
    params = make("rfd_graded").default_params._replace(initial_height=jnp.float32(100.0),
                                                       repose=jnp.float32(0.25))
    settled = np.asarray(settle(graph, altitude, params))[:7]
    # (1, 0) is a pit between two 101s: raised to 101.25, which makes (0, 0) a pit in turn.
    # (2, 0) drains to the unfilled (3, 0); unfilled and carved nodes and (6, 0), which drains
    # into the bed at (5, 0), keep their altitude.
    np.testing.assert_allclose(settled, [101.5, 101.25, 101.0, 100.0, 99.0, 0.0, 102.0])
    # A filled node without any edge has nowhere to settle to and keeps its altitude.
    alone = np.ones((1, STRIP), bool)
    alone[0, 1] = False
    lone = np.asarray(settle(grid_graph(alone), np.full(STRIP, 101.0, np.float32), params))
    assert lone[1] == 101.0


def test_sediment_settles_all_the_way_in_one_call():
    # Filled ground (101) along a 200-cell corridor drains only through its east end (100): it
    # settles to a slope of repose down to there, which takes about 200 sweeps.
    graph, altitude = strip(STRIP, [101.0] * (STRIP - 1))
    params = make("rfd_graded").default_params._replace(initial_height=jnp.float32(100.0),
                                                       repose=jnp.float32(0.25))
    settled = np.asarray(settle(graph, altitude, params))
    np.testing.assert_allclose(settled[:199], 101.0 + 0.25 * (198 - np.arange(199)))
    assert settled[199] == 100.0


def test_a_drop_erodes_the_banks_it_visits():
    graph, altitude = strip(5, [100.0, 7.0, 9.0, 0.5, 0.0])
    params = make("rfd_graded").default_params._replace(initial_height=jnp.float32(100.0),
                                                       erosion=jnp.float32(1.0))
    visited = np.arange(STRIP) < 3
    eroded = np.asarray(erode_banks(graph, altitude, visited, params))
    # (2, 0) sees the bed at (3, 0): 0.5 + 1. (1, 0) looks once, at the old 9 and the uncarved
    # plateau, and keeps its 7; the plateau nodes and the unvisited nodes are left alone.
    np.testing.assert_allclose(eroded[:5], [100.0, 7.0, 1.5, 0.5, 0.0])
    np.testing.assert_array_equal(eroded[5:], 100.0)


def test_ground_explored_in_vain_rises_towards_the_frontier():
    # The drops run out of steps on (2, 0) of a 1 x 6 corridor: their trail gains sediment and
    # settles so that it slopes down to the unexplored (3, 0).
    graph = grid_graph(np.zeros((1, 6), bool))
    task = make_task(graph, (0, 0), (5, 0))
    swarm = make("rfd_graded", num_agents=4, max_steps=2)
    params = swarm.default_params._replace(initial_height=jnp.float32(100.0),
                                           sediment=jnp.float32(0.5), repose=jnp.float32(0.25))
    state = swarm.init(jax.random.key(0), graph, task, params)
    state, trace = iterate(swarm, graph, task, params, state)
    assert np.asarray(trace.arrived)[0] == 0.0
    np.testing.assert_allclose(state.altitude, [101.0, 100.75, 100.5, 100.0, 100.0, 0.0])


def test_with_exact_altitudes_the_greedy_drop_walks_a_shortest_path():
    from jaxswarm.exact.field import distance_field
    # Few drops on a large map: with more drops or on a smaller map, the drops that draw their
    # moves walk a shortest path as well, and a greedy drop that did not would go unnoticed.
    chosen = paper_map("mosaic50")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    optimum = dijkstra(graph, chosen.start, chosen.goal).cost
    swarm = make("rfd_graded", num_agents=4, greedy_drops=1)
    params = swarm.default_params
    field = np.asarray(distance_field(graph, task.goal)) * np.asarray(params.erosion)
    state = swarm.init(jax.random.key(0), graph, task, params)
    for seed in range(3):
        state = dataclasses.replace(state, altitude=field, key=jax.random.key(seed))
        stepped, _ = swarm.step(state, graph, task, params)
        assert float(stepped.best_cost) == pytest.approx(optimum, rel=1e-5)


def test_greedy_drops_are_checked():
    with pytest.raises(ValueError, match=r"greedy_drops must be between 0 and num_agents \(4\)"):
        make("rfd_star", num_agents=4, greedy_drops=5)
    with pytest.raises(ValueError, match="greedy_drops must be between 0 and num_agents"):
        make("rfd_star", greedy_drops=-1)


def test_rfd_star_options_are_checked():
    with pytest.raises(ValueError, match="unknown erosion_law 'sideways'; choose one of linear"):
        make("rfd_star", erosion_law="sideways")
    with pytest.raises(ValueError, match="unknown erosion_law 'graded'"):  # that is rfd_graded
        make("rfd_star", erosion_law="graded")
    with pytest.raises(ValueError, match="unknown erode 'complete'; choose one of arrived, "
                                         "travelled"):
        make("rfd_star", erode="complete")
    with pytest.raises(ValueError, match="max_climb must be non-negative"):
        make("rfd_star", max_climb=-1.0)
    with pytest.raises(ValueError, match="unknown option 'climb' of rfd_star; known: num_agents"):
        make("rfd_star", climb=0.3)


NEVER = 2 ** 30
"""An iteration no run reaches."""


def _late_arrival_swarm() -> Swarm:
    """A stand-in swarm (no walking) whose params ``(first_path_at, improvements)`` say when its
    first path, of cost 100, appears (iteration, 1-based) and at which iterations (i32[2],
    :data:`NEVER` for none) the cost drops by one: one program for every such schedule."""
    def init(key, graph, task, params):
        return jnp.int32(0), jnp.float32(jnp.inf)

    def step(state, graph, task, params):
        first_path_at, improvements = params
        count = state[0] + 1
        cost = jnp.where(count >= first_path_at, 100.0, jnp.inf)
        cost = cost - jnp.sum(jnp.where(count >= improvements, 1.0, 0.0))
        info = StepInfo(iteration_cost=cost, arrived=jnp.float32(0), converged=jnp.array(False),
                        moves=jnp.int32(0), lane_steps=jnp.int32(0), evaluations=jnp.int32(0))
        return (count, cost.astype(jnp.float32)), info

    def best(state):
        return Solution(path=jnp.zeros((1,), jnp.int32), cost=state[1],
                        found=jnp.isfinite(state[1]))

    return Swarm(name="late", config=None, init=init, step=step, best=best,
                 default_params=None, check_params=lambda params: None)


LATE = _late_arrival_swarm()


@pytest.mark.parametrize("name", ["rfd_star", "ant_system"])
def test_a_run_stops_when_every_agent_followed_the_same_path(name, corridor):
    # On the corridor there is one path.
    graph, task = corridor
    swarm = make(name, **SMALL)
    _, trace = iterate(swarm, graph, task, swarm.default_params, budget=ITERATIONS)
    assert int(trace.iterations) == 1 and np.asarray(trace.arrived)[0] == 1.0


def test_keep_best_calls_an_iteration_converged_only_on_one_path_of_all_agents():
    @jax.jit
    def kept(paths, arrived, best_path, best_cost):
        """keep_best after a walk along ``paths`` (i32[A, L], -1 padded) in which ``arrived``
        (bool[A]) arrived, in one program (applied outside jit, dozens of operations and a
        program of its branch)."""
        moves = jnp.sum(paths >= 0, axis=1) - 1
        slots = jnp.where(paths[:, 1:] >= 0, paths[:, 1:], -1).astype(jnp.int16)  # one per node
        walk_ = Walk(log=from_rows(paths, slots, moves, paths[0, 0], paths.shape[1] - 1),
                     length=jnp.sum(paths >= 0, axis=1).astype(jnp.float32) - 1,
                     arrived=arrived, stuck=~arrived, position=paths[:, -1],
                     visited=jnp.zeros((len(paths), 1), jnp.uint32), moves=moves,
                     lane_steps=jnp.int32(paths.size))
        return keep_best(walk_, best_path, best_cost)

    best_path, best_cost = np.full(3, -1, np.int32), np.float32(np.inf)
    same, other = [[0, 1, 2]] * 3, [[0, 1, 2], [0, 3, 2], [0, 1, 2]]
    for paths, arrived, converged in [(same, [True] * 3, True), (other, [True] * 3, False),
                                      (same, [True, False, True], False)]:
        _, cost, info = kept(np.array(paths, np.int32), np.array(arrived), best_path, best_cost)
        assert bool(info.converged) == converged and float(cost) == 2.0


@pytest.mark.parametrize("first_path_at, improvements, stops_after", [
    (1, (), 1 + 5),          # patience counts from the first path ...
    (12, (), 12 + 5),        # ... however late it comes
    (12, (15, 19), 19 + 5),  # and restarts at every improvement
])
def test_patience_counts_iterations_without_gain_since_the_first_path(first_path_at,
                                                                       improvements, stops_after):
    graph = grid_graph(np.zeros((2, 2), bool))
    schedule = (jnp.int32(first_path_at),
                jnp.array(improvements + (NEVER,) * (2 - len(improvements)), jnp.int32))
    state, trace = run(LATE, jax.random.key(0), graph, make_task(graph, (0, 0), (1, 1)), schedule,
                       iterations=40, patience=5)
    assert int(trace.iterations) == stops_after
    assert np.asarray(trace.best_cost)[stops_after - 1] == 100.0 - len(improvements)


def test_a_patience_that_cannot_stop_a_run_is_none_and_shares_its_program():
    graph, task = sizes.maze()
    swarm = make("rfd", **sizes.CONFIG)
    key = jax.random.key(4)
    without = run(swarm, key, graph, task, swarm.default_params, iterations=sizes.ITERATIONS)
    with Compilations() as built:
        for patience in (sizes.ITERATIONS, sizes.ITERATIONS + 5):
            same = run(swarm, key, graph, task, swarm.default_params,
                       iterations=sizes.ITERATIONS, patience=patience)
            np.testing.assert_array_equal(same[1].best_cost, without[1].best_cost)
            np.testing.assert_array_equal(same[0].altitude, without[0].altitude)
    assert built.count == 0, built.names


@pytest.mark.parametrize("field, value, message", [
    ("p_base", float("nan"), "p_base must be finite"),
    ("p_base", 0.0, "p_base must be positive"),
    ("p_base", -2.0, "p_base must be positive"),
    ("alpha", float("inf"), "alpha must be finite"),
    ("sediment", -1.0, "sediment must be non-negative"),
    ("erosion", 0.0, "erosion must be positive"),  # the graded law's slope
    ("repose", -0.1, "repose must be non-negative"),
])
def test_bad_params_are_named(field, value, message):
    graph, task = sizes.maze()
    swarm = make("rfd_graded", **SMALL)
    params = swarm.default_params._replace(**{field: jnp.float32(value)})
    with pytest.raises(ValueError, match=message):
        run(swarm, jax.random.key(0), graph, task, params, iterations=2)


def test_bad_sizes_and_endpoints_are_named():
    graph, task = sizes.maze()
    with pytest.raises(ValueError, match="num_agents must be at least 1, got 0"):
        make("rfd_star", num_agents=0)
    with pytest.raises(ValueError, match="iterations must be at least 1"):
        run(make("rfd", **SMALL), jax.random.key(0), graph, task, make("rfd").default_params,
            iterations=0)
    with pytest.raises(ValueError, match="goal .* is blocked"):
        make_task(graph, (0, 0), (1, 1))


