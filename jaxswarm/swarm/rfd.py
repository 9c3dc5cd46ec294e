"""River Formation Dynamics: the original RFD and the modified RFD* of the RFD paper.

Every node has an altitude; the goal is the sea, fixed at 0, every other node starts at
``initial_height``. Each iteration all drops walk from the start (:mod:`jaxswarm.swarm.walk`),
choosing among admissible neighbours ``j`` of their node ``i`` by the gradient

    gradient(i, j) = (altitude(i) - altitude(j)) / distance(i, j)                     (eq. 2)

* RFD (eqs. 1, 3): weight ``gradient`` downhill, ``omega / |gradient|`` uphill, ``delta`` flat.
* RFD* (eq. 6): weight ``p_base ** gradient / d_j ** alpha`` for every admissible neighbour, with
  ``d_j`` the straight-line distance from ``j`` to the goal; the goal is taken whenever adjacent.

After the walk the drops erode their paths, by one of three laws (``erosion_law``; the original
RFD always uses ``"linear"``):

* ``"linear"`` (eq. 4): each edge ``i -> j`` of a path that reached the goal erodes node ``i`` by
  ``E / ((N - 1) * D) * gradient(i, j)`` (negative gradients erode nothing); then every node gains
  ``erosionProduced / (N - 1)`` (eq. 5).
* ``"exponential"``: the same with ``p_base ** gradient`` in place of ``gradient`` (the exponential
  form the paper suggests for erosion too; it also erodes flat ground), and eq. 5.
* ``"graded"`` (RFD*'s default, our law): a river cuts its bed down to a graded profile. A drop
  lowers every node ``i`` of its path to ``E * r(i)`` when that is lower, where ``r(i)`` is the
  shortest way its own walk offers from ``i`` to water: to the goal, or to any node ``m`` later
  on its path carved before this iteration, plus ``altitude(m) / E`` (a tributary: the drop need
  not arrive, only drain into a bed). The altitude of a carved node is then ``E`` times the
  shortest route to the goal the swarm has walked from it, refined one walked edge at a time
  (an asynchronous Bellman-Ford over the walks), and at a fork the branch with the shorter
  remainder is the steeper one. Ground that no drop has carved stays at ``initial_height`` (keep
  it above ``E`` times the longest walk). Between bed and plateau the transition sees clipped
  gradients: a drop in a bed climbs out as if the slope were at most ``climb`` steep, so it
  keeps looking for shortcuts beside its river, and a drop on the plateau sees a bed as no
  steeper than ``E``, the bed's own slope, so a river does not swallow every drop that passes
  beside it and other routes keep being walked. A drop also erodes the banks it passes: a
  carved node it visits is lowered to its lowest carved neighbour plus ``E`` times the edge
  (one look sideways, so a high stretch of bed left by an early meandering walk is corrected
  by the first drop that visits it, wherever that drop goes next). No eq. 5 sediment: the
  profile is not levelled.

Why a third law: with eqs. 4 and 5 an altitude difference has to travel back from the goal one
node per iteration and reflects how often an edge was used rather than how short the paths
through it were; on the paper's 50 x 50 and 100 x 100 maps this converged to long paths within
100 iterations for every setting we tried (``sweeps/rfd_static.py`` reports both laws).

Sediment. An original RFD drop that got stuck deposits ``sediment`` where it stands. An RFD*
drop that got stuck fills the blind alley it ran into: the sediment settles where it stopped
and flows back along its trail as long as the trail node has no other way out (every admissible
move from it leads back or into the alley); each node filled in an iteration gains ``sediment``
once. RFD* drops do not climb slopes steeper than ``climb`` on uncarved ground, so a filled
alley is closed to later drops (the paper's "reduces the likelihood of transition to blind
alleys"). Under the graded law a drop that did not arrive also leaves ``sediment`` on
every uncarved node of its trail (once per node and iteration), and filled ground then settles
(:func:`settle`): no filled node stays a pit, each stands at least ``repose`` per unit length
above its lowest neighbour. Ground explored in vain thus rises and slopes down to where no drop
has been yet or to a bed, and the drops, which do not climb, cross it to the frontier instead of
trapping themselves on it (on the alley maps the basins in front of the walls are otherwise
filled one stuck drop at a time, and no drop arrived on alley100 within 100 iterations).
Altitudes are kept non-negative and the goal is reset to 0. Drops that run out of steps simply
evaporate.

Greedy drops. The first ``greedy_drops`` drops of each RFD* iteration (1 by default) do not
draw their moves: each takes its most likely admissible move (ties drawn at random), i.e. it
runs down the river. Once the altitudes are right, a greedy drop walks the shortest path, which a
drawing drop of a 100 x 100 map almost never does in full (one less likely move in 150 is
enough to miss it); the other drops keep exploring.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.graph import Graph, lowest_neighbour, move_lengths, relax, straight_line
from jaxswarm.paths import Solution
from jaxswarm.swarm.core import Swarm, Task, check_positive, check_sizes, keep_best, register
from jaxswarm.swarm.walk import FORCED, Walk, edge_table, step_budget, visited_nodes, walk


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
      greedy_drops: how many of the drops always take their most likely move instead of
        drawing one (see the module docstring); 0 for the original RFD.
      devices: spread each walk's drops over this many devices (see
        :func:`jaxswarm.swarm.walk.walk`); results are the same as with one.
    """

    num_agents: int = 256
    max_steps: int | None = None
    modified: bool = True
    erosion_law: str = "graded"
    greedy_drops: int = 0
    devices: int = 1

    def __post_init__(self):
        check_sizes(self.num_agents, self.max_steps, self.devices)
        if not 0 <= self.greedy_drops <= self.num_agents:
            raise ValueError(f"greedy_drops must be between 0 and num_agents "
                             f"({self.num_agents}), got {self.greedy_drops}")
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
        unit of path still to walk (and the steepest a bed looks from the plateau).
      sediment: what each node of a blind alley gains when a stuck drop fills it; graded law:
        also what each uncarved node on the trail of a drop that did not arrive gains.
      climb: the steepest uphill gradient a drop on uncarved ground will take; a drop whose only
        moves are steeper is stuck (so a filled blind alley is closed to later drops). Graded
        law: from a carved node, uphill moves count as at most this steep.
      repose: graded law: the slope filled ground settles to (see :func:`settle`); keep it
        well above the float32 spacing at ``initial_height`` (about 1e-3 at 1e4).
    """

    p_base: jax.Array
    alpha: jax.Array
    initial_height: jax.Array
    erosion: jax.Array
    sediment: jax.Array
    climb: jax.Array
    repose: jax.Array


SETTLE_SWEEPS = 1024
"""Most relaxation sweeps of :func:`settle` per iteration (a bound for ground that has no way
down; it stops as soon as nothing moves). Sediment may have to slide far: at one maze100
iteration we measured, settling took 188 sweeps (5.5-7 ms). Settling at most 64 sweeps per
iteration, and the rest in later ones, made RFD* find the maze100 optimum later: in two sets of
20 seeds at median iterations 67 and 26.5, against 22.5 and 19 when settled fully."""

CARVE_COLUMNS = 8
"""Path columns per block of the graded carving (:func:`_carve_graded`). Its reverse running
sum and minimum lower to reduce-windows whose cost grows with the square of the block width on
CPU: 8 columns carve maze100 in about 3 ms per iteration, 64 (the walk's block) in about 5."""

MAX_LOG_EROSION = 60.0
"""Cap on ``log(p_base ** gradient)`` in the exponential erosion (float32 overflows near 88)."""


def _f32(**values):
    # NumPy scalars, not JAX arrays: importing the module must not start JAX's backend (see
    # jaxswarm.cpu.configure); jit and vmap take them as float32 arrays.
    return {name: np.float32(value) for name, value in values.items()}


DEFAULT_RFD = RFDParams(**_f32(initial_height=1.0, erosion=1.0, sediment=0.1, omega=0.1,
                               delta=0.1))
DEFAULT_RFD_STAR = RFDStarParams(**_f32(p_base=100.0, alpha=12.0, initial_height=1e4,
                                        erosion=1.0, sediment=1.0, climb=0.0, repose=0.05))
"""Defaults for the graded law (tuned on the nine paper maps, see ``sweeps/rfd_static.py``)."""
DEFAULT_RFD_STAR_EQ4 = RFDStarParams(**_f32(p_base=50.0, alpha=50.0, initial_height=1.0,
                                            erosion=50.0, sediment=0.3, climb=0.3, repose=0.0))
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
                     max_steps=step_budget(graph, config.max_steps), devices=config.devices,
                     greedy_agents=config.greedy_drops)
        altitude = _erode_and_deposit(config, graph, task, state.altitude, log_weights, drops,
                                      params)
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
def rfd(num_agents: int = 256, max_steps: int | None = None, devices: int = 1) -> Swarm:
    """The original River Formation Dynamics (eqs. 1-5), with RFDParams."""
    return _build(RFDConfig(num_agents, max_steps, modified=False, erosion_law="linear",
                            devices=devices), "rfd")


@register("rfd_star")
def rfd_star(num_agents: int = 256, max_steps: int | None = None,
             erosion_law: str = "graded", greedy_drops: int = 1, devices: int = 1) -> Swarm:
    """The modified RFD* (eq. 6), with RFDStarParams; ``erosion_law`` one of EROSION_LAWS."""
    return _build(RFDConfig(num_agents, max_steps, True, erosion_law, greedy_drops, devices),
                  "rfd_star")


def transition_rule(config: RFDConfig, graph: Graph, task: Task, altitude, params):
    """f32[N, K] log-weight of every edge for altitudes f32[N] (the walker's table, see
    :func:`jaxswarm.swarm.walk.edge_table`): eq. 1 for RFD; eq. 6 for RFD*, plus its climb limit
    and the goal taken whenever adjacent. Under the graded law, gradients between a carved bed
    and the uncarved plateau are clipped: at least -climb out of the bed, at most ``erosion``
    (the bed's own slope) into it."""
    heads = jnp.where(graph.nbr >= 0, graph.nbr, 0)
    gradient = (altitude[:, None] - altitude[heads]) / jnp.where(graph.nbr >= 0, graph.cost, 1.0)
    if config.modified:
        to_goal = straight_line(graph, task.goal)
        # Nodes at distance 0 from the goal other than the goal (general graphs without
        # coordinates) get a neutral heuristic instead of log(0).
        log_distance = jnp.log(jnp.where(to_goal > 0, to_goal, 1.0))
        too_steep = gradient < -params.climb
        if config.erosion_law == "graded":
            carved = altitude < params.initial_height
            from_bed, into_bed = carved[:, None], carved[heads]
            too_steep = too_steep & ~from_bed
            # Between a bed and the plateau: out of it at most climb steep, into it at most as
            # steep as the bed itself (E), so a river does not drain every drop beside it.
            gradient = jnp.where(from_bed, jnp.maximum(gradient, -params.climb), gradient)
            gradient = jnp.where(~from_bed & into_bed, jnp.minimum(gradient, params.erosion),
                                 gradient)
        logw = gradient * jnp.log(params.p_base) - params.alpha * log_distance[heads]
        logw = jnp.where(too_steep, -jnp.inf, logw)
        logw = jnp.where(heads == task.goal, FORCED, logw)
    else:
        weight = jnp.where(gradient > 0, gradient,
                           jnp.where(gradient < 0, params.omega / jnp.abs(gradient), params.delta))
        logw = jnp.log(weight)
    return edge_table(graph, logw)


def _erode_and_deposit(config: RFDConfig, graph: Graph, task: Task, altitude, log_weights,
                       drops: Walk, params):
    """One iteration's sediment, then its erosion (by ``config.erosion_law``), for altitudes f32[N]
    and the walk's transition table f32[N, K]."""
    n = graph.num_nodes
    if config.modified:
        altitude = altitude + jnp.where(blind_alleys(graph, log_weights, drops), params.sediment,
                                        0.0)
    else:
        stuck_at = jnp.where(drops.stuck, drops.position, n)  # n is out of bounds: dropped
        altitude = altitude.at[stuck_at].add(params.sediment, mode="drop")
    if config.erosion_law == "graded":
        failed = visited_nodes(drops, n, ~drops.arrived)
        plateau = altitude >= params.initial_height
        altitude = settle(graph, altitude + jnp.where(failed & plateau, params.sediment, 0.0),
                          params)
        altitude = _carve_graded(graph, altitude, drops, params)
        altitude = erode_banks(graph, altitude, visited_nodes(drops, n), params)
    else:
        altitude = _erode_eq4(config, graph, altitude, drops, params)
    return jnp.maximum(altitude, 0.0).at[task.goal].set(0.0)


def settle(graph: Graph, altitude, params):
    """Sediment slides into pits: f32[N] altitudes, for altitudes f32[N], after sweeps that raise
    every filled node (above ``initial_height``) to at least its lowest neighbour plus
    ``repose`` times the edge length, until no filled node is a pit (or ``SETTLE_SWEEPS`` sweeps
    have run). Then a drop on filled ground (which does not climb) always has a way down to
    unfilled ground or a bed. The result is the lowest ground at or above the given altitudes on
    which no filled node is a pit, whatever the order of the sweeps."""
    rise = jnp.where(graph.valid_edges(), params.repose * graph.cost, jnp.inf)

    def raise_pits(here, lowest):  # lowest is inf for a node without edges
        pit = (here > params.initial_height) & (lowest > here) & jnp.isfinite(lowest)
        return jnp.where(pit, lowest, here), pit

    return relax(graph, altitude, rise, raise_pits, max_sweeps=SETTLE_SWEEPS)[0]


def erode_banks(graph: Graph, altitude, visited, params):
    """f32[N] altitudes after every carved node a drop visited (``visited`` bool[N]) was lowered
    to its lowest carved neighbour plus ``erosion`` times the edge length, where that is lower:
    the drop saw the deeper bed beside its own."""
    carved = altitude < params.initial_height
    bed = jnp.where(carved, altitude, jnp.inf)
    run = jnp.where(graph.valid_edges(), params.erosion * graph.cost, jnp.inf)
    return jnp.where(visited & carved,
                     jnp.minimum(altitude, lowest_neighbour(graph, bed, run)), altitude)


def _erode_eq4(config: RFDConfig, graph: Graph, altitude, drops: Walk, params):
    """Eqs. 4 and 5 (or the exponential form of eq. 4) along the paths of the drops that
    arrived: f32[N] altitudes after erosion."""
    n = altitude.shape[0]
    moved = (drops.slots >= 0) & drops.arrived[:, None]
    here = jnp.where(moved, drops.path[:, :-1], 0)
    there = jnp.where(moved, drops.path[:, 1:], 0)
    distance = move_lengths(graph, here, drops.slots)
    gradient = (altitude[here] - altitude[there]) / jnp.where(moved, distance, 1.0)
    if config.erosion_law == "exponential":
        # p_base ** gradient, capped so that a cliff cannot overflow float32.
        shape = jnp.exp(jnp.minimum(gradient * jnp.log(params.p_base), MAX_LOG_EROSION))
    else:
        shape = jnp.maximum(gradient, 0.0)
    amount = jnp.where(moved, params.erosion / ((n - 1) * config.num_agents) * shape, 0.0)
    altitude = altitude.at[here].add(-amount)
    return altitude + jnp.sum(amount) / (n - 1)


def _carve_graded(graph: Graph, altitude, drops: Walk, params):
    """The graded law: f32[N] altitudes after every drop lowered each node of its path to
    ``erosion`` times the shortest way its walk offers from there to water: the goal, or a later
    node of the path carved before this iteration (below ``initial_height``) plus its depth.

    Works backwards over the walked part of the paths, ``CARVE_COLUMNS`` columns at a time,
    carrying per drop the length walked after the block and the best way to water found there.
    """
    n = altitude.shape[0]
    num_agents, width = drops.path.shape
    blocks = -(-width // CARVE_COLUMNS)
    walked_blocks = (drops.steps + CARVE_COLUMNS) // CARVE_COLUMNS  # blocks holding nodes

    def one_block(carry):
        block, after, best, carved = carry
        # The block's columns, read past the end as -1 (no copy of the paths padded to whole
        # blocks; the last node has no move, so slots reads one column further as -1).
        columns = block * CARVE_COLUMNS + jnp.arange(CARVE_COLUMNS)
        nodes = jnp.take(drops.path, columns, axis=1, mode="fill", fill_value=-1)
        slot = jnp.take(drops.slots, columns, axis=1, mode="fill", fill_value=-1)
        on_path = nodes >= 0
        node = jnp.where(on_path, nodes, 0)
        edge = move_lengths(graph, node, slot)
        # to_end[a, k]: length drop a walks from this node to where it stopped.
        to_end = after[:, None] + jax.lax.cumsum(edge, axis=1, reverse=True)
        depth = altitude[node]
        water = jnp.where(on_path & (depth < params.initial_height),
                          depth / params.erosion - to_end, jnp.inf)
        reach = jnp.minimum(jax.lax.cummin(water, axis=1, reverse=True), best[:, None])
        carves = on_path & jnp.isfinite(reach)
        carved = carved.at[jnp.where(carves, node, n)].min(params.erosion * (reach + to_end),
                                                           mode="drop")
        return block - 1, to_end[:, 0], reach[:, 0], carved

    _, _, _, carved = jax.lax.while_loop(
        lambda carry: carry[0] >= 0, one_block,
        (jnp.minimum(walked_blocks, blocks) - 1, jnp.zeros((num_agents,), jnp.float32),
         jnp.full((num_agents,), jnp.inf, jnp.float32), altitude))
    return carved


def blind_alleys(graph: Graph, log_weights, drops: Walk):
    """bool[N]: the blind alleys the stuck drops of a walk (``drops``, A agents) ran into, given
    the walk's transition table ``log_weights`` f32[N, K].

    For each stuck drop: the node where it stopped, and back along its trail every node from
    which each admissible move (finite ``log_weights`` f32[N, K]) leads either back to where the
    drop came from or into a node already filled; the first node with another way out, and the
    start, end the alley.
    """
    n = graph.num_nodes
    num_agents = drops.path.shape[0]
    agents = jnp.arange(num_agents)
    last = jnp.sum(drops.path >= 0, axis=1) - 1  # index of the node where each drop stopped
    filled = jnp.zeros((n,), bool).at[jnp.where(drops.stuck, drops.position, n)].set(
        True, mode="drop")

    def any_filling(carry):
        return jnp.any(carry[1])

    def one_back(carry):
        back, filling, filled = carry
        index = jnp.maximum(last - back, 1)
        node, came_from = drops.path[agents, index], drops.path[agents, index - 1]
        heads = graph.nbr[node]
        way_out = ((log_weights[node] > -jnp.inf) & (heads != came_from[:, None])
                   & ~filled[jnp.where(heads >= 0, heads, 0)])
        dead = filling & (last - back >= 1) & ~jnp.any(way_out, axis=1)
        return back + 1, dead, filled.at[jnp.where(dead, node, n)].set(True, mode="drop")

    _, _, filled = jax.lax.while_loop(any_filling, one_back,
                                      (jnp.int32(1), drops.stuck, filled))
    return filled


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
    check_positive("repose", params.repose, allow_zero=True)
