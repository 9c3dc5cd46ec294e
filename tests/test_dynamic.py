"""Changes during a run: events as data, each family's memory rule, invalid best paths forgotten,
and runs that continue from a state."""
import dataclasses

import jax
import numpy as np
import pytest
import sizes
from graphs import solved_paper_map
from jitted import apply_event, change
from jaxswarm.dynamic import events as events_module
from jaxswarm.dynamic.events import check_events, first_iteration_at, make_event, replan
from jaxswarm.plot.graph import animate_field
from jaxswarm.plot.memory import memory_frames, memory_view
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.testing import Compilations
from jaxswarm.world.graph import grid_graph

H0 = 1e4


def open_3x3():
    """A free 3 x 3 grid (node y * 3 + x), 8-connected; start 0, goal 8."""
    graph = grid_graph(np.zeros((3, 3), bool))
    return graph, make_task(graph, 0, 8)


def test_event_moves_goal_blocks_and_opens_without_changing_shapes():
    graph, task = open_3x3()
    event = make_event(graph, goal=(2, 0), block=[(1, 1)], unblock=[], size=2)
    after, new_task = apply_event(event, graph, task)
    assert int(new_task.goal) == 2 and int(new_task.start) == 0
    free = np.asarray(after.free)
    assert not free[4] and free.sum() == 8
    def shapes(tree):
        return [(x.shape, x.dtype) for x in jax.tree_util.tree_leaves(tree)]
    assert shapes(after) == shapes(graph) and shapes(new_task) == shapes(task)
    reopened, _ = apply_event(make_event(after, unblock=[4], size=2), after, new_task)
    assert np.asarray(reopened.free)[4]


def test_paper_rule_old_goal_mean_new_goal_zero_opened_node_at_plateau():
    obstacles = np.zeros((3, 3), bool)
    obstacles[1, 0] = True  # node 3 blocked, to be opened
    graph = grid_graph(obstacles)
    task = make_task(graph, 0, 8)
    swarm = make("rfd_star", num_agents=4)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    altitude = np.arange(9, dtype=np.float32) * 10.0
    altitude[8] = 0.0
    state = dataclasses.replace(state, altitude=altitude, residual=np.full(9, 1e-7, np.float32))
    event = make_event(graph, goal=(0, 0), unblock=[(0, 1)], size=1)
    new_state, after, new_task = change(swarm, state, event, graph, task, params)
    got = np.asarray(new_state.altitude)
    # A set altitude has no residual (old goal 8, new goal 0, opened 3); the others keep theirs.
    kept = np.float32(1e-7)
    np.testing.assert_array_equal(np.asarray(new_state.residual),
                                  [0.0, kept, kept, 0.0, kept, kept, kept, kept, 0.0])
    # Node 8's neighbours on the new map: 5, 7 and 4 (no corner rule blocks them): mean 53.33.
    assert got[8] == pytest.approx((50 + 70 + 40) / 3)
    assert got[0] == 0.0  # the new goal
    assert got[3] == pytest.approx(float(params.initial_height))  # opened
    np.testing.assert_array_equal(got[[1, 2, 4, 5, 6, 7]], altitude[[1, 2, 4, 5, 6, 7]])


def test_pheromone_rule_new_edges_at_tau0_others_kept():
    obstacles = np.zeros((3, 3), bool)
    obstacles[1, 1] = True
    graph = grid_graph(obstacles)
    task = make_task(graph, 0, 8)
    swarm = make("aco_star", num_agents=4)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    state = dataclasses.replace(state, pheromone=np.full(graph.nbr.shape, 7.0, np.float32))
    new_state, after, _ = change(swarm, state, make_event(graph, unblock=[4], size=1), graph,
                                 task, params)
    new_edges = np.asarray(after.valid_edges()) & ~np.asarray(graph.valid_edges())
    # The 8 edges out of the opened centre, the 8 into it, and the 8 diagonals between edge
    # cells that squeezed past it (no corner cutting).
    assert new_edges[4].all() and new_edges.sum() == 24
    got = np.asarray(new_state.pheromone)
    np.testing.assert_allclose(got[new_edges], float(params.tau0))
    np.testing.assert_array_equal(got[~new_edges], 7.0)


def test_graded_rule_beds_remeasured_cut_beds_back_to_plateau():
    graph, task = open_3x3()
    swarm = make("rfd_graded", num_agents=4)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    # A bed 0 -> 1 -> 2 -> 5 -> 8 (carved as if walked, E = 1), a filled node 6, plateau else.
    altitude = np.full(9, H0, np.float32)
    altitude[[0, 1, 2, 5, 8]] = [4.0, 3.0, 2.0, 1.0, 0.0]
    altitude[6] = H0 + 3.0
    state = dataclasses.replace(state, altitude=altitude)
    # Block node 2: the bed above it is cut; the goal moves to node 1 (on the bed).
    new_state, _, _ = change(swarm, state, make_event(graph, goal=1, block=[2], size=1), graph,
                             task, params)
    got = np.asarray(new_state.altitude)
    assert got[1] == 0.0 and got[0] == pytest.approx(1.0)  # one step along the bed
    # 5 and 8 reach the new goal over carved ground only through 2 (blocked): plateau now.
    assert got[5] == H0 and got[8] == H0
    assert got[6] == H0 + 3.0 and got[3] == H0 and got[4] == H0  # filled and plateau kept


def test_invalid_best_path_is_forgotten_and_a_valid_one_kept():
    graph, task = open_3x3()
    swarm = make("aco_star", num_agents=4)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    path = np.full(state.best_path.shape, -1, np.int32)
    path[:3] = [0, 4, 8]
    state = dataclasses.replace(state, best_path=path, best_cost=np.float32(2 * np.sqrt(2)))
    kept, _, _ = change(swarm, state, make_event(graph, block=[2], size=1), graph, task, params)
    assert float(kept.best_cost) == pytest.approx(2 * np.sqrt(2))
    for event in (make_event(graph, block=[4], size=1), make_event(graph, goal=7, size=1),
                  make_event(graph, start=1, size=1)):
        dropped, _, _ = change(swarm, state, event, graph, task, params)
        assert np.isinf(float(dropped.best_cost)) and (np.asarray(dropped.best_path) == -1).all()


def test_vmap_over_events_equals_a_loop():
    _, graph, task, swarm, params, state = solved_paper_map("mosaic20", "rfd_graded", seed=1)
    free = np.nonzero(np.asarray(graph.free))[0]
    events = [make_event(graph, goal=int(free[i]), block=[int(free[i + 50])], size=1)
              for i in (40, 120, 200)]
    batch = jax.tree_util.tree_map(lambda *x: np.stack(x), *events)

    def changed_run(key, event, state, graph, task):
        return replan(swarm, key, state, event, graph, task, params,
                      iterations=sizes.ITERATIONS)[1].best_cost

    keys = jax.random.split(jax.random.key(2), len(events))
    together = np.asarray(jax.jit(jax.vmap(changed_run, in_axes=(0, 0, None, None, None)))(
        keys, batch, state, graph, task))
    # The loop replans outside jit: the change op by op, the continuation in run's program
    # (the one this file's other continuations use).
    for key, event, row in zip(keys, events, together):
        np.testing.assert_array_equal(row, changed_run(key, event, state, graph, task))


def test_continuing_uses_the_given_key_and_events_do_not_recompile():
    _, graph, task, swarm, params, state = solved_paper_map("maze20", "rfd_graded")
    other = dataclasses.replace(state, key=jax.random.key(99))  # the state's own key is ignored
    a, trace_a = run(swarm, jax.random.key(3), graph, task, params, iterations=sizes.ITERATIONS,
                     state=state)
    b, trace_b = run(swarm, jax.random.key(3), graph, task, params, iterations=sizes.ITERATIONS,
                     state=other)
    np.testing.assert_array_equal(a.altitude, b.altitude)
    last = int(trace_a.iterations) - 1  # the run may stop early: its trace is NaN after
    best = np.asarray(trace_a.best_cost)
    assert best[last] <= float(state.best_cost)  # memory kept: never worse
    free = np.nonzero(np.asarray(graph.free))[0]
    events = [make_event(graph, goal=int(free[goal]), block=[int(free[blocked])], size=1)
              for goal, blocked in ((-5, 40), (-30, 70))]
    for i, event in enumerate(events):  # the first change builds the change's own programs
        check_events(graph, task, event)
        with Compilations() as built:
            # Outside jit, with the operations replan applies outside jit (the jitted change
            # serves the memory rules on 3 x 3 maps).
            s, g, t = events_module.change(swarm, state, event, graph, task, params)
            run(swarm, jax.random.key(4), g, t, params, iterations=sizes.ITERATIONS, state=s)
        assert i == 0 or built.count == 0, f"a change of the map built {built.names}"


def test_bad_events_are_named_before_anything_is_applied():
    graph, task = open_3x3()
    with pytest.raises(ValueError, match="event: the start .* is blocked"):
        check_events(graph, task, make_event(graph, block=[0]))
    with pytest.raises(ValueError, match="event: the goal .* is blocked"):
        check_events(graph, task, make_event(graph, block=[8]))
    blocked = grid_graph(np.eye(3, dtype=bool)[::-1])  # node 2, 4, 6 blocked
    with pytest.raises(ValueError, match="goal .* moves onto an obstacle"):
        check_events(blocked, make_task(blocked, 0, 8), make_event(blocked, goal=4))
    with pytest.raises(ValueError, match="off the 3x3 map"):
        make_event(graph, goal=(5, 5))
    bigger = grid_graph(np.zeros((4, 4), bool))
    with pytest.raises(ValueError, match="made for a map of 16 nodes; this map has 9"):
        check_events(graph, task, make_event(bigger, goal=3))
    batch = jax.tree_util.tree_map(lambda *x: np.stack(x), make_event(graph, goal=5, size=1),
                                   make_event(graph, block=[8], size=1))
    with pytest.raises(ValueError, match="event 1: the goal"):
        check_events(graph, task, batch)


def test_memory_frames_and_their_gif(tmp_path):
    _, graph, task, swarm, params, state = solved_paper_map("maze20", "rfd_graded")
    after, frames = jax.jit(memory_frames, static_argnums=(0, 5))(swarm, state, graph, task,
                                                                   params, 4)
    frames = np.asarray(frames)
    assert frames.shape == (5, graph.num_nodes)
    np.testing.assert_array_equal(frames[0], memory_view(swarm).of(state))
    np.testing.assert_array_equal(frames[-1], memory_view(swarm).of(after))
    gif = tmp_path / "sub" / "altitude.gif"
    animate_field(graph, np.minimum(frames, 100.0), gif, title="{frame}")
    assert gif.read_bytes()[:6] == b"GIF89a" and list(gif.parent.iterdir()) == [gif]
    with pytest.raises(ValueError, match=r"frames must be \[T, 400\]"):
        animate_field(graph, np.zeros((3, 5)), tmp_path / "bad.gif")


def test_replan_is_change_then_run_and_first_iteration_at_reads_the_trace():
    _, graph, task, swarm, params, state = solved_paper_map("maze20", "rfd_graded")
    # Of the vmap test's events' size: the same operations when replan runs outside jit.
    event = make_event(graph, block=[int(np.nonzero(np.asarray(graph.free))[0][60])], size=1)
    key = jax.random.key(5)
    _, together = replan(swarm, key, state, event, graph, task, params,
                         iterations=sizes.ITERATIONS)
    changed, edited, new_task = events_module.change(swarm, state, event, graph, task, params)
    _, apart = run(swarm, key, edited, new_task, params, iterations=sizes.ITERATIONS,
                   state=changed)
    np.testing.assert_array_equal(together.best_cost, apart.best_cost)
    trace = dataclasses.replace(together, best_cost=np.float32([np.inf, 12.0, 10.0005, 10.0]),
                                iterations=np.int32(4))
    assert first_iteration_at(trace, 10.0, gap=1e-4) == 3  # 5e-5 relative: within the gap
    assert first_iteration_at(trace, 10.0, gap=1e-6) == 4
    assert first_iteration_at(trace, 9.0, gap=1e-4) is None
