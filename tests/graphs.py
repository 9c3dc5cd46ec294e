"""Maps and swarm states shared by several test modules."""
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import sizes

from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.walking import walk
from jaxswarm.swarm.walking.moves import NARROWEST
from jaxswarm.world.graph import dense_graph, grid_graph


def geometric_graph(rng, n: int, *, radius: float, density: float, stretch: tuple[float, float]):
    """A directed graph of ``n`` random points in a 10 x 10 square: an edge between two points
    closer than ``radius`` with probability ``density``, its weight the distance times a factor
    drawn from ``stretch`` (at least 1, so the Euclidean heuristic is admissible)."""
    xy = rng.uniform(0, 10, (n, 2))
    span = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
    weights = np.where((span < radius) & (rng.random((n, n)) < density),
                       span * rng.uniform(*stretch, (n, n)), 0.0)
    return dense_graph(weights, xy=xy)


def wandering_walk():
    """``(graph, walk)``: 32 agents walking uniformly on an open 24 x 24 grid from (0, 0) to
    (3, 3), whose arrived agents' walks fit the narrowest width of the work after a walk
    (:data:`~jaxswarm.swarm.walking.moves.NARROWEST` moves) while some that did not arrive walk
    longer."""
    graph = grid_graph(np.zeros((24, 24), bool))
    task = make_task(graph, (0, 0), (3, 3))
    agents = walk(jax.random.key(0), graph, jnp.where(graph.nbr >= 0, 0.0, -jnp.inf), task.start,
                  task.goal, num_agents=32, max_steps=575)
    moves, arrived = np.asarray(agents.moves), np.asarray(agents.arrived)
    assert moves[arrived].max() <= NARROWEST < moves[~arrived].max()
    return graph, agents


class Solved(NamedTuple):
    """A paper map, its graph and task, a swarm, its default params and a state after a run."""

    chosen: object
    graph: object
    task: object
    swarm: object
    params: object
    state: object


def solved_paper_map(name: str, swarm_name: str, *, agents: int = sizes.AGENTS,
                     iterations: int = sizes.ITERATIONS, seed: int = 0) -> Solved:
    """``swarm_name`` with ``agents`` agents run for ``iterations`` on paper map ``name`` from
    ``jax.random.key(seed)`` (the tests' shared sizes by default: the program the conformance
    checks compile)."""
    chosen = paper_map(name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make(swarm_name, num_agents=agents)
    state, _ = run(swarm, jax.random.key(seed), graph, task, swarm.default_params,
                   iterations=iterations)
    return Solved(chosen, graph, task, swarm, swarm.default_params, state)
