"""Ant colonies: pheromone rules and quality on the paper maps."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest
import sizes
from graphs import wandering_walk

from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import aco, make, make_task, run
from jaxswarm.swarm.aco.ant_system import ant_system_update
from jaxswarm.world.graph import grid_graph
from jaxswarm.world.paths import is_valid_path, path_length, step_slots


def corridor():
    """A one-cell corridor (0,1)..(4,1): every ant walks the same path of length 4."""
    obstacles = np.ones((3, 5), bool)
    obstacles[1] = False
    graph = grid_graph(obstacles)
    return graph, make_task(graph, (0, 1), (4, 1))


def test_ant_system_deposits_q_over_length_on_both_directions():
    graph, task = corridor()
    swarm = make("ant_system", num_agents=8)
    params = swarm.default_params._replace(rho=jnp.float32(1.0), q=jnp.float32(2.0))
    state = swarm.init(jax.random.key(0), graph, task, params)
    state, info = swarm.step(state, graph, task, params)
    assert float(info.arrived) == 1.0
    tau = np.asarray(state.pheromone)
    east, west = 0, 2
    for x in range(4):  # every edge of the corridor: 8 ants x Q / 4
        assert tau[5 + x, east] == pytest.approx(8 * 2.0 / 4)
        assert tau[6 + x, west] == pytest.approx(8 * 2.0 / 4)
    # Nothing anywhere else: every other slot holds the floor (rho = 1), about 1.2e-38.
    assert tau.sum() == pytest.approx(2 * 4 * 8 * 2.0 / 4)


def test_ants_that_did_not_arrive_leave_the_deposit_unchanged_and_do_not_widen_it():
    # Some ants that did not arrive walk longer than the arrived ones' width.
    graph, ants = wandering_walk()
    pheromone = jax.random.uniform(jax.random.key(1), graph.nbr.shape, minval=0.5, maxval=2.0)
    params = aco.DEFAULT_ANT_SYSTEM
    got = ant_system_update(graph, pheromone, ants, None, None, None, params)
    # Every ant's whole row, as before the cut: the same bits.
    evaporated = jnp.maximum((1.0 - params.rho) * pheromone, aco.TAU_FLOOR)
    amount = jnp.where(ants.arrived, params.q / ants.length, 0.0)
    want = aco.deposit(graph, evaporated, ants.path[:, :-1], ants.slots, amount)
    np.testing.assert_array_equal(np.asarray(got), np.asarray(want))


def test_pheromone_is_symmetric_and_max_min_stays_in_its_bounds():
    chosen = paper_map("mosaic20")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    for name, options in (("ant_system", {}), ("max_min_aco", {}),
                          ("max_min_aco", dict(upper_bound=True))):
        swarm = make(name, **sizes.CONFIG, **options)
        params = swarm.default_params
        if name == "max_min_aco":  # a cap below tau0: only the upper_bound switch applies it
            params = params._replace(tau_max=np.float32(0.1))
        state, _ = run(swarm, jax.random.key(1), graph, task, params, iterations=sizes.ITERATIONS)
        tau, nbr, rev = map(np.asarray, (state.pheromone, graph.nbr, graph.rev))
        rows, slots = np.nonzero(nbr >= 0)
        np.testing.assert_allclose(tau[rows, slots], tau[nbr[rows, slots], rev[rows, slots]],
                                   rtol=1e-6)
        if name == "max_min_aco":
            assert tau.min() >= float(params.tau_min)
            assert (tau.max() <= 0.1) == options.get("upper_bound", False)


@pytest.mark.parametrize("name", ["ant_system", "aco_star"])
def test_pheromone_at_rho_09_never_becomes_impassable(name):
    """alley20, rho = 0.9, 48 iterations: 0.1 ** 48 = 1e-48 is far below the smallest
    normal float32 (1.18e-38), where float32 arithmetic would make tau 0 and its log -inf. Every
    valid edge keeps a finite log-weight: the edges left unwalked lie at the floor."""
    chosen = paper_map("alley20")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make(name, **sizes.CONFIG)
    params = swarm.default_params._replace(rho=np.float32(0.9))
    state, ran = None, 0
    for seed in range(6):
        state, trace = run(swarm, jax.random.key(seed), graph, task, params,
                           iterations=sizes.ITERATIONS, state=state)
        ran += int(trace.iterations)
    assert ran == 6 * sizes.ITERATIONS
    valid = np.asarray(graph.valid_edges())
    tau = np.asarray(state.pheromone)[valid]
    table = np.asarray(aco.transition_rule(graph, task, state.pheromone, params,
                                           goal_distance=name == "aco_star"))[valid]
    assert tau.min() == aco.TAU_FLOOR and (tau == aco.TAU_FLOOR).sum() > valid.sum() // 2
    assert np.isfinite(table).all()


def test_bad_params_are_named():
    graph, task = corridor()
    swarm = make("max_min_aco", num_agents=4, global_best=True)
    for field, value, message in (("rho", 1.5, "rho must be at most 1"),
                                  ("tau_min", 20.0, "tau_min .* exceeds tau_max"),
                                  ("q", 0.0, "q must be positive")):
        with pytest.raises(ValueError, match=message):
            run(swarm, jax.random.key(0), graph, task,
                swarm.default_params._replace(**{field: jnp.float32(value)}), iterations=2)
    with pytest.raises(ValueError, match="unknown first_ant 'bug'; choose one of weighted"):
        make("improved_max_min_aco", first_ant="bug")


@pytest.mark.parametrize("first_ant", ["weighted", "greedy"])
def test_improved_max_min_starts_from_its_first_ants_path_and_keeps_the_floor(first_ant):
    from jaxswarm.swarm.aco.bug2 import bug2_path

    chosen = paper_map("alley20")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make("improved_max_min_aco", first_ant=first_ant)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    first = np.asarray(state.best_path)
    nodes = first[first >= 0]
    assert bool(is_valid_path(graph, state.best_path, task.start, task.goal))
    assert len(set(nodes.tolist())) == len(nodes)  # its memory: no node twice
    assert float(state.best_cost) == pytest.approx(float(path_length(graph, state.best_path)))
    if first_ant == "greedy":  # a deterministic depth-first ant
        path, cost, _ = bug2_path(graph, task.start, task.goal)
        np.testing.assert_array_equal(nodes, np.asarray(path)[: len(nodes)])
    # Algorithm 1: nothing is deposited before the first population has walked.
    np.testing.assert_array_equal(np.asarray(state.pheromone), float(params.tau0))
    for _ in range(60):
        state, _ = swarm.step(state, graph, task, params)
    # The last update floored every edge and added delta on the best path's: each of its edges
    # holds at least tau_min + q. An edge off every best path decays by 0.9 ** 60 and rests on
    # the floor: most edges do.
    tau = np.asarray(state.pheromone)
    on_best = tau[np.asarray(state.best_path[:-1])[np.asarray(state.best_path[1:]) >= 0],
                  np.asarray(step_slots(graph, state.best_path))[np.asarray(
                      state.best_path[1:]) >= 0]]
    assert on_best.min() >= float(params.tau_min + params.q) * (1 - 1e-6)
    assert np.median(tau[np.asarray(graph.valid_edges())]) == pytest.approx(
        float(params.tau_min))
