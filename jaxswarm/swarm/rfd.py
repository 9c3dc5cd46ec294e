"""River Formation Dynamics: the original RFD and the modified RFD* of the RFD paper.

Every node has an altitude; the goal is the sea, fixed at 0, every other node starts at
``initial_height``. Each iteration all drops walk from the start (:mod:`jaxswarm.swarm.walk`),
choosing among admissible neighbours ``j`` of their node ``i`` by the gradient

    gradient(i, j) = (altitude(i) - altitude(j)) / distance(i, j)                     (eq. 2)

* RFD (eqs. 1, 3): weight ``gradient`` downhill, ``omega / |gradient|`` uphill, ``delta`` flat.
* RFD* (eq. 6): weight ``p_base ** gradient / d_j ** alpha`` for every admissible neighbour, with
  ``d_j`` the straight-line distance from ``j`` to the goal; the goal is taken whenever adjacent.

After the walk the drops that reached the goal erode their paths, by one of three laws
(``erosion_law``; the original RFD always uses ``"linear"``):

* ``"linear"`` (eq. 4): each edge ``i -> j`` of an arrived path erodes node ``i`` by
  ``E / ((N - 1) * D) * gradient(i, j)`` (negative gradients erode nothing); then every node gains
  ``erosionProduced / (N - 1)`` (eq. 5).
* ``"exponential"``: the same with ``p_base ** gradient`` in place of ``gradient`` (the exponential
  form the paper suggests for erosion too; it also erodes flat ground), and eq. 5.
* ``"graded"`` (RFD*'s default, our law): a river cuts its bed down to a graded profile, so a
  drop that arrived lowers every node of its path to ``E * (length still to walk to the goal)``
  when that is lower than the node's altitude. The altitude of a carved node is then ``E`` times
  the shortest route to the goal any drop has walked from it, and at a fork the branch with the
  shorter remainder is the steeper one, whichever drop found it. Ground that no drop has carved
  stays at ``initial_height`` (keep it above ``E`` times the longest walk); a drop standing in a
  carved bed climbs onto it as if the slope were at most ``climb`` steep, so it keeps looking
  for shortcuts beside its river (weight ``p_base ** -climb`` at worst). No eq. 5 sediment: the
  profile is not levelled.

Why a third law: with eqs. 4 and 5 an altitude difference has to travel back from the goal one
node per iteration and reflects how often an edge was used rather than how short the paths
through it were; on the paper's 50 x 50 and 100 x 100 maps this converged to long paths within
100 iterations for every setting we tried (``sweeps/rfd_static.py`` reports both laws).

A drop that got stuck deposits ``sediment`` where it stands. RFD* drops do not climb slopes
steeper than ``climb`` on uncarved ground: a drop whose only moves are steeper is stuck too, so
deposits fill a blind alley from its end back to its entrance and later drops avoid it (the
paper's "reduces the likelihood of transition to blind alleys"; without it a one-cell-wide dead
end never fills). Altitudes are kept non-negative and the goal is reset to 0. Drops that run out
of steps simply evaporate.
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


EROSION_LAWS = ("linear", "exponential", "graded")
"""How arrived drops erode their paths (see the module docstring)."""


@dataclasses.dataclass(frozen=True)
class RFDConfig:
    """Static sizes and switches.

    Attributes:
      num_agents: D, drops per iteration.
      max_steps: step budget of one walk (paths hold max_steps + 1 nodes); None = N - 1 (the
        longest walk without revisits) on general graphs and min(N - 1, 8 (H + W)) on grids.
      modified: RFD* (eq. 6) instead of the original RFD (eq. 1).
      erosion_law: one of ``EROSION_LAWS`` (see the module docstring); the original RFD only
        has ``"linear"``.
    """

    num_agents: int = 256
    max_steps: int | None = None
    modified: bool = True
    erosion_law: str = "graded"

    def __post_init__(self):
        check_sizes(self.num_agents, self.max_steps)
        if self.erosion_law not in EROSION_LAWS:
            raise ValueError(f"unknown erosion_law {self.erosion_law!r}; "
                             f"choose one of {', '.join(EROSION_LAWS)}")
        if self.erosion_law != "linear" and not self.modified:
            raise ValueError(f"erosion_law {self.erosion_law!r} needs the modified RFD* "
                             "(the original RFD erodes by eq. 4 only)")


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
      initial_height: altitude of every node but the goal at the start (graded law: the
        uncarved plateau, above ``erosion`` times the longest walk).
      erosion: E in eq. 4 (linear and exponential laws); the graded law's slope, altitude per
        unit of path still to walk.
      sediment: what a stuck drop deposits where it stands.
      climb: the steepest uphill gradient a drop on uncarved ground will take; a drop whose only
        moves are steeper is stuck (so deposits fill blind alleys from their end back to their
        entrance). Graded law: from a carved node, uphill moves count as at most this steep.
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
DEFAULT_RFD_STAR = RFDStarParams(**_f32(p_base=10.0, alpha=7.0, initial_height=1e4,
                                        erosion=1.0, sediment=0.3, climb=1.0))
"""Defaults for the graded law (tuned on the nine paper maps, see ``sweeps/rfd_static.py``)."""
DEFAULT_RFD_STAR_EQ4 = RFDStarParams(**_f32(p_base=50.0, alpha=50.0, initial_height=1.0,
                                            erosion=50.0, sediment=0.3, climb=0.3))
"""Defaults for the linear and exponential laws (eqs. 4 and 5)."""


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

    if not config.modified:
        defaults, check = DEFAULT_RFD, _check_rfd
    elif config.erosion_law == "graded":
        defaults, check = DEFAULT_RFD_STAR, _check_graded
    else:
        defaults, check = DEFAULT_RFD_STAR_EQ4, _check_rfd_star
    return Swarm(name=name, config=config, init=init, step=step, best=best,
                 default_params=defaults, check_params=check,
                 memory=lambda state: state.altitude, memory_label="altitude")


@register("rfd")
def rfd(num_agents: int = 256, max_steps: int | None = None) -> Swarm:
    """The original River Formation Dynamics (eqs. 1-5), with RFDParams."""
    return _build(RFDConfig(num_agents, max_steps, modified=False, erosion_law="linear"), "rfd")


@register("rfd_star")
def rfd_star(num_agents: int = 256, max_steps: int | None = None,
             erosion_law: str = "graded") -> Swarm:
    """The modified RFD* (eq. 6), with RFDStarParams; ``erosion_law`` one of EROSION_LAWS."""
    return _build(RFDConfig(num_agents, max_steps, True, erosion_law), "rfd_star")


def transition_rule(config: RFDConfig, graph: Graph, task: Task, altitude, params):
    """f32[N, K] log-weight of every edge for altitudes f32[N] (the walker's table, see
    :func:`jaxswarm.swarm.walk.edge_table`): eq. 1 for RFD; eq. 6 for RFD*, plus its climb limit
    (a floor on the uphill gradient out of a carved bed, under the graded law) and the goal taken
    whenever adjacent."""
    heads = jnp.where(graph.nbr >= 0, graph.nbr, 0)
    gradient = (altitude[:, None] - altitude[heads]) / jnp.where(graph.nbr >= 0, graph.cost, 1.0)
    if config.modified:
        to_goal = jnp.linalg.norm(graph.xy - graph.xy[task.goal], axis=-1)
        # Nodes at distance 0 from the goal other than the goal (general graphs without
        # coordinates) get a neutral heuristic instead of log(0).
        log_distance = jnp.log(jnp.where(to_goal > 0, to_goal, 1.0))
        too_steep = gradient < -params.climb
        if config.erosion_law == "graded":
            carved = (altitude < params.initial_height)[:, None]
            too_steep = too_steep & ~carved
            gradient = jnp.where(carved, jnp.maximum(gradient, -params.climb), gradient)
        logw = gradient * jnp.log(params.p_base) - params.alpha * log_distance[heads]
        logw = jnp.where(too_steep, -jnp.inf, logw)
        logw = jnp.where(heads == task.goal, FORCED, logw)
    else:
        weight = jnp.where(gradient > 0, gradient,
                           jnp.where(gradient < 0, params.omega / jnp.abs(gradient), params.delta))
        logw = jnp.log(weight)
    return edge_table(graph, logw)


def _erode_and_deposit(config: RFDConfig, graph: Graph, task: Task, altitude, drops: Walk,
                       params):
    """One iteration's erosion (by ``config.erosion_law``) and the sediment of stuck drops."""
    n = graph.num_nodes
    moved = (drops.slots >= 0) & drops.arrived[:, None]
    here = jnp.where(moved, drops.path[:, :-1], 0)
    distance = jnp.where(moved, graph.cost[here, jnp.maximum(drops.slots, 0).astype(jnp.int32)],
                         0.0)
    if config.erosion_law == "graded":
        altitude = _carve_graded(altitude, here, moved, distance, drops.length, params)
    else:
        altitude = _erode_eq4(config, altitude, drops, here, moved, distance, params)
    stuck_at = jnp.where(drops.stuck, drops.position, n)  # n is out of bounds: dropped
    altitude = altitude.at[stuck_at].add(params.sediment, mode="drop")
    return jnp.maximum(altitude, 0.0).at[task.goal].set(0.0)


def _erode_eq4(config: RFDConfig, altitude, drops: Walk, here, moved, distance, params):
    """Eqs. 4 and 5 (or the exponential form of eq. 4): f32[N] altitudes after erosion."""
    n = altitude.shape[0]
    there = jnp.where(moved, drops.path[:, 1:], 0)
    gradient = (altitude[here] - altitude[there]) / jnp.where(moved, distance, 1.0)
    if config.erosion_law == "exponential":
        # p_base ** gradient, capped so that a cliff cannot overflow float32.
        shape = jnp.exp(jnp.minimum(gradient * jnp.log(params.p_base), MAX_LOG_EROSION))
    else:
        shape = jnp.maximum(gradient, 0.0)
    amount = jnp.where(moved, params.erosion / ((n - 1) * config.num_agents) * shape, 0.0)
    altitude = altitude.at[here].add(-amount)
    return altitude + jnp.sum(amount) / (n - 1)


def _carve_graded(altitude, here, moved, distance, length, params):
    """The graded law: f32[N] altitudes after each arrived path (nodes ``here`` i32[A, L - 1],
    edge lengths ``distance`` f32[A, L - 1], path lengths ``length`` f32[A]) lowered its nodes to
    ``erosion`` times the length still to walk from them."""
    n = altitude.shape[0]
    to_walk = length[:, None] - jnp.cumsum(distance, axis=1) + distance
    bed = jnp.full((n,), jnp.inf, altitude.dtype).at[jnp.where(moved, here, n)].min(
        params.erosion * to_walk, mode="drop")
    return jnp.minimum(altitude, bed)


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


def _check_graded(params: RFDStarParams) -> None:
    _check_rfd_star(params)
    check_positive("erosion", params.erosion)  # the slope: 0 would flatten every bed to the sea
