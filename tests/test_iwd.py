"""Intelligent Water Drops: each equation against a hand computation, the soil updates of drops
that share an edge in one step applied in lane order, bit-identically, and the walker hook."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.iwd import DEFAULT_IWD, global_update, soil_taken, velocity_after
from jaxswarm.swarm.iwd.soil import SOIL, choice_log_weights, goal_log_desirability
from jaxswarm.swarm.walking import FORCED, edge_table, walk
from jaxswarm.swarm.walking.hooks import UNCLAIMED, Move, edge_groups
from jaxswarm.world.graph import grid_graph
from jaxswarm.world.paths import step_slots

P = DEFAULT_IWD
EAST = 0  # slot of the move (x, y) -> (x + 1, y)


def per_lane(params, lanes):
    return jax.tree_util.tree_map(lambda p: jnp.full((lanes,), p, jnp.float32), params)


def test_choice_shifts_negative_soil_and_weighs_the_goal_by_inverse_distance():
    rows = jnp.array([[5.0, -3.0, 2.0, 7.0]])
    admissible = jnp.array([[True, True, False, True]])
    got = np.asarray(choice_log_weights(per_lane(P, 1), rows, admissible))[0]
    # The smallest admissible soil is -3 < 0: g = s + 3 on the admissible slots (eq. 3).
    want = [-np.log(0.01 + 8), -np.log(0.01 + 0), 0.0, -np.log(0.01 + 10)]
    np.testing.assert_allclose(got, want, rtol=1e-6)
    positive = np.asarray(choice_log_weights(per_lane(P, 1), jnp.abs(rows), admissible))[0]
    np.testing.assert_allclose(positive[[0, 1, 3]], -np.log(0.01 + np.array([5, 3, 7])),
                               rtol=1e-6)
    graph = grid_graph(np.zeros((3, 3), bool))
    h = np.asarray(goal_log_desirability(graph, 8))
    assert h[4, 4] == FORCED  # the centre's SE move enters the goal (2, 2)
    assert h[0, EAST] == pytest.approx(-np.log(np.hypot(1, 2)))  # (1, 0) is sqrt 5 away


def test_velocity_and_soil_taken_are_eqs_4_and_5():
    v = float(velocity_after(P, jnp.float32(200.0), jnp.float32(3.0)))
    assert v == pytest.approx(200 + 1 / (0.01 + 9))
    taken = float(soil_taken(P, jnp.float32(np.sqrt(2)), jnp.float32(4.0)))
    assert taken == pytest.approx(1 / (0.01 + (np.sqrt(2) / 4) ** 2), rel=1e-6)
    slow = float(soil_taken(P, jnp.float32(1.0), jnp.float32(0.0)))  # eps_v keeps time finite
    assert slow == pytest.approx(1 / (0.01 + (1 / 1e-4) ** 2), rel=1e-5)


def step_groups(run, here, slot, moving, runs, graph):
    """The walker's grouping of one step's lanes (fresh claims), and the claims after it."""
    run, here, slot = (jnp.asarray(x, jnp.int32) for x in (run, here, slot))
    claims = jnp.full((runs * graph.num_nodes,), UNCLAIMED, jnp.int32)
    return edge_groups(run, here, slot, jnp.asarray(moving), claims, graph.num_nodes,
                       graph.max_degree)


def test_edge_groups_match_a_count_by_brute_force():
    graph = grid_graph(np.zeros((2, 2), bool))
    rng = np.random.default_rng(3)
    lanes, runs = 200, 3
    run, here = rng.integers(0, runs, lanes), rng.integers(0, 4, lanes)
    slot, moving = rng.integers(0, 3, lanes), rng.random(lanes) < 0.8
    groups, claims = step_groups(run, here, slot, moving, runs, graph)
    edge = [(r, h, s) if m else None for r, h, s, m in zip(run, here, slot, moving)]
    rank = [sum(edge[j] == edge[i] for j in range(i)) if edge[i] else 0 for i in range(lanes)]
    count = [edge.count(edge[i]) if edge[i] else 0 for i in range(lanes)]
    assert groups.rank.tolist() == rank and groups.count.tolist() == count
    assert groups.first.tolist() == [bool(m) and r == 0 for m, r in zip(moving, rank)]
    values = rng.random(lanes).astype(np.float32)
    want = [sum(values[j] for j in range(lanes) if edge[j] == edge[i]) if edge[i] else 0.0
            for i in range(lanes)]
    np.testing.assert_allclose(groups.group_sum(jnp.asarray(values)), want, rtol=1e-5)
    assert np.all(np.asarray(claims) == UNCLAIMED)  # ready for the next step


def test_drops_on_one_edge_in_one_step_update_it_in_lane_order():
    graph = grid_graph(np.zeros((1, 3), bool))
    soil = jnp.full((2,) + graph.nbr.shape, 50.0)
    velocities = jnp.array([300.0, 100.0, 200.0, 250.0])
    # Lanes 0, 2 and 3 cross 0 -> 1 in run 0; lane 1 crosses it in run 1.
    run, here = jnp.array([0, 1, 0, 0]), jnp.zeros(4, jnp.int32)
    slot, moving = jnp.full((4,), EAST, jnp.int32), jnp.ones(4, bool)
    groups, _ = step_groups(run, here, slot, moving, 2, graph)
    assert groups.rank.tolist() == [0, 0, 1, 2] and groups.count.tolist() == [3, 1, 3, 3]
    move = Move(run=run, agent=jnp.array([5, 0, 1, 2]), here=here, slot=slot, moving=moving,
                state=jnp.stack([velocities, jnp.zeros(4)], axis=-1), groups=groups)
    after, state = SOIL.update(per_lane(P, 4), soil, move, graph)
    taken = [1 / (0.01 + (1 / (float(v) + 1 / (0.01 + 50.0 ** 2))) ** 2) for v in velocities]
    s = 50.0
    for lane in (0, 2, 3):  # by hand, in lane order, each drop's taken soil from the soil 50
        s = 0.1 * s - 0.9 * taken[lane]
    assert float(after[0, 0, EAST]) == pytest.approx(s, rel=1e-5)
    assert float(after[1, 0, EAST]) == pytest.approx(0.1 * 50.0 - 0.9 * taken[1], rel=1e-5)
    np.testing.assert_allclose(np.asarray(state[:, 1]), taken, rtol=1e-6)
    untouched = np.ones(after.shape, bool)
    untouched[:, 0, EAST] = False
    assert np.all(np.asarray(after)[untouched] == 50.0)
    still = jnp.zeros(4, bool)
    move = move._replace(moving=still, slot=jnp.full((4,), -1),
                         groups=step_groups(run, here, slot, still, 2, graph)[0])
    same, kept = SOIL.update(per_lane(P, 4), soil, move, graph)
    assert np.array_equal(np.asarray(same), np.asarray(soil))
    assert np.array_equal(np.asarray(kept), np.asarray(move.state))


def test_two_drops_down_a_corridor_by_hand_and_bit_identically():
    graph = grid_graph(np.zeros((1, 3), bool))  # 0 - 1 - 2, goal 2
    table = edge_table(graph, goal_log_desirability(graph, 2))
    soil = jnp.full(graph.nbr.shape, 10_000.0)

    def drops(key):
        return walk(key, graph, table, 0, 2, num_agents=2, max_steps=4, hook=SOIL,
                    memory=soil, hook_params=P)

    first, again = drops(jax.random.key(0)), drops(jax.random.key(0))
    for a, b in zip(jax.tree_util.tree_leaves(first), jax.tree_util.tree_leaves(again)):
        assert np.array_equal(np.asarray(a), np.asarray(b))
    assert first.arrived.all() and np.asarray(first.path)[:, :3].tolist() == [[0, 1, 2]] * 2
    v1 = 200 + 1 / (0.01 + 1e8)
    d1 = 1 / (0.01 + (1 / v1) ** 2)
    # Both drops cross 0 -> 1 in the first step and 1 -> 2 in the second (eq. 6 twice a step).
    want = 0.01 * 10_000 - 0.09 * d1 - 0.9 * d1  # ~1.25: float32 cancels digits of 100 - 98.75
    assert float(first.memory[0, EAST]) == pytest.approx(want, abs=1e-3)
    assert float(first.memory[1, EAST]) == pytest.approx(want, abs=1e-3)
    np.testing.assert_allclose(np.asarray(first.state[:, 1]), 2 * d1, rtol=1e-5)
    np.testing.assert_allclose(np.asarray(first.state[:, 0]), 200 + 2 / (0.01 + 1e8), rtol=1e-6)


def test_global_update_on_the_best_path():
    graph = grid_graph(np.zeros((3, 3), bool))
    soil = jnp.arange(72, dtype=jnp.float32).reshape(9, 8)
    path = jnp.array([0, 4, 8, -1])
    after = np.asarray(global_update(graph, soil, path, jnp.float32(30.0), P))
    slots = np.asarray(step_slots(graph, path))[:2]
    for node, slot in zip((0, 4), slots):
        assert after[node, slot] == pytest.approx(1.9 * float(soil[node, slot]) - 0.9 * 30 / 2)
    changed = np.zeros((9, 8), bool)
    changed[[0, 4], slots] = True
    assert np.array_equal(after[~changed], np.asarray(soil)[~changed])


def test_iwd_finds_the_corridor_and_its_soil_falls_along_it():
    graph = grid_graph(np.zeros((1, 6), bool))
    swarm = make("iwd", num_agents=4)
    state, trace = run(swarm, jax.random.key(0), graph, make_task(graph, 0, 5),
                       swarm.default_params, iterations=3)
    assert float(swarm.best(state).cost) == pytest.approx(5.0)
    soil = np.asarray(state.soil)
    assert np.all(soil[:5, EAST] < 10_000) and np.all(soil[:, 2] == 10_000)  # no west moves


def test_bad_params_are_named():
    swarm = make("iwd")
    with pytest.raises(ValueError, match="rho_n must be at most 1"):
        swarm.check_params(swarm.default_params._replace(rho_n=np.float32(1.5)))
    with pytest.raises(ValueError, match="initial_velocity must be positive"):
        swarm.check_params(swarm.default_params._replace(initial_velocity=np.float32(0)))


def test_every_run_counts_its_fitness_calls():
    graph = grid_graph(np.zeros((4, 4), bool))
    for name in ("iwd", "aco_star"):
        swarm = make(name, num_agents=8)
        _, trace = run(swarm, jax.random.key(2), graph, make_task(graph, 0, 15),
                       swarm.default_params, iterations=5)
        used = int(trace.iterations)
        evaluations = np.asarray(trace.evaluations)
        # One call per agent that arrived: a complete path whose length was evaluated.
        np.testing.assert_array_equal(evaluations[:used],
                                      np.round(np.asarray(trace.arrived)[:used] * 8))
        assert evaluations[used:].sum() == 0 and evaluations.sum() > 0
