"""The registry: the papers' names and ours, one Swarm per Config, and rfd_graded replaying its
recorded runs bit for bit."""
import json
from pathlib import Path

import jax
import numpy as np
import pytest

from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import config_options, definition, make, make_task, registered, run
from jaxswarm.swarm.registry import REGISTRY
from jaxswarm.world.graph import Graph
from jaxswarm.world.plane import Plane

GOLDEN = Path(__file__).parent / "golden" / "rfd_graded_0.3.0.json"
"""Runs of ``make("rfd_graded", num_agents=...)`` with its defaults, written by
``tests/golden/record.py``: map, agents, iterations, patience, seed and what came out (best path
and cost, iterations run, the best cost after each, final altitudes). jaxswarm 0.1.0's
``rfd_star`` was this law; 0.3.0's walker draws other random numbers, so the record was made
again then, and 0.7.0's arithmetic (:mod:`jaxswarm.runtime.arithmetic`) moved its last bits, so
again then."""


def test_the_registry_holds_the_papers_algorithms_and_ours():
    assert set(registered()) == {"rfd", "rfd_star", "rfd_graded", "ant_system", "aco_star",
                                 "max_min_aco", "improved_max_min_aco", "iwd", "iwd_pg", "cabc"}
    assert registered(Plane) == ("cabc",)
    assert set(registered(Graph)) == set(registered()) - {"cabc"}
    ours = {name for name, entry in REGISTRY.items() if not entry.faithful}
    assert ours == {"rfd_graded"}
    with pytest.raises(ValueError, match="unknown swarm 'bees'; registered: .*rfd_star"):
        make("bees")


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_equal_configs_give_one_swarm(name):
    explicit = {option: getattr(REGISTRY[name].config(), option)
                for option in config_options(name)}
    assert make(name) is make(name, **explicit)
    default_steps = REGISTRY[name].config().max_steps
    assert make(name, num_agents=32) is make(name, num_agents=32, max_steps=default_steps)
    assert make(name, num_agents=32) is not make(name, num_agents=16)
    assert definition(make(name, num_agents=32))["config"]["num_agents"] == 32


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_params_with_sets_the_named_params_as_float32_and_keeps_the_rest(name):
    swarm = make(name)
    first = swarm.default_params._fields[0]
    params = swarm.params_with(**{first: 0.375})
    assert params[0] == np.float32(0.375) and params[0].dtype == np.float32
    assert params[1:] == swarm.default_params[1:]
    with pytest.raises(ValueError, match="no_such_param"):
        swarm.params_with(no_such_param=1.0)


def test_the_papers_variants_are_the_defaults():
    star = make("rfd_star").config
    assert (star.erosion_law, star.erode, star.greedy_drops, star.fill_blind_alleys,
            star.max_climb) == ("linear", "arrived", 0, False, None)
    assert set(make("rfd_star").default_params._fields) == {
        "p_base", "alpha", "initial_height", "erosion", "sediment"}
    assert float(make("ant_system").default_params.beta) == 0.0  # eq. 7: pheromone only
    assert float(make("aco_star").default_params.beta) == 0.0
    max_min = make("max_min_aco").config
    assert not max_min.upper_bound and not max_min.global_best
    improved = make("improved_max_min_aco")
    assert improved.config.first_ant == "weighted" and improved.config.num_agents == 50
    assert float(improved.default_params.beta_first) == 5.0  # Algorithm 1's hweight
    assert (float(improved.default_params.alpha), float(improved.default_params.beta)) == (1, 1)
    standard = dict(alpha=1, beta=1, eps_s=0.01, a_v=1, b_v=0.01, c_v=1, initial_velocity=200,
                    a_s=1, b_s=0.01, c_s=1, rho_n=0.9, rho_iwd=0.9, initial_soil=10_000)
    fixed_by_paper = ("eps_s", "a_v", "b_v", "c_v", "initial_velocity", "a_s", "b_s", "c_s")
    drops = make("iwd").default_params  # the standard values the paper fixes, calibrated others
    assert {name: float(getattr(drops, name)) for name in fixed_by_paper} == pytest.approx(
        {name: standard[name] for name in fixed_by_paper})
    assert drops.alpha == drops.beta  # "equal", as the paper says
    pg = make("iwd_pg").default_params  # Shah-Hosseini's standard values throughout
    assert {name: float(getattr(pg, name)) for name in standard} == pytest.approx(standard)


@pytest.mark.slow  # runs at the sizes of its records, about 60 s cold
@pytest.mark.parametrize("record", json.loads(GOLDEN.read_text()),
                         ids=lambda r: f"{r['map']}-seed{r['seed']}")
def test_rfd_graded_replays_its_recorded_runs(record):
    """Twin in the default tier: rfd_graded's golden records at the shared size
    (test_conformance.py)."""
    chosen = paper_map(record["map"])
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make("rfd_graded", num_agents=record["num_agents"])
    state, trace = run(swarm, jax.random.key(record["seed"]), graph, task, swarm.default_params,
                       iterations=record["iterations"], patience=record["patience"])
    assert int(trace.iterations) == record["ran"]
    assert float(state.best_cost) == record["best_cost"]
    np.testing.assert_array_equal(np.asarray(state.best_path), record["best_path"])
    np.testing.assert_array_equal(np.asarray(trace.best_cost)[:record["ran"]],
                                  np.float32(record["trace_best"]))
    np.testing.assert_array_equal(np.asarray(state.altitude), np.float32(record["altitude"]))
