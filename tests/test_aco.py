"""Ant colonies: pheromone rules and quality on the paper maps."""
import jax
import numpy as np
import pytest
import sizes
from graphs import wandering_walk
from jitted import ant_system_update, bug2_path, deposit, transition_rule

from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import aco, make, make_task, run
from jaxswarm.world.paths import is_valid_path, path_length



def corridor():
    """A one-cell corridor (0,1)..(16,1) in a map of the shared shape (:data:`sizes.MAP`'s):
    every ant walks the same path of length 16."""
    graph = sizes.cut_out([[False] * 17, [True] * 17])
    return graph, make_task(graph, (0, 1), (16, 1))


def test_ant_system_deposits_q_over_length_on_both_directions():
    graph, task = corridor()
    swarm = make("ant_system", **sizes.CONFIG)
    params = swarm.default_params._replace(rho=np.float32(1.0), q=np.float32(2.0))
    # One iteration (budget 1) of the run at the shared size.
    state, trace = run(swarm, jax.random.key(0), graph, task, params,
                       iterations=sizes.ITERATIONS, budget=1)
    assert int(trace.iterations) == 1 and np.asarray(trace.arrived)[0] == 1.0
    tau = np.asarray(state.pheromone)
    east, west, width = 0, 2, graph.shape[1]
    amount = sizes.AGENTS * 2.0 / 16  # every ant x Q / 16
    for x in range(16):  # every edge of the corridor, (x,1) - (x+1,1)
        assert tau[width + x, east] == pytest.approx(amount)
        assert tau[width + x + 1, west] == pytest.approx(amount)
    # Nothing anywhere else: every other slot holds the floor (rho = 1), about 1.2e-38.
    assert tau.sum() == pytest.approx(2 * 16 * amount)


def test_ants_that_did_not_arrive_leave_the_deposit_unchanged_and_do_not_widen_it():
    # Some ants that did not arrive walk longer than the arrived ones' width.
    graph, ants = wandering_walk()
    pheromone = jax.random.uniform(jax.random.key(1), graph.nbr.shape, minval=0.5, maxval=2.0)
    params = aco.DEFAULT_ANT_SYSTEM
    got = ant_system_update(graph, pheromone, ants, None, None, None, params)
    # Every ant's whole row, as before the cut: the same bits (eq. 9 and the amounts in NumPy's
    # float32, rounded as XLA rounds them).
    evaporated = np.maximum((1 - params.rho) * np.asarray(pheromone), aco.TAU_FLOOR)
    arrived, length = np.asarray(ants.arrived), np.asarray(ants.length)
    amount = np.where(arrived, params.q / length, np.float32(0))
    want = deposit(graph, evaporated, np.asarray(ants.path)[:, :-1], ants.slots, amount)
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
    """alley20, rho = 0.9, from tau0 = 1e-31 (what an edge holds after 31 evaporations from 1):
    after the run's 8 iterations an edge left unwalked would hold 1e-31 * 0.1 ** 8 = 1e-39, below
    the smallest normal float32 (1.18e-38), where float32 arithmetic would make tau 0 and its
    log -inf. Every valid edge keeps a finite log-weight: the edges left unwalked lie at the
    floor."""
    chosen = paper_map("alley20")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make(name, **sizes.CONFIG)
    params = swarm.default_params._replace(rho=np.float32(0.9), tau0=np.float32(1e-31))
    state, trace = run(swarm, jax.random.key(0), graph, task, params,
                       iterations=sizes.ITERATIONS)
    assert int(trace.iterations) == sizes.ITERATIONS
    valid = np.asarray(graph.valid_edges())
    tau = np.asarray(state.pheromone)[valid]
    table = np.asarray(transition_rule(graph, task, state.pheromone, params,
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
                swarm.default_params._replace(**{field: np.float32(value)}), iterations=2)
    with pytest.raises(ValueError, match="unknown first_ant 'bug'; choose one of weighted"):
        make("improved_max_min_aco", first_ant="bug")


@pytest.mark.parametrize("first_ant", ["weighted", "greedy"])
def test_improved_max_min_starts_from_its_first_ants_path_and_keeps_the_floor(first_ant):
    chosen = paper_map("alley20")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make("improved_max_min_aco", first_ant=first_ant, **sizes.CONFIG)
    # rho = 0.5: within the run's 8 iterations an edge off every best path decays below tau_min.
    params = swarm.default_params._replace(rho=np.float32(0.5))
    key = jax.random.key(0)
    # No iteration (budget 0): the state swarm.init makes, from the program of the run below.
    state, _ = run(swarm, key, graph, task, params, iterations=sizes.ITERATIONS, budget=0)
    first = np.asarray(state.best_path)
    nodes = first[first >= 0]
    assert bool(is_valid_path(graph, state.best_path, task.start, task.goal))
    assert len(set(nodes.tolist())) == len(nodes)  # its memory: no node twice
    assert float(state.best_cost) == pytest.approx(float(path_length(graph, state.best_path)))
    if first_ant == "greedy":  # a deterministic depth-first ant
        # Node numbers as ints, as test_bug2.py passes them: the program of its 20 x 20 maps.
        path, cost, _ = bug2_path(graph, int(task.start), int(task.goal))
        np.testing.assert_array_equal(nodes, np.asarray(path)[: len(nodes)])
    # Algorithm 1: nothing is deposited before the first population has walked.
    np.testing.assert_array_equal(np.asarray(state.pheromone), float(params.tau0))
    state, _ = run(swarm, key, graph, task, params, iterations=sizes.ITERATIONS)
    # The last update floored every edge and added delta on the best path's: each of its edges
    # holds at least tau_min + q. An edge off every best path decays by 0.5 ** 8 and rests on
    # the floor: most edges do.
    tau, nbr, best = map(np.asarray, (state.pheromone, graph.nbr, state.best_path))
    here, there = best[:-1][best[1:] >= 0], best[1:][best[1:] >= 0]
    on_best = tau[here, np.argmax(nbr[here] == there[:, None], axis=1)]  # each step's slot
    assert on_best.min() >= float(params.tau_min + params.q) * (1 - 1e-6)
    assert np.median(tau[np.asarray(graph.valid_edges())]) == pytest.approx(
        float(params.tau_min))
