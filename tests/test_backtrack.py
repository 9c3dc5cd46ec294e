"""The walker's depth-first walk: agents that back out of dead ends, their paths without the dead
ends, the longest path they may hold, and the Walk a population of them makes."""
import functools

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.walking import visited_nodes
from jaxswarm.swarm.walking.backtrack import backtracking_walk, depth_first_walk
from jaxswarm.world.graph import grid_graph
from jaxswarm.world.paths import path_length


def comb():
    """A 2 x 5 grid whose lower row is a comb of three dead-end cells (x = 0, 2, 4)."""
    free = np.zeros((2, 5), bool)
    free[1, [1, 3]] = True  # blocked
    return grid_graph(free)


def toward_the_dead_ends(graph):
    """A rule that prefers every move into the lower row: a walker following it backs out."""
    below = graph.xy[:, 1] > 0
    valid = graph.valid_edges()

    def choice(here, unvisited):
        heads = jnp.maximum(graph.nbr[here], 0)
        return jnp.where(valid[here], jnp.where(below[heads], 5.0, 0.0), -jnp.inf)

    return choice


def any_valid_move(graph):
    """A rule that weighs every valid move the same."""
    valid = graph.valid_edges()
    return lambda here, unvisited: jnp.where(valid[here], 0.0, -jnp.inf)


@functools.partial(jax.jit, static_argnames=("rule", "max_nodes", "greedy"))
def depth_first(key, graph, rule, start, goal, *, max_nodes, greedy=False):
    """:func:`depth_first_walk` following ``rule(graph)``, jitted: one program, not its loop and
    each operation around it, with the graph an argument (the rule is made inside)."""
    return depth_first_walk(key, graph, rule(graph), start, goal, max_nodes=max_nodes,
                            greedy=greedy)


@functools.partial(jax.jit, static_argnames=("rule", "num_agents", "max_steps"))
def backtracking(key, graph, rule, start, goal, *, num_agents, max_steps):
    """:func:`backtracking_walk` following ``rule(graph)``, jitted as :func:`depth_first`."""
    return backtracking_walk(key, graph, rule(graph), start, goal, num_agents=num_agents,
                             max_steps=max_steps)


visited = jax.jit(visited_nodes, static_argnames="num_nodes")
""":func:`visited_nodes` under test, one program for every agent's selection."""


def test_a_greedy_walker_backs_out_of_each_dead_end_and_keeps_the_way():
    graph = comb()
    walked = jax.device_get(depth_first(jax.random.key(0), graph, toward_the_dead_ends, 0, 4,
                                        max_nodes=graph.num_nodes, greedy=True))
    path = walked.path
    nodes = path[path >= 0]
    assert walked.found and nodes[0] == 0 and nodes[-1] == 4
    assert len(set(nodes.tolist())) == len(nodes)
    assert not set(nodes.tolist()) & {5, 7, 9}  # the dead ends are not on the path
    assert walked.moves > len(nodes) - 1  # it went into them and came back


def test_a_way_longer_than_max_nodes_is_a_dead_end():
    graph = grid_graph(np.zeros((1, 6), bool))  # a corridor: the only way has 6 nodes
    short = jax.device_get(depth_first(jax.random.key(0), graph, any_valid_move, 0, 5,
                                       max_nodes=5))
    assert not short.found and np.all(short.path == -1)
    enough = jax.device_get(depth_first(jax.random.key(0), graph, any_valid_move, 0, 5,
                                        max_nodes=6))
    assert enough.found and enough.path.tolist() == [0, 1, 2, 3, 4, 5]


def test_a_population_of_backtracking_walkers_is_a_consistent_walk():
    graph = comb()
    drops = jax.device_get(backtracking(jax.random.key(3), graph, toward_the_dead_ends, 0, 4,
                                        num_agents=6, max_steps=9))
    paths = np.asarray(drops.path)
    assert paths.shape == (6, 10) and drops.slots.shape == (6, 9)
    assert drops.arrived.all() and not drops.stuck.any()
    for agent in range(6):
        path = paths[agent]
        assert float(drops.length[agent]) == float(path_length(graph, path))
        on_path = np.zeros(graph.num_nodes, bool)
        on_path[path[path >= 0]] = True
        seen = visited(drops, graph.num_nodes, np.arange(6) == agent)
        assert np.array_equal(np.asarray(seen), on_path)
        assert int(drops.position[agent]) == 4
    again = backtracking(jax.random.key(3), graph, toward_the_dead_ends, 0, 4, num_agents=6,
                         max_steps=9)
    assert np.array_equal(np.asarray(again.path), paths)
    assert int(drops.lane_steps) == 6 * int(drops.moves.max())
