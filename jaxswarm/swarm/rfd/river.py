"""What every river formation variant shares: the altitude memory and one iteration's shape.

Every node has an altitude; the goal is the sea, fixed at 0, every other node starts at
``initial_height``. Each iteration all drops walk from the start over one table of transition
log-weights (:mod:`jaxswarm.swarm.walking`: no drop visits a node twice, the RFD paper's per-drop
neighbour sets), then the variant reshapes the altitudes from what the drops did, and the best
arrived path is kept.

Arithmetic, not algorithm: the paper's laws add small amounts to the altitudes (eq. 4's erosion
of one move is ``E / ((N - 1) D)`` times a gradient, eq. 5's sediment the eroded total over ``N -
1``), and in float32 an addition below half the spacing at the altitude (about 3e-8 at altitude
1) is lost whole. The state keeps ``residual``, f32[N], what the float32 additions to each
altitude lost, and :func:`add_compensated` adds it back with the next change (compensated
summation: Kahan's, with Neumaier's test of which addend is larger), so that many small steps
move an altitude as their sum does. A law that sets altitudes rather than adding to them
(``rfd_graded``) leaves ``residual`` at zero. Where an altitude is clamped at 0 or set by a rule
(the goal, a change of the map), its residual is dropped.
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import jax
import jax.numpy as jnp

from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.swarm.core import Swarm, Task, best_solution, keep_best
from jaxswarm.swarm.walking import Walk, heads, neighbour_slots, step_budget, walk
from jaxswarm.world.graph import Graph


@dataclasses.dataclass(frozen=True)
class RFDState:
    """Memory of a river formation run (a pytree).

    Attributes:
      key: PRNG key for the next iteration.
      altitude: f32[N] node altitudes (the goal's is 0).
      residual: f32[N] what float32 rounding lost of the additions to each altitude, added back
        with the next one (:func:`add_compensated`; zeros for a law that sets altitudes).
      best_path: i32[L] best path found so far, -1 padded (all -1 before any drop arrived).
      best_cost: f32[] its length (inf before any drop arrived).
    """

    key: jax.Array
    altitude: jax.Array
    residual: jax.Array
    best_path: jax.Array
    best_cost: jax.Array


jax.tree_util.register_dataclass(
    RFDState, data_fields=["key", "altitude", "residual", "best_path", "best_cost"], meta_fields=[])


Transition = Callable[[Graph, Task, jax.Array, object], jax.Array]
"""``(graph, task, altitude f32[N], params) -> f32[N, K]`` the walker's log-weight table."""
Reshape = Callable[[Graph, Task, jax.Array, jax.Array, jax.Array, Walk, object],
                   tuple[jax.Array, jax.Array]]
"""``(graph, task, altitude f32[N], residual f32[N], table f32[N, K], drops, params) ->
(altitude f32[N], residual f32[N])``: the altitudes after one iteration's erosion and sediment,
and what float32 rounding lost of them (see :func:`add_compensated`)."""


def river_swarm(name: str, config, *, transition: Transition, reshape: Reshape,
                greedy_drops: int, default_params, check_params) -> Swarm:
    """A river formation Swarm from its transition rule and its altitude update.

    Args:
      name: registry name.
      config: the variant's static config (``num_agents`` and ``max_steps`` are read).
      transition: the log-weight table of the current altitudes.
      reshape: erosion and sediment after a walk (see :data:`Reshape`).
      greedy_drops: how many drops (the first ones) take their most likely move.
      default_params: the variant's default Params.
      check_params: host-side Params check.
    """
    def init(key, graph: Graph, task: Task, params) -> RFDState:
        altitude = jnp.full((graph.num_nodes,), params.initial_height,
                            jnp.float32).at[task.goal].set(0.0)
        return RFDState(key=key, altitude=altitude, residual=jnp.zeros_like(altitude),
                        best_path=jnp.full((step_budget(graph, config.max_steps) + 1,), -1,
                                           jnp.int32),
                        best_cost=jnp.float32(jnp.inf))

    def step(state: RFDState, graph: Graph, task: Task, params):
        key, walk_key = jax.random.split(state.key)
        table = transition(graph, task, state.altitude, params)
        drops = walk(walk_key, graph, table, task.start, task.goal,
                     num_agents=config.num_agents,
                     max_steps=step_budget(graph, config.max_steps),
                     greedy_agents=greedy_drops, walker=config.walker)
        altitude, residual = reshape(graph, task, state.altitude, state.residual, table, drops,
                                     params)
        altitude = jnp.maximum(altitude, 0.0).at[task.goal].set(0.0)
        best_path, best_cost, info = keep_best(drops, state.best_path, state.best_cost)
        return RFDState(key=key, altitude=altitude,
                        residual=jnp.where(altitude > 0.0, residual, 0.0), best_path=best_path,
                        best_cost=best_cost), info

    return Swarm(name=name, config=config, init=jax.jit(init), step=jax.jit(step),
                 best=best_solution, default_params=default_params, check_params=check_params)


def paper_altitude_rule(state: RFDState, before: Graph, after: Graph, old: Task, new: Task,
                        params) -> RFDState:
    """The RFD paper's memory rule for a change of the map or the goal (RFD and RFD*): the old
    goal takes the mean altitude of its neighbours (those it has a valid edge to on the new map),
    the new goal 0, a newly opened node ``initial_height``; every other altitude is kept, with its
    residual (a set altitude has none)."""
    altitude = state.altitude
    valid = after.valid_edges()[old.goal]
    around = jnp.where(valid, altitude[jnp.maximum(after.nbr[old.goal], 0)], 0.0)
    # Times the reciprocal: the count comes from the map, which a batch of runs may share.
    mean = ordered_sum(around) * (1.0 / jnp.maximum(jnp.sum(valid), 1))
    nodes = jnp.arange(altitude.shape[0])
    moved = (nodes == old.goal) & (new.goal != old.goal)
    opened = after.free & ~before.free
    altitude = jnp.where(moved, mean, altitude)
    altitude = jnp.where(opened, params.initial_height, altitude).at[new.goal].set(0.0)
    residual = jnp.where(moved | opened | (nodes == new.goal), 0.0, state.residual)
    return dataclasses.replace(state, altitude=altitude, residual=residual)


def check_greedy_drops(greedy_drops: int, num_agents: int) -> None:
    """Static config check: between 0 and all of the drops are greedy."""
    if not 0 <= greedy_drops <= num_agents:
        raise ValueError(f"greedy_drops must be between 0 and num_agents ({num_agents}), "
                         f"got {greedy_drops}")


def gradients(graph: Graph, altitude: jax.Array) -> tuple[jax.Array, jax.Array]:
    """``(heads i32[K, N], gradient f32[K, N])``, slot-major (see
    :func:`~jaxswarm.swarm.walking.tables.neighbour_slots`; transpose the finished table once):
    each slot's neighbour (0 where there is none) and the RFD paper's eq. 2,
    ``(altitude(i) - altitude(j)) / distance(i, j)``, computed as the drop times the reciprocal
    of the distance."""
    drop = altitude - neighbour_slots(graph, altitude)
    # Not a division: under vmap the map's distances are one operand shared by the batch, and
    # XLA rewrites a division by a broadcast operand as a multiplication by its reciprocal
    # (up to 1.5 ulp away from the quotient), so a run alone and the same run in a sweep drew
    # from different tables. Multiplying by the reciprocal is what every program computes.
    return heads(graph).T, drop * (1.0 / jnp.where(graph.nbr >= 0, graph.cost, 1.0).T)


def sediment_where_stuck(num_nodes: int, drops: Walk, sediment) -> jax.Array:
    """f32[N]: what every drop that could not move deposits, ``sediment`` on the node where it
    stopped (the RFD paper's "deposits a fraction of carried sediment"), summed per node."""
    stuck_at = jnp.where(drops.stuck, drops.position, num_nodes)  # out of bounds: dropped
    return jnp.zeros((num_nodes,), jnp.float32).at[stuck_at].add(sediment, mode="drop")


def add_compensated(altitude: jax.Array, residual: jax.Array,
                    change: jax.Array) -> tuple[jax.Array, jax.Array]:
    """``(altitude f32[N], residual f32[N])`` after adding ``change`` f32[N] to ``altitude``
    f32[N] by compensated summation: ``residual`` f32[N] (what earlier additions lost to float32
    rounding) is added with the change, and what this addition loses takes its place.

    The lost part is exact (Neumaier's test: the error of ``a + b`` is recovered from the larger
    addend), so a step of 1e-9 added to altitude 1 a thousand times moves it by 1e-6 (without
    the residual it would not move). XLA does not reassociate float arithmetic on CPU (its
    fast-math is off), so fusion keeps the recovered error exact.
    """
    step = change + residual
    total = altitude + step
    lost = jnp.where(jnp.abs(altitude) >= jnp.abs(step), (altitude - total) + step,
                     (step - total) + altitude)
    return total, lost
