"""Intelligent Water Drops: each equation against a hand computation, the soil updates of drops
that arrived applied after the walk in agent order, the soil updates of drops that share an edge
in one step applied in lane order (``while_walking``), bit-identically, the walker hook, and
drops that back out of dead ends."""
import functools

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import sizes

from jaxswarm.maps.paper import paper_map
from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.iwd import STANDARD_IWD, global_update, soil_taken, velocity_after
from jaxswarm.swarm.iwd.iwd import FEW_DROPS, drop_walk, goal_table
from jaxswarm.swarm.iwd.soil import (SOIL, arrived_update, choice_log_weights,
                                     goal_log_desirability, walked_soil)
from jaxswarm.swarm.walking import FORCED, edge_table, walk
from jaxswarm.swarm.walking.hooks import UNCLAIMED, Move, edge_groups
from jaxswarm.swarm.walking.moves import NARROWEST
from jaxswarm.world.graph import grid_graph
from jaxswarm.world.paths import step_slots

P = STANDARD_IWD
EAST = 0  # slot of the move (x, y) -> (x + 1, y)


def per_lane(params, lanes):
    return jax.tree_util.tree_map(lambda p: np.full((lanes,), p, np.float32), params)


# The equations under test, each called from the tests through one jitted wrapper: one program
# per shape, where called outside jit each of their JAX operations is a program of its own.
log_weights = jax.jit(choice_log_weights)
desirability = jax.jit(goal_log_desirability)
arrived_soil = jax.jit(arrived_update)
best_path_soil = jax.jit(global_update)


@jax.jit
def walked(graph, soil, here, slots, params):
    """:func:`walked_soil` and the soil each walk took in all (:func:`ordered_sum` over its
    moves): ``(taken, velocity, carried)``."""
    taken, velocity = walked_soil(graph, soil, here, slots, params)
    return taken, velocity, ordered_sum(taken, axis=1)


def test_choice_shifts_negative_soil_and_weighs_the_goal_by_inverse_distance():
    rows = np.array([[5.0, -3.0, 2.0, 7.0]], np.float32)
    admissible = np.array([[True, True, False, True]])
    got = np.asarray(log_weights(per_lane(P, 1), rows, admissible))[0]
    # The smallest admissible soil is -3 < 0: g = s + 3 on the admissible slots (eq. 3).
    want = [-np.log(0.01 + 8), -np.log(0.01 + 0), 0.0, -np.log(0.01 + 10)]
    np.testing.assert_allclose(got, want, rtol=1e-6)
    positive = np.asarray(log_weights(per_lane(P, 1), np.abs(rows), admissible))[0]
    np.testing.assert_allclose(positive[[0, 1, 3]], -np.log(0.01 + np.array([5, 3, 7])),
                               rtol=1e-6)
    graph = grid_graph(np.zeros((3, 3), bool))
    h = np.asarray(desirability(graph, 8))
    assert h[4, 4] == FORCED  # the centre's SE move enters the goal (2, 2)
    assert h[0, EAST] == pytest.approx(-np.log(np.hypot(1, 2)))  # (1, 0) is sqrt 5 away


def test_velocity_and_soil_taken_eq_4():
    v = float(velocity_after(P, jnp.float32(200.0), jnp.float32(3.0)))
    assert v == pytest.approx(200 + 1 / (0.01 + 9))
    taken = float(soil_taken(P, jnp.float32(np.sqrt(2)), jnp.float32(4.0)))
    assert taken == pytest.approx(1 / (0.01 + (np.sqrt(2) / 4) ** 2), rel=1e-6)
    slow = float(soil_taken(P, jnp.float32(1.0), jnp.float32(0.0)))  # eps_v keeps time finite
    assert slow == pytest.approx(1 / (0.01 + (1 / 1e-4) ** 2), rel=1e-5)


def test_hud_scale_makes_the_soil_taken_depend_on_the_edge_length():
    # HUD = 1 x length: time^2 = 2.5e-5 (straight) or 5e-5 (diagonal) against b_s = 0.01.
    straight, diagonal = (float(soil_taken(P, jnp.float32(n), jnp.float32(200.0)))
                          for n in (1.0, np.sqrt(2)))
    assert straight == pytest.approx(1 / (0.01 + 2.5e-5), rel=1e-5)
    assert diagonal / straight > 0.997  # the length hardly matters
    # HUD = 20 x length: time = 0.1 or 0.141, soil taken 1 / 0.02 = 50 and 1 / 0.03 = 33.3.
    scaled = P._replace(hud_scale=jnp.float32(20.0))
    straight, diagonal = (float(soil_taken(scaled, jnp.float32(n), jnp.float32(200.0)))
                          for n in (1.0, np.sqrt(2)))
    assert straight == pytest.approx(50.0, rel=1e-5)
    assert diagonal == pytest.approx(100 / 3, rel=1e-5)


def test_walked_soil_is_the_velocity_update_and_eq_4_along_a_path():
    graph = grid_graph(np.zeros((1, 3), bool))  # 0 - 1 - 2
    soil = np.full(graph.nbr.shape, 10.0, np.float32)
    soil[1, EAST] = 2.0
    path = np.array([[0, 1, 2], [0, 1, -1]], np.int32)
    slots = np.array([[EAST, EAST], [EAST, -1]], np.int8)
    taken, velocity, _ = jax.device_get(walked(graph, soil, path[:, :-1], slots, P))
    v1 = 200 + 1 / (0.01 + 100)  # the velocity after 0 -> 1 (soil 10)
    v2 = v1 + 1 / (0.01 + 4)  # after 1 -> 2 (soil 2)
    np.testing.assert_allclose(taken[0],
                               [1 / (0.01 + (1 / v1) ** 2), 1 / (0.01 + (1 / v2) ** 2)],
                               rtol=1e-6)
    assert taken[1, 1] == 0.0
    np.testing.assert_allclose(velocity, [v2, v1], rtol=1e-6)


def test_an_arrived_drop_updates_the_soil_of_its_moves_by_eq_5():
    graph = grid_graph(np.zeros((1, 3), bool))  # 0 - 1 - 2
    soil = np.full(graph.nbr.shape, 1000.0, np.float32)
    here = np.array([0, 1, -1], np.int32)
    slots = np.array([EAST, EAST, -1], np.int8)
    taken = np.array([10.0, 20.0, 0.0], np.float32)
    after = np.asarray(arrived_soil(graph, soil, here, slots, taken, P))
    assert after[0, EAST] == pytest.approx(0.1 * 1000 - 0.9 * 10, rel=1e-6)
    assert after[1, EAST] == pytest.approx(0.1 * 1000 - 0.9 * 20, rel=1e-6)
    untouched = np.ones(after.shape, bool)
    untouched[[0, 1], EAST] = False
    assert np.all(after[untouched] == 1000.0)


SIDE = 24
"""The side of the grids the drops walk on (a smaller map is cut out of one by obstacles): one
program of :func:`drops_of` for all of them."""


def cut_out(obstacles):
    """A SIDE x SIDE grid, ``obstacles`` (bool[H, W]) in its corner and blocked elsewhere."""
    grid = np.ones((SIDE, SIDE), bool)
    grid[:obstacles.shape[0], :obstacles.shape[1]] = obstacles
    return grid_graph(grid)


def comb():
    """A corridor (0, 0) .. (4, 0) with dead ends below (1, 0) and (3, 0), and its task from end
    to end."""
    obstacles = np.zeros((2, 5), bool)
    obstacles[1, [0, 2, 4]] = True  # the row below is a comb
    graph = cut_out(obstacles)
    return graph, make_task(graph, (0, 0), (4, 0))


@functools.partial(jax.jit, static_argnames=("backtrack",))
def drops_of(key, graph, task, soil, params, *, backtrack=False):
    """:func:`drop_walk` of 32 drops in the map's step budget over ``soil``, f32[N, K] (a
    weakly typed one, ``jnp.full`` of a Python float, would be a program of its own). One
    program for every SIDE x SIDE map (the map, task, soil and params are arguments), and one
    with ``backtrack``."""
    return drop_walk(key, graph, task, soil, params, num_agents=32, max_steps=None,
                     backtrack=backtrack)


@jax.jit
def drop_batches(keys, graph, tasks, soil, params):
    """:func:`drops_of` of each of ``keys`` with its task of ``tasks`` (an outer ``vmap``, the
    params shared) and each of ``params`` (an inner one): one program for the tests of
    batches."""
    return jax.vmap(lambda key, task: jax.vmap(
        lambda p: drops_of(key, graph, task, soil, p))(params))(keys, tasks)


def stack(*trees):
    """The pytrees stacked leaf by leaf along a new leading axis."""
    return jax.tree_util.tree_map(lambda *x: jnp.stack(x), *trees)


def assert_sequential_soil(graph, soil, drops):
    """The drops' soil and states equal a loop over the arrived drops in agent order and their
    moves in move order (NumPy float32, the soil taken over each whole row), bit for bit; the
    other drops' states NaN. Returns the expected soil."""
    here, slots = np.asarray(drops.path)[:, :-1], np.asarray(drops.slots)
    taken, velocity, carried = jax.device_get(walked(graph, soil, here, slots, P))
    expected = np.asarray(soil).copy()
    keep, rho = np.float32(1) - np.float32(P.rho_n), np.float32(P.rho_n)
    arrived = np.asarray(drops.arrived)
    for a, m in np.argwhere(arrived[:, None] & (slots >= 0)):
        node, slot = here[a, m], slots[a, m]
        expected[node, slot] = keep * expected[node, slot] - rho * taken[a, m]
    np.testing.assert_array_equal(np.asarray(drops.memory), expected)
    state = np.asarray(drops.state)
    np.testing.assert_array_equal(state[arrived, 0], velocity[arrived])
    np.testing.assert_array_equal(state[arrived, 1], carried[arrived])
    assert np.isnan(state[~arrived]).all()
    return expected


def test_arrived_drops_update_the_soil_after_the_walk_in_agent_order():
    # Drops share the corridor's edges: the order of their updates is part of the rule. A wall
    # shuts the right end off, where the second task's goal lies.
    blocked = np.zeros((3, 9), bool)
    blocked[:, 6] = True
    graph = cut_out(blocked)
    tasks = [make_task(graph, (0, 1), goal) for goal in ((5, 1), (8, 1))]
    soil = jax.random.uniform(jax.random.key(3), graph.nbr.shape, minval=900.0, maxval=1100.0)
    drops = drops_of(jax.random.key(2), graph, tasks[0], soil, P)
    assert np.asarray(drops.arrived).sum() >= 2
    expected = assert_sequential_soil(graph, soil, drops)
    # A batch of that run and one whose drops cannot arrive, each under an inner batch of the
    # same params twice: each run's soil as alone.
    batch = drop_batches(stack(jax.random.key(2), jax.random.key(2)), graph, stack(*tasks),
                         soil, per_lane(P, 2))
    assert not np.asarray(batch.arrived)[1].any()
    memory = np.asarray(batch.memory)
    for member in range(2):
        np.testing.assert_array_equal(memory[0, member], expected)
        np.testing.assert_array_equal(memory[1, member], np.asarray(soil))


def test_few_drops_update_the_soil_in_one_pass_as_a_loop_over_them_does():
    # Up to FEW_DROPS drops (IWD_PG's local searches) take one pass over their walks (eq. 4
    # for all at once, eq. 5 drop by drop): the soil and states of the loop in agent order.
    blocked = np.zeros((3, 9), bool)
    blocked[:, 6] = True
    graph = cut_out(blocked)
    task = make_task(graph, (0, 1), (5, 1))
    soil = jax.random.uniform(jax.random.key(3), graph.nbr.shape, minval=900.0, maxval=1100.0)
    drops = few_drops(jax.random.key(2), graph, task, soil, P)
    assert drops.arrived.shape[0] <= FEW_DROPS and np.asarray(drops.arrived).sum() >= 2
    assert_sequential_soil(graph, soil, drops)


@jax.jit
def few_drops(key, graph, task, soil, params):
    """:func:`drop_walk` of 8 drops (below :data:`FEW_DROPS`)."""
    return drop_walk(key, graph, task, soil, params, num_agents=8, max_steps=None)


def test_the_goal_table_on_grids_is_the_edge_table_of_the_goal_desirability():
    graph, task = sizes.maze()
    fast = jax.jit(goal_table)(graph, task.goal, P)
    composed = jax.jit(lambda graph, goal, params: edge_table(
        graph, params.beta * goal_log_desirability(graph, goal)))(graph, task.goal, P)
    assert np.asarray(fast).tobytes() == np.asarray(composed).tobytes()


def test_arrived_drops_leave_the_soil_of_stuck_drops_alone():
    # Dead ends beside the corridor: drops that enter them get stuck.
    graph, task = comb()
    table_soil = np.full(graph.nbr.shape, 10_000.0, np.float32)
    drops = drops_of(jax.random.key(1), graph, task, table_soil, P)
    arrived, path, moved = (np.asarray(x) for x in (drops.arrived, drops.path, drops.slots))
    assert arrived.any() and (~arrived).any()
    changed = np.asarray(drops.memory) != 10_000.0
    rows, slots = np.nonzero(changed)
    arrived_moves = {(int(n), int(k)) for a in np.flatnonzero(arrived)
                     for n, k in zip(path[a, :-1], moved[a]) if k >= 0}
    assert set(zip(rows.tolist(), slots.tolist())) == arrived_moves
    carried = np.asarray(drops.state)[:, 1]
    assert np.all(carried[arrived] > 0)


def test_drops_that_did_not_arrive_change_nothing_and_do_not_widen_the_work_after_the_walk():
    # On an open grid the arrived drops' walks fit the narrowest width of the work after a
    # walk (128 moves), some drops that did not arrive walk longer.
    graph = grid_graph(np.zeros((SIDE, SIDE), bool))
    task = make_task(graph, (0, 0), (10, 10))
    soil = jax.random.uniform(jax.random.key(2), graph.nbr.shape, minval=9_000.0, maxval=11_000.0)
    drops = drops_of(jax.random.key(0), graph, task, soil, P)
    moves, arrived = np.asarray(drops.moves), np.asarray(drops.arrived)
    assert moves[arrived].max() <= NARROWEST < moves[~arrived].max()
    # Every drop's whole row, as before the cut: the same bits for the arrived drops.
    assert_sequential_soil(graph, soil, drops)


def test_backtracking_drops_back_out_of_dead_ends():
    graph, task = comb()
    soil = np.full(graph.nbr.shape, 10_000.0, np.float32)
    drops = drops_of(jax.random.key(1), graph, task, soil, P, backtrack=True)
    assert np.asarray(drops.arrived).all()
    paths = np.asarray(drops.path)
    for path, moves in zip(paths, np.asarray(drops.moves)):
        nodes = path[path >= 0]
        assert nodes[0] == 0 and nodes[-1] == 4 and len(set(nodes)) == len(nodes)
        assert moves >= len(nodes) - 1  # back-outs count as moves
    assert np.asarray(drops.moves).max() > (paths >= 0).sum(axis=1).max() - 1  # one backed out
    with pytest.raises(ValueError, match="backtrack=True needs local_updates='arrived'"):
        make("iwd", backtrack=True, local_updates="while_walking")
    with pytest.raises(ValueError, match="unknown local_updates 'all'"):
        make("iwd", local_updates="all")


def step_groups(run, here, slot, moving, runs, graph):
    """The walker's grouping of one step's lanes (fresh claims), and the claims after it."""
    run, here, slot = (jnp.asarray(x, jnp.int32) for x in (run, here, slot))
    claims = jnp.full((runs * graph.num_nodes,), UNCLAIMED, jnp.int32)
    return edge_groups(run, here, slot, moving, claims, graph.num_nodes, graph.max_degree)


@functools.partial(jax.jit, static_argnames=("runs",))
def grouped(run, here, slot, moving, graph, values=None, *, runs):
    """:func:`step_groups` in one program: each lane's rank and count in its group, whether it
    is its group's first, the sums of ``values`` (f32[l], if given) over its group, and the
    claims after it."""
    groups, claims = step_groups(run, here, slot, moving, runs, graph)
    sums = None if values is None else groups.group_sum(values)
    return groups.rank, groups.count, groups.first, sums, claims


@jax.jit
def soil_update(params, soil, move, graph):
    """:data:`SOIL`'s update of one step's ``move``, whose groups (None) are the lanes'
    :func:`step_groups`: ``(soil, states, rank, count)``, the last two the groups' per lane."""
    groups, _ = step_groups(move.run, move.here, move.slot, move.moving, soil.shape[0], graph)
    after, state = SOIL.update(params, soil, move._replace(groups=groups), graph)
    return after, state, groups.rank, groups.count


def test_edge_groups_match_a_count_by_brute_force():
    graph = grid_graph(np.zeros((2, 2), bool))
    rng = np.random.default_rng(3)
    lanes, runs = 200, 3
    run, here = rng.integers(0, runs, lanes), rng.integers(0, 4, lanes)
    slot, moving = rng.integers(0, 3, lanes), rng.random(lanes) < 0.8
    values = rng.random(lanes).astype(np.float32)
    got_rank, got_count, first, sums, claims = grouped(run, here, slot, moving, graph, values,
                                                       runs=runs)
    edge = [(r, h, s) if m else None for r, h, s, m in zip(run, here, slot, moving)]
    rank = [sum(edge[j] == edge[i] for j in range(i)) if edge[i] else 0 for i in range(lanes)]
    count = [edge.count(edge[i]) if edge[i] else 0 for i in range(lanes)]
    assert got_rank.tolist() == rank and got_count.tolist() == count
    assert first.tolist() == [bool(m) and r == 0 for m, r in zip(moving, rank)]
    want = [sum(values[j] for j in range(lanes) if edge[j] == edge[i]) if edge[i] else 0.0
            for i in range(lanes)]
    np.testing.assert_allclose(np.asarray(sums), want, rtol=1e-5)
    assert np.all(np.asarray(claims) == UNCLAIMED)  # ready for the next step


def test_edge_groups_of_more_lanes_than_one_sort_key_holds():
    # 2^15 lanes of 8 slots: groups need 19 bits and lanes 15, more than one u32 sort key.
    graph = grid_graph(np.zeros((2, 2), bool))
    rng = np.random.default_rng(5)
    lanes, runs = 1 << 15, 2
    run, here = rng.integers(0, runs, lanes), rng.integers(0, 4, lanes)
    slot, moving = rng.integers(0, 3, lanes), rng.random(lanes) < 0.9
    got_rank, got_count, *_ = grouped(run, here, slot, moving, graph, runs=runs)
    edge = np.where(moving, (run * 4 + here) * 3 + slot, -1)
    order = np.argsort(edge, kind="stable")
    sorted_edge = edge[order]
    starts = np.searchsorted(sorted_edge, sorted_edge, side="left")
    rank, count = np.zeros(lanes, int), np.zeros(lanes, int)
    rank[order] = np.arange(lanes) - starts
    count[order] = np.searchsorted(sorted_edge, sorted_edge, side="right") - starts
    assert got_rank.tolist() == np.where(moving, rank, 0).tolist()
    assert got_count.tolist() == np.where(moving, count, 0).tolist()


def test_drops_on_one_edge_in_one_step_update_it_in_lane_order():
    graph = grid_graph(np.zeros((1, 3), bool))
    soil = np.full((2,) + graph.nbr.shape, 50.0, np.float32)
    velocities = np.array([300.0, 100.0, 200.0, 250.0], np.float32)
    # Lanes 0, 2 and 3 cross 0 -> 1 in run 0; lane 1 crosses it in run 1.
    move = Move(run=np.array([0, 1, 0, 0], np.int32), agent=np.array([5, 0, 1, 2], np.int32),
                here=np.zeros(4, np.int32), slot=np.full((4,), EAST, np.int32),
                moving=np.ones(4, bool), groups=None,
                state=np.stack([velocities, np.zeros(4, np.float32)], axis=-1))
    after, state, rank, count = jax.device_get(soil_update(per_lane(P, 4), soil, move, graph))
    assert rank.tolist() == [0, 0, 1, 2] and count.tolist() == [3, 1, 3, 3]
    taken = [1 / (0.01 + (1 / (float(v) + 1 / (0.01 + 50.0 ** 2))) ** 2) for v in velocities]
    s = 50.0
    for lane in (0, 2, 3):  # by hand, in lane order, each drop's taken soil from the soil 50
        s = 0.1 * s - 0.9 * taken[lane]
    assert float(after[0, 0, EAST]) == pytest.approx(s, rel=1e-5)
    assert float(after[1, 0, EAST]) == pytest.approx(0.1 * 50.0 - 0.9 * taken[1], rel=1e-5)
    np.testing.assert_allclose(state[:, 1], taken, rtol=1e-6)
    untouched = np.ones(after.shape, bool)
    untouched[:, 0, EAST] = False
    assert np.all(after[untouched] == 50.0)
    move = move._replace(moving=np.zeros(4, bool), slot=np.full((4,), -1, np.int32))
    same, kept, *_ = jax.device_get(soil_update(per_lane(P, 4), soil, move, graph))
    assert np.array_equal(same, soil)
    assert np.array_equal(kept, move.state)


def test_two_drops_down_a_corridor_while_walking_by_hand_and_bit_identically():
    graph = grid_graph(np.zeros((1, 3), bool))  # 0 - 1 - 2, goal 2
    table = edge_table(graph, desirability(graph, 2))
    soil = jnp.full(graph.nbr.shape, 10_000.0)

    def drops(key):
        return walk(key, graph, table, 0, 2, num_agents=2, max_steps=4, hook=SOIL,
                    memory=soil, hook_params=P)

    first, again = drops(jax.random.key(0)), drops(jax.random.key(0))
    for a, b in zip(jax.tree_util.tree_leaves(first), jax.tree_util.tree_leaves(again)):
        assert np.array_equal(np.asarray(a), np.asarray(b))
    assert np.asarray(first.arrived).all()
    assert np.asarray(first.path)[:, :3].tolist() == [[0, 1, 2]] * 2
    v1 = 200 + 1 / (0.01 + 1e8)
    d1 = 1 / (0.01 + (1 / v1) ** 2)
    # Both drops cross 0 -> 1 in the first step and 1 -> 2 in the second (eq. 5 twice a step).
    want = 0.01 * 10_000 - 0.09 * d1 - 0.9 * d1  # ~1.25: float32 cancels digits of 100 - 98.75
    memory, state = np.asarray(first.memory), np.asarray(first.state)
    assert float(memory[0, EAST]) == pytest.approx(want, abs=1e-3)
    assert float(memory[1, EAST]) == pytest.approx(want, abs=1e-3)
    np.testing.assert_allclose(state[:, 1], 2 * d1, rtol=1e-5)
    np.testing.assert_allclose(state[:, 0], 200 + 2 / (0.01 + 1e8), rtol=1e-6)


def test_global_update_on_the_best_path():
    graph = grid_graph(np.zeros((3, 3), bool))
    soil = np.arange(72, dtype=np.float32).reshape(9, 8)
    path = np.array([0, 4, 8, -1], np.int32)
    after = np.asarray(best_path_soil(graph, soil, path, np.float32(30.0), P))
    slots = np.asarray(step_slots(graph, path))[:2]
    for node, slot in zip((0, 4), slots):
        assert after[node, slot] == pytest.approx(1.9 * float(soil[node, slot]) - 0.9 * 30 / 2)
    changed = np.zeros((9, 8), bool)
    changed[[0, 4], slots] = True
    assert np.array_equal(after[~changed], soil[~changed])


def test_iwd_finds_the_corridor_and_its_soil_falls_along_it():
    graph = sizes.cut_out([[True] * 6])  # a corridor (0, 0) .. (5, 0)
    swarm = make("iwd", **sizes.CONFIG)
    state, trace = run(swarm, jax.random.key(0), graph, make_task(graph, 0, 5),
                       swarm.default_params, iterations=sizes.ITERATIONS, budget=3)
    assert float(swarm.best(state).cost) == pytest.approx(5.0)
    soil, initial = np.asarray(state.soil), swarm.default_params.initial_soil
    assert np.all(soil[:5, EAST] < initial) and np.all(soil[:, 2] == initial)  # no west moves


def test_bad_params_are_named():
    swarm = make("iwd")
    with pytest.raises(ValueError, match="rho_n must be at most 1"):
        swarm.check_params(swarm.default_params._replace(rho_n=np.float32(1.5)))
    with pytest.raises(ValueError, match="initial_velocity must be positive"):
        swarm.check_params(swarm.default_params._replace(initial_velocity=np.float32(0)))


def test_every_run_counts_its_fitness_calls():
    graph, task = sizes.maze()
    for name in ("iwd", "aco_star"):
        swarm = make(name, **sizes.CONFIG)
        _, trace = run(swarm, jax.random.key(2), graph, task, swarm.default_params,
                       iterations=sizes.ITERATIONS)
        used = int(trace.iterations)
        evaluations = np.asarray(trace.evaluations)
        # One call per agent that arrived: a complete path whose length was evaluated.
        np.testing.assert_array_equal(evaluations[:used],
                                      np.round(np.asarray(trace.arrived)[:used] * sizes.AGENTS))
        assert evaluations[used:].sum() == 0 and evaluations.sum() > 0


@pytest.mark.slow
def test_drops_that_arrive_find_mosaic50_where_drops_that_all_take_soil_did_not():
    """With Shah-Hosseini's standard values (the defaults before 0.8.0's calibration): a path
    in 6 of 6 seeds, and in at most 2 when every drop takes soil as it walks."""
    
    chosen = paper_map("mosaic50")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    keys = jax.random.split(jax.random.key(0), 6)
    found = {}
    for reading in ("arrived", "while_walking"):
        swarm = make("iwd", local_updates=reading)
        states, _ = jax.jit(jax.vmap(lambda k: run(swarm, k, graph, task, STANDARD_IWD,
                                                   iterations=100, patience=30)))(keys)
        found[reading] = int(np.isfinite(np.asarray(states.best_cost)).sum())
    assert found["arrived"] == 6 and found["while_walking"] <= 2, found


def test_hook_params_of_an_inner_vmap_reach_every_member_of_an_outer_one():
    # Keys (and their task) outside, params shared; params inside: the outer batch rule meets
    # params that the inner one folded to one per run; each member must walk with its own.
    graph = grid_graph(np.zeros((SIDE, SIDE), bool))
    task = make_task(graph, (0, 0), (7, 7))
    soil = jax.random.uniform(jax.random.key(5), graph.nbr.shape, minval=1.0, maxval=10_000.0)
    keys = jax.random.split(jax.random.key(0), 2)
    params = per_lane(P, 2)._replace(alpha=np.array([0.0, 3.0], np.float32))
    nested = np.asarray(drop_batches(keys, graph, stack(task, task), soil, params).moves)
    for i in range(2):
        for j in range(2):
            alone = drops_of(keys[i], graph, task, soil,
                             jax.tree_util.tree_map(lambda x, j=j: x[j], params)).moves
            np.testing.assert_array_equal(nested[i, j], alone, err_msg=f"key {i}, params {j}")
