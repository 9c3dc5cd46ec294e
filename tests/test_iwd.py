"""Intelligent Water Drops: each equation against a hand computation, the soil updates of drops
that share an edge in one step applied in agent order, bit-identically, and the walker hook."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxswarm.graph import grid_graph
from jaxswarm.paths import step_slots
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.iwd import DEFAULT_IWD, global_update, soil_taken, velocity_after
from jaxswarm.swarm.iwd.soil import SOIL, choice_log_weights, goal_log_desirability
from jaxswarm.swarm.walking import FORCED, edge_table, walk
from jaxswarm.swarm.walking.hooks import Move, edge_groups

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


def test_drops_on_one_edge_in_one_step_update_it_in_agent_order():
    graph = grid_graph(np.zeros((1, 3), bool))
    soil = jnp.full((1,) + graph.nbr.shape, 50.0)
    velocities = jnp.array([300.0, 100.0, 200.0])
    agents = jnp.array([2, 0, 1])  # lane 0 holds agent 2, lane 1 agent 0, lane 2 agent 1
    move = Move(run=jnp.zeros(3, jnp.int32), agent=agents, here=jnp.zeros(3, jnp.int32),
                slot=jnp.full((3,), EAST, jnp.int32), moving=jnp.ones(3, bool),
                state=jnp.stack([velocities, jnp.zeros(3)], axis=-1))
    groups = edge_groups(move, graph.num_nodes, graph.max_degree)
    assert groups.rank.tolist() == [2, 0, 1] and groups.count.tolist() == [3, 3, 3]
    assert groups.last.tolist() == [True, False, False]
    np.testing.assert_allclose(groups.group_sum(jnp.array([1.0, 2.0, 4.0])), [7.0] * 3)
    after, state = SOIL.update(per_lane(P, 3), soil, move, graph)
    # By hand, in agent order (lanes 1, 2, 0), each drop's taken soil from the step's soil 50.
    s = 50.0
    taken = {}
    for lane in (1, 2, 0):
        v = float(velocities[lane]) + 1 / (0.01 + 50.0 ** 2)
        taken[lane] = 1 / (0.01 + (1 / v) ** 2)
        s = 0.1 * s - 0.9 * taken[lane]
    assert float(after[0, 0, EAST]) == pytest.approx(s, rel=1e-5)
    np.testing.assert_allclose(np.asarray(state[:, 1]), [taken[0], taken[1], taken[2]],
                               rtol=1e-6)
    untouched = np.ones(graph.nbr.shape, bool)
    untouched[0, EAST] = False
    assert np.all(np.asarray(after[0])[untouched] == 50.0)
    still = move._replace(moving=jnp.array([False, False, False]), slot=jnp.full((3,), -1))
    same, kept = SOIL.update(per_lane(P, 3), soil, still, graph)
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
