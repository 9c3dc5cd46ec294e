"""rfd_graded (ours) against the Dijkstra optimum on the paper maps (fixed seeds: deterministic).

Only our own algorithm has a quality bar; the papers' are reported by the sweeps, not tuned."""
import jax
import numpy as np
import pytest

from jaxswarm.exact import dijkstra
from jaxswarm.maps.paper import PAPER_MAPS, paper_map
from jaxswarm.swarm import make, make_task, run

SEEDS = 20
NEEDED = 19  # the bar: the optimum (gap < 1e-4) in at least 19 of 20 seeds


def successes(name: str) -> int:
    chosen = paper_map(name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    optimum = dijkstra(graph, chosen.start, chosen.goal).cost
    swarm = make("rfd_graded")
    keys = jax.random.split(jax.random.key(0), SEEDS)
    states, _ = jax.jit(jax.vmap(lambda k: run(swarm, k, graph, task, swarm.default_params,
                                               iterations=100)))(keys)
    gaps = (np.asarray(states.best_cost) - optimum) / optimum
    assert (gaps > -1e-6).all()  # never better than the optimum
    return int((gaps < 1e-4).sum())


@pytest.mark.parametrize("name", [n for n in PAPER_MAPS if n.endswith("20")])
def test_rfd_graded_reaches_the_optimum_on_20x20_maps(name):
    assert successes(name) >= NEEDED


@pytest.mark.slow
@pytest.mark.parametrize("name", [n for n in PAPER_MAPS if not n.endswith("20")])
def test_rfd_graded_reaches_the_optimum_on_larger_maps(name):
    assert successes(name) >= NEEDED
