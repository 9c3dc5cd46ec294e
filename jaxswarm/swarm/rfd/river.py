"""What every river formation variant shares: the altitude memory and one iteration's shape.

Every node has an altitude; the goal is the sea, fixed at 0, every other node starts at
``initial_height``. Each iteration all drops walk from the start over one table of transition
log-weights (:mod:`jaxswarm.swarm.walking`: no drop visits a node twice, the RFD paper's per-drop
neighbour sets), then the variant reshapes the altitudes from what the drops did, and the best
arrived path is kept.
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import jax
import jax.numpy as jnp

from jaxswarm.swarm.core import Swarm, Task, best_solution, keep_best
from jaxswarm.swarm.walking import Walk, heads, neighbour_slots, step_budget, walk
from jaxswarm.world.graph import Graph


@dataclasses.dataclass(frozen=True)
class RFDState:
    """Memory of a river formation run (a pytree).

    Attributes:
      key: PRNG key for the next iteration.
      altitude: f32[N] node altitudes (the goal's is 0).
      best_path: i32[L] best path found so far, -1 padded (all -1 before any drop arrived).
      best_cost: f32[] its length (inf before any drop arrived).
    """

    key: jax.Array
    altitude: jax.Array
    best_path: jax.Array
    best_cost: jax.Array


jax.tree_util.register_dataclass(
    RFDState, data_fields=["key", "altitude", "best_path", "best_cost"], meta_fields=[])


Transition = Callable[[Graph, Task, jax.Array, object], jax.Array]
"""``(graph, task, altitude f32[N], params) -> f32[N, K]`` the walker's log-weight table."""
Reshape = Callable[[Graph, Task, jax.Array, jax.Array, Walk, object], jax.Array]
"""``(graph, task, altitude f32[N], table f32[N, K], drops, params) -> f32[N]`` the altitudes
after one iteration's erosion and sediment."""


def river_swarm(name: str, config, *, transition: Transition, reshape: Reshape,
                greedy_drops: int, default_params, check_params, adapt=None) -> Swarm:
    """A river formation Swarm from its transition rule and its altitude update.

    Args:
      name: registry name.
      config: the variant's static config (``num_agents`` and ``max_steps`` are read).
      transition: the log-weight table of the current altitudes.
      reshape: erosion and sediment after a walk.
      greedy_drops: how many drops (the first ones) take their most likely move.
      default_params: the variant's default Params.
      check_params: host-side Params check.
      adapt: the memory rule of a change (``Swarm.adapt``); default
        :func:`paper_altitude_rule`.
    """
    def init(key, graph: Graph, task: Task, params) -> RFDState:
        altitude = jnp.full((graph.num_nodes,), params.initial_height,
                            jnp.float32).at[task.goal].set(0.0)
        return RFDState(key=key, altitude=altitude,
                        best_path=jnp.full((step_budget(graph, config.max_steps) + 1,), -1,
                                           jnp.int32),
                        best_cost=jnp.float32(jnp.inf))

    def step(state: RFDState, graph: Graph, task: Task, params):
        key, walk_key = jax.random.split(state.key)
        table = transition(graph, task, state.altitude, params)
        drops = walk(walk_key, graph, table, task.start, task.goal,
                     num_agents=config.num_agents,
                     max_steps=step_budget(graph, config.max_steps),
                     greedy_agents=greedy_drops)
        altitude = reshape(graph, task, state.altitude, table, drops, params)
        altitude = jnp.maximum(altitude, 0.0).at[task.goal].set(0.0)
        best_path, best_cost, info = keep_best(drops, state.best_path, state.best_cost)
        return RFDState(key=key, altitude=altitude, best_path=best_path,
                        best_cost=best_cost), info

    return Swarm(name=name, config=config, init=jax.jit(init), step=jax.jit(step),
                 best=best_solution, default_params=default_params, check_params=check_params,
                 memory=lambda state: state.altitude, memory_label="altitude",
                 adapt=paper_altitude_rule if adapt is None else adapt)


def paper_altitude_rule(state: RFDState, before: Graph, after: Graph, old: Task, new: Task,
                        params) -> RFDState:
    """The RFD paper's memory rule for a change of the map or the goal (RFD and RFD*): the old
    goal takes the mean altitude of its neighbours (those it has a valid edge to on the new map),
    the new goal 0, a newly opened node ``initial_height``; every other altitude is kept."""
    altitude = state.altitude
    valid = after.valid_edges()[old.goal]
    around = jnp.where(valid, altitude[jnp.maximum(after.nbr[old.goal], 0)], 0.0)
    mean = jnp.sum(around) / jnp.maximum(jnp.sum(valid), 1)
    altitude = altitude.at[old.goal].set(jnp.where(new.goal != old.goal, mean,
                                                   altitude[old.goal]))
    altitude = jnp.where(after.free & ~before.free, params.initial_height, altitude)
    return dataclasses.replace(state, altitude=altitude.at[new.goal].set(0.0))


def check_greedy_drops(greedy_drops: int, num_agents: int) -> None:
    """Static config check: between 0 and all of the drops are greedy."""
    if not 0 <= greedy_drops <= num_agents:
        raise ValueError(f"greedy_drops must be between 0 and num_agents ({num_agents}), "
                         f"got {greedy_drops}")


def gradients(graph: Graph, altitude: jax.Array) -> tuple[jax.Array, jax.Array]:
    """``(heads i32[K, N], gradient f32[K, N])``, slot-major (see
    :func:`~jaxswarm.swarm.walking.tables.neighbour_slots`; transpose the finished table once):
    each slot's neighbour (0 where there is none) and the RFD paper's eq. 2,
    ``(altitude(i) - altitude(j)) / distance(i, j)``."""
    drop = altitude - neighbour_slots(graph, altitude)
    return heads(graph).T, drop / jnp.where(graph.nbr >= 0, graph.cost, 1.0).T


def deposit_where_stuck(altitude: jax.Array, drops: Walk, sediment) -> jax.Array:
    """f32[N]: ``altitude`` after every drop that could not move deposited ``sediment`` on the
    node where it stopped (the RFD paper's "deposits a fraction of carried sediment")."""
    stuck_at = jnp.where(drops.stuck, drops.position, altitude.shape[0])  # out of bounds: dropped
    return altitude.at[stuck_at].add(sediment, mode="drop")
