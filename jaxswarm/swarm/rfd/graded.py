"""``rfd_graded``: this project's river formation law (not a paper's algorithm).

It keeps RFD*'s transition rule (eq. 6, ``p_base ** gradient / d_j ** alpha``, the goal taken
whenever adjacent; :func:`graded_transition`, which clips the gradients between a bed and the
plateau) and replaces the paper's erosion (eqs. 4 and 5) by a graded river bed
(:func:`graded_reshape`): each drop carves its path down to ``E`` times the shortest way its
walk offers to water, the goal or a bed carved before (:func:`carve`); a visited bed sinks to
its lowest carved neighbour plus ``E`` times the edge (:func:`erode_banks`); a stuck drop fills
its blind alley, a drop that did not arrive raises its uncarved trail by ``sediment``, and
filled ground settles (:func:`settle`). Uncarved ground stays at ``initial_height``; the first
``greedy_drops`` drops take their most likely move; :func:`regrade` is the memory rule for a
changed map. ``docs/papers.md`` explains each rule, why eqs. 4 and 5 gave way, and what the law
reaches.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.exact.field import distance_field
from jaxswarm.runtime.arithmetic import ordered_cumsum
from jaxswarm.runtime.batching import one_at_a_time
from jaxswarm.swarm.core import Swarm, WalkingConfig, Task, check_positive, default_params
from jaxswarm.swarm.rfd.alleys import blind_alleys
from jaxswarm.swarm.rfd.river import RFDState, check_greedy_drops, gradients, river_swarm
from jaxswarm.swarm.walking import (FORCED, Walk, edge_table, fold_blocks_backwards,
                                    goal_log_distance, neighbour_slots, visited_nodes)
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import move_lengths
from jaxswarm.world.relax import lowest_neighbour, relax

SETTLE_SWEEPS = 1024
"""Most relaxation sweeps of :func:`settle` per iteration (a bound for ground that has no way
down; it stops as soon as nothing moves). Sediment may have to slide far, and settling part of
it in later iterations makes the optimum come later (measured: ``docs/performance.md``)."""

CARVE_COLUMNS = 8
"""Path columns per block of the carving (:func:`carve`). Its reverse running sum and minimum
lower to reduce-windows whose cost grows with the square of the block width on CPU
(measured: ``docs/performance.md``)."""


@dataclasses.dataclass(frozen=True)
class GradedConfig(WalkingConfig):
    """Static sizes and switches of ``rfd_graded``.

    Attributes:
      greedy_drops: how many drops (the first ones) take their most likely move.
    """

    greedy_drops: int = 1

    def __post_init__(self):
        super().__post_init__()
        check_greedy_drops(self.greedy_drops, self.num_agents)


class GradedParams(NamedTuple):
    """Numbers of ``rfd_graded`` (f32 scalars, traced; defaults in ``DEFAULT_GRADED``).

    Attributes:
      p_base: base of the transition weight ``p_base ** gradient`` (eq. 6).
      alpha: exponent of the goal-distance heuristic ``1 / d_j ** alpha`` (eq. 6).
      initial_height: the uncarved plateau (above ``erosion`` times the longest walk).
      erosion: E, the bed's slope: altitude per unit of path still to walk (and the steepest a
        bed looks from the plateau).
      sediment: what each node of a blind alley gains when a stuck drop fills it, and what each
        uncarved node on the trail of a drop that did not arrive gains.
      climb: the steepest uphill gradient a drop on uncarved ground takes; from a carved node,
        uphill moves count as at most this steep.
      repose: the slope filled ground settles to (see :func:`settle`); keep it well above the
        float32 spacing at ``initial_height`` (about 1e-3 at 1e4).
    """

    p_base: jax.Array
    alpha: jax.Array
    initial_height: jax.Array
    erosion: jax.Array
    sediment: jax.Array
    climb: jax.Array
    repose: jax.Array


DEFAULT_GRADED = default_params(GradedParams, p_base=100.0, alpha=12.0, initial_height=1e4,
                                erosion=1.0, sediment=1.0, climb=0.0, repose=0.05)
"""Tuned on the nine paper maps (see ``sweeps/rfd_static.py``)."""


def graded_transition(graph: Graph, task: Task, altitude, params: GradedParams):
    """f32[N, K] log-weight table of eq. 6 for altitudes f32[N], with gradients between a carved
    bed and the uncarved plateau clipped (at least ``-climb`` out of a bed, at most ``erosion``
    into one), climbs steeper than ``climb`` on uncarved ground banned, and the goal forced
    whenever adjacent."""
    heads, gradient = gradients(graph, altitude)  # slot-major: [K, N]
    carved = altitude < params.initial_height
    from_bed, into_bed = carved, neighbour_slots(graph, carved)
    too_steep = (gradient < -params.climb) & ~from_bed
    gradient = jnp.where(from_bed, jnp.maximum(gradient, -params.climb), gradient)
    gradient = jnp.where(~from_bed & into_bed, jnp.minimum(gradient, params.erosion), gradient)
    logw = (gradient * jnp.log(params.p_base)
            - params.alpha * neighbour_slots(graph, goal_log_distance(graph, task.goal)))
    logw = jnp.where(too_steep, -jnp.inf, logw)
    logw = jnp.where(heads == task.goal, FORCED, logw)
    return edge_table(graph, logw.T)


def graded_reshape(graph: Graph, task: Task, altitude, table, drops: Walk, params: GradedParams):
    """f32[N] altitudes after one iteration: blind alleys filled, the trails of drops that did
    not arrive raised and settled, the walked paths carved, the visited banks eroded."""
    n = graph.num_nodes
    altitude = altitude + jnp.where(blind_alleys(graph, table, drops), params.sediment, 0.0)
    failed = visited_nodes(drops, n, ~drops.arrived)
    plateau = altitude >= params.initial_height
    altitude = settle(graph, altitude + jnp.where(failed & plateau, params.sediment, 0.0),
                      params)
    altitude = carve(graph, altitude, drops, params)
    return erode_banks(graph, altitude, visited_nodes(drops, n), params)


@one_at_a_time
def settle(graph: Graph, altitude, params: GradedParams):
    """Sediment slides into pits: f32[N] altitudes, for altitudes f32[N], after sweeps that raise
    every filled node (above ``initial_height``) to at least its lowest neighbour plus
    ``repose`` times the edge length, until no filled node is a pit (or ``SETTLE_SWEEPS`` sweeps
    have run). Then a drop on filled ground (which does not climb) always has a way down to
    unfilled ground or a bed. The result is the lowest ground at or above the given altitudes on
    which no filled node is a pit, whatever the order of the sweeps.

    Under ``vmap`` (a sweep) the runs settle one at a time
    (:func:`~jaxswarm.runtime.batching.one_at_a_time`): most need one sweep, a few dozens, and
    settled together each paid for the slowest."""
    rise = jnp.where(graph.valid_edges(), params.repose * graph.cost, jnp.inf)

    def raise_pits(here, lowest):  # lowest is inf for a node without edges
        pit = (here > params.initial_height) & (lowest > here) & jnp.isfinite(lowest)
        return jnp.where(pit, lowest, here), pit

    return relax(graph, altitude, rise, raise_pits, max_sweeps=SETTLE_SWEEPS)[0]


def erode_banks(graph: Graph, altitude, visited, params: GradedParams):
    """f32[N] altitudes after every carved node a drop visited (``visited`` bool[N]) was lowered
    to its lowest carved neighbour plus ``erosion`` times the edge length, where that is lower:
    the drop saw the deeper bed beside its own."""
    carved = altitude < params.initial_height
    bed = jnp.where(carved, altitude, jnp.inf)
    run = jnp.where(graph.valid_edges(), params.erosion * graph.cost, jnp.inf)
    return jnp.where(visited & carved,
                     jnp.minimum(altitude, lowest_neighbour(graph, bed, run)), altitude)


def carve(graph: Graph, altitude, drops: Walk, params: GradedParams):
    """f32[N] altitudes after every drop lowered each node of its path to ``erosion`` times the
    shortest way its walk offers from there to water: the goal, or a later node of the path
    carved before this iteration (below ``initial_height``) plus its depth.

    Works backwards over the walked part of the paths, ``CARVE_COLUMNS`` columns at a time
    (:func:`~jaxswarm.swarm.walking.fold_blocks_backwards`: under ``vmap`` every run of the
    batch in each step), carrying per drop the length walked after the block and the best way
    to water found there.
    """
    num_agents = drops.moves.shape[0]
    after = jnp.zeros((num_agents,), jnp.float32)
    best = jnp.full((num_agents,), jnp.inf, jnp.float32)
    return fold_blocks_backwards(_carve_block, drops.log, (after, best, altitude),
                                 (altitude, params), graph, block=CARVE_COLUMNS)[2]


def _carve_block(carry, block, per_run, graph: Graph):
    """:func:`carve`'s step over one block of path columns (``block``: their nodes i32[A, B],
    -1 past each path's end, and slots, -1 where no move was made), from ``carry``: per drop the
    length walked after the block f32[A] and the best way to water found there f32[A], and the
    altitudes carved so far f32[N]."""
    after, best, carved = carry
    altitude, params = per_run
    nodes, slot = block
    on_path = nodes >= 0
    node = jnp.where(on_path, nodes, 0)
    edge = move_lengths(graph, node, slot)
    # to_end[a, k]: length drop a walks from this node to where it stopped.
    to_end = after[:, None] + ordered_cumsum(edge, axis=1, reverse=True)
    depth = altitude[node]
    water = jnp.where(on_path & (depth < params.initial_height),
                      depth / params.erosion - to_end, jnp.inf)
    reach = jnp.minimum(jax.lax.cummin(water, axis=1, reverse=True), best[:, None])
    carves = on_path & jnp.isfinite(reach)
    carved = carved.at[jnp.where(carves, node, carved.shape[0])].min(
        params.erosion * (reach + to_end), mode="drop")
    return to_end[:, 0], reach[:, 0], carved


def regrade(state: RFDState, before: Graph, after: Graph, old: Task, new: Task,
            params: GradedParams) -> RFDState:
    """``rfd_graded``'s memory rule for a change of the map or the goal: every bed keeps only the
    depth it can still justify, ``erosion`` times its shortest way to the (new) goal over carved
    ground that is still passable; a bed cut off from the goal returns to the plateau
    (``initial_height``), as does a newly opened node; filled ground keeps its altitude, and the
    new goal is 0.

    Why not the paper's rule: a carved altitude is a promise (``E`` times a walked way to the
    goal), and drops trust it (a drop on the plateau sees any bed as a way down). After a block
    or a goal move a bed may promise a way that no longer exists: kept as it is, it draws the
    drops into the cut river, and nothing in the law raises carved ground again. Re-measured on
    the new map (:func:`~jaxswarm.exact.field.distance_field` over carved ground), the beds that
    still lead to the goal keep guiding the drops, and no bed lies.
    """
    altitude = state.altitude
    carved = (altitude < params.initial_height) | (jnp.arange(altitude.shape[0]) == new.goal)
    beds = dataclasses.replace(after, free=after.free & carved)
    way = distance_field(beds, new.goal)
    altitude = jnp.where(carved, jnp.where(jnp.isfinite(way), params.erosion * way,
                                           params.initial_height), altitude)
    altitude = jnp.where(after.free & ~before.free, params.initial_height, altitude)
    return dataclasses.replace(state, altitude=altitude.at[new.goal].set(0.0))


def _check_graded(params: GradedParams) -> None:
    check_positive("p_base", params.p_base)
    check_positive("alpha", params.alpha, allow_zero=True)
    check_positive("initial_height", params.initial_height)
    check_positive("erosion", params.erosion)  # the slope: 0 would flatten every bed to the sea
    check_positive("sediment", params.sediment, allow_zero=True)
    check_positive("climb", params.climb, allow_zero=True)
    check_positive("repose", params.repose, allow_zero=True)


def build_rfd_graded(config: GradedConfig) -> Swarm:
    """This project's river formation law (see the module docstring), with :class:`GradedParams`."""
    def reshape(graph, task, altitude, residual, table, drops, params):
        # The graded law sets altitudes: the shared residual (compensated additions) stays 0.
        return graded_reshape(graph, task, altitude, table, drops, params), residual

    return river_swarm("rfd_graded", config, transition=graded_transition, reshape=reshape,
                       greedy_drops=config.greedy_drops, default_params=DEFAULT_GRADED,
                       check_params=_check_graded)
