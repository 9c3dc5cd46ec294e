"""River Formation Dynamics: the original RFD and the modified RFD* of the RFD paper.

Every node has an altitude; the goal is the sea, fixed at 0, every other node starts at
``initial_height``. Each iteration all drops walk from the start (:mod:`jaxswarm.swarm.walk`),
choosing among admissible neighbours ``j`` of their node ``i`` by the gradient

    gradient(i, j) = (altitude(i) - altitude(j)) / distance(i, j)                     (eq. 2)

* RFD (eqs. 1, 3): weight ``gradient`` downhill, ``omega / |gradient|`` uphill, ``delta`` flat.
* RFD* (eq. 6): weight ``p_base ** gradient / d_j ** alpha`` for every admissible neighbour, with
  ``d_j`` the straight-line distance from ``j`` to the goal; the goal is taken whenever adjacent.

After the walk, each edge ``i -> j`` of every path that reached the goal erodes node ``i`` by

    erosion(i, j) = E / ((N - 1) * D) * gradient(i, j)                               (eq. 4)

(negative gradients erode nothing) or, as an RFD* option, by ``E / ((N - 1) * D) *
p_base ** gradient`` (the exponential form the paper suggests, which also erodes flat ground). A
drop that got stuck deposits ``sediment`` where it stands. RFD* drops do not climb slopes steeper
than ``climb``: a drop whose only moves are steeper is stuck too, so deposits fill a blind alley
from its end back to its entrance and later drops avoid it (the paper's "reduces the likelihood
of transition to blind alleys"; without it a one-cell-wide dead end never fills). Finally every
node gains ``erosionProduced / (N - 1)`` (eq. 5), altitudes are kept non-negative and the goal
is reset to 0. Drops that run out of steps simply evaporate.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.graph import Graph
from jaxswarm.paths import Solution
from jaxswarm.swarm.core import Swarm, Task, check_positive, check_sizes, keep_best, register
from jaxswarm.swarm.walk import FORCED, Walk, edge_table, step_budget, walk


@dataclasses.dataclass(frozen=True)
class RFDConfig:
    """Static sizes and switches.

    Attributes:
      num_agents: D, drops per iteration.
      max_steps: step budget of one walk (paths hold max_steps + 1 nodes); None = N - 1 (the
        longest walk without revisits) on general graphs and min(N - 1, 8 (H + W)) on grids.
      modified: RFD* (eq. 6) instead of the original RFD (eq. 1).
      exponential_erosion: RFD* only: erode by ``p_base ** gradient`` instead of ``gradient``.
    """

    num_agents: int = 256
    max_steps: int | None = None
    modified: bool = True
    exponential_erosion: bool = False

    def __post_init__(self):
        check_sizes(self.num_agents, self.max_steps)
        if self.exponential_erosion and not self.modified:
            raise ValueError("exponential_erosion needs the modified RFD* (p_base)")


class RFDParams(NamedTuple):
    """Numbers of the original RFD (f32 scalars, traced; defaults in ``DEFAULT_RFD``).

    Attributes:
      initial_height: altitude of every node but the goal at the start.
      erosion: E in eq. 4.
      sediment: what a stuck drop deposits where it stands.
      omega: numerator of the uphill weight ``omega / |gradient|``.
      delta: weight of a flat move.
    """

    initial_height: jax.Array
    erosion: jax.Array
    sediment: jax.Array
    omega: jax.Array
    delta: jax.Array


class RFDStarParams(NamedTuple):
    """Numbers of RFD* (f32 scalars, traced; defaults in ``DEFAULT_RFD_STAR``).

    Attributes:
      p_base: base of the exponential transition weight ``p_base ** gradient``.
      alpha: exponent of the goal-distance heuristic ``1 / d_j ** alpha``.
      initial_height: altitude of every node but the goal at the start.
      erosion: E in eq. 4.
      sediment: what a stuck drop deposits where it stands.
      climb: the steepest uphill gradient a drop will take; a drop whose only moves are steeper
        is stuck (so deposits fill blind alleys from their end back to their entrance).
    """

    p_base: jax.Array
    alpha: jax.Array
    initial_height: jax.Array
    erosion: jax.Array
    sediment: jax.Array
    climb: jax.Array


MAX_LOG_EROSION = 60.0
"""Cap on ``log(p_base ** gradient)`` in the exponential erosion (float32 overflows near 88)."""


def _f32(**values):
    return {name: jnp.float32(value) for name, value in values.items()}


DEFAULT_RFD = RFDParams(**_f32(initial_height=1.0, erosion=1.0, sediment=0.1, omega=0.1,
                               delta=0.1))
DEFAULT_RFD_STAR = RFDStarParams(**_f32(p_base=50.0, alpha=50.0, initial_height=1.0,
                                        erosion=50.0, sediment=0.3, climb=0.3))


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


def _build(config: RFDConfig, name: str) -> Swarm:
    def init(key, graph: Graph, task: Task, params) -> RFDState:
        n = graph.num_nodes
        altitude = jnp.full((n,), params.initial_height, jnp.float32).at[task.goal].set(0.0)
        return RFDState(key=key, altitude=altitude,
                        best_path=jnp.full((step_budget(graph, config.max_steps) + 1,), -1,
                                           jnp.int32),
                        best_cost=jnp.float32(jnp.inf))

    def step(state: RFDState, graph: Graph, task: Task, params):
        key, walk_key = jax.random.split(state.key)
        log_weights = transition_rule(config, graph, task, state.altitude, params)
        drops = walk(walk_key, graph, log_weights, task.start, task.goal,
                     num_agents=config.num_agents,
                    max_steps=step_budget(graph, config.max_steps))
        altitude = _erode_and_deposit(config, graph, task, state.altitude, drops, params)
        best_path, best_cost, info = keep_best(drops, state.best_path, state.best_cost)
        return RFDState(key=key, altitude=altitude, best_path=best_path,
                        best_cost=best_cost), info

    def best(state: RFDState) -> Solution:
        return Solution(path=state.best_path, cost=state.best_cost,
                        found=jnp.isfinite(state.best_cost))

    defaults, check = ((DEFAULT_RFD_STAR, _check_rfd_star) if config.modified
                       else (DEFAULT_RFD, _check_rfd))
    return Swarm(name=name, config=config, init=init, step=step, best=best,
                 default_params=defaults, check_params=check,
                 memory=lambda state: state.altitude, memory_label="altitude")


@register("rfd")
def rfd(num_agents: int = 256, max_steps: int | None = None) -> Swarm:
    """The original River Formation Dynamics (eqs. 1-5), with RFDParams."""
    return _build(RFDConfig(num_agents, max_steps, modified=False, exponential_erosion=False),
                  "rfd")


@register("rfd_star")
def rfd_star(num_agents: int = 256, max_steps: int | None = None,
             exponential_erosion: bool = False) -> Swarm:
    """The modified RFD* (eq. 6), with RFDStarParams."""
    return _build(RFDConfig(num_agents, max_steps, True, exponential_erosion), "rfd_star")


def transition_rule(config: RFDConfig, graph: Graph, task: Task, altitude, params):
    """f32[N, K] log-weight of every edge for altitudes f32[N] (the walker's table, see
    :func:`jaxswarm.swarm.walk.edge_table`): eq. 1 for RFD; eq. 6 for RFD*, plus its climb limit
    and the goal taken whenever adjacent."""
    heads = jnp.where(graph.nbr >= 0, graph.nbr, 0)
    gradient = (altitude[:, None] - altitude[heads]) / jnp.where(graph.nbr >= 0, graph.cost, 1.0)
    if config.modified:
        to_goal = jnp.linalg.norm(graph.xy - graph.xy[task.goal], axis=-1)
        # Nodes at distance 0 from the goal other than the goal (general graphs without
        # coordinates) get a neutral heuristic instead of log(0).
        log_distance = jnp.log(jnp.where(to_goal > 0, to_goal, 1.0))
        logw = gradient * jnp.log(params.p_base) - params.alpha * log_distance[heads]
        logw = jnp.where(gradient < -params.climb, -jnp.inf, logw)
        logw = jnp.where(heads == task.goal, FORCED, logw)
    else:
        weight = jnp.where(gradient > 0, gradient,
                           jnp.where(gradient < 0, params.omega / jnp.abs(gradient), params.delta))
        logw = jnp.log(weight)
    return edge_table(graph, logw)


def _erode_and_deposit(config: RFDConfig, graph: Graph, task: Task, altitude, drops: Walk,
                       params):
    """Eqs. 4 and 5: erosion along arrived paths, sediment of stuck drops, uniform sediment."""
    n = graph.num_nodes
    here, there = drops.path[:, :-1], drops.path[:, 1:]
    moved = (drops.slots >= 0) & drops.arrived[:, None]
    here_safe = jnp.where(moved, here, 0)
    there_safe = jnp.where(moved, there, 0)
    distance = graph.cost[here_safe, jnp.maximum(drops.slots, 0).astype(jnp.int32)]
    gradient = (altitude[here_safe] - altitude[there_safe]) / jnp.where(moved, distance, 1.0)
    if config.exponential_erosion:
        # p_base ** gradient, capped so that a cliff cannot overflow float32.
        shape = jnp.exp(jnp.minimum(gradient * jnp.log(params.p_base), MAX_LOG_EROSION))
    else:
        shape = jnp.maximum(gradient, 0.0)
    amount = jnp.where(moved, params.erosion / ((n - 1) * config.num_agents) * shape, 0.0)
    altitude = altitude.at[here_safe].add(-amount)
    stuck_at = jnp.where(drops.stuck, drops.position, n)  # n is out of bounds: dropped
    altitude = altitude.at[stuck_at].add(params.sediment, mode="drop")
    altitude = altitude + jnp.sum(amount) / (n - 1)
    return jnp.maximum(altitude, 0.0).at[task.goal].set(0.0)


def _check_rfd(params: RFDParams) -> None:
    check_positive("initial_height", params.initial_height)
    check_positive("erosion", params.erosion, allow_zero=True)
    check_positive("sediment", params.sediment, allow_zero=True)
    check_positive("omega", params.omega)
    check_positive("delta", params.delta)


def _check_rfd_star(params: RFDStarParams) -> None:
    check_positive("p_base", params.p_base)
    check_positive("alpha", params.alpha, allow_zero=True)
    check_positive("initial_height", params.initial_height)
    check_positive("erosion", params.erosion, allow_zero=True)
    check_positive("sediment", params.sediment, allow_zero=True)
    check_positive("climb", params.climb, allow_zero=True)
