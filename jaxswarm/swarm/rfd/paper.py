"""River Formation Dynamics as the RFD paper writes it: the original RFD and the modified RFD*.

Both walk their drops over the gradient of eq. 2, ``(altitude(i) - altitude(j)) / distance(i,
j)``, among the neighbours a drop has not visited yet (the paper's ``V_k``, ``U_k``, ``F_k``).
``rfd`` weighs a move by eqs. 1 and 3 (``gradient`` downhill, ``omega / |gradient|`` uphill,
``delta`` flat; :func:`rfd_transition`), ``rfd_star`` by eq. 6 (``p_base ** gradient / d_j **
alpha``, ``d_j`` the straight-line distance to the goal; :func:`rfd_star_transition`), taking
the goal whenever adjacent, where eq. 6 divides by 0. After the walk (Algorithm 1, lines 6-8)
each move ``i -> j`` of an eroding path erodes ``i`` by ``E / ((N - 1) D) gradient(i, j)`` (eq.
4; :func:`erode`) and every node gains ``erosionProduced / (N - 1)`` (eq. 5); a drop that could
not move deposits ``sediment`` where it stands. Altitudes stay non-negative, the goal at 0, and
every change is added by compensated summation (:func:`~jaxswarm.swarm.rfd.river.add_compensated`).
``rfd_star``'s options (:class:`RFDStarConfig`) and how we read the paper for each and for its
defaults: ``docs/papers.md``.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.runtime.arithmetic import exp, ordered_sum
from jaxswarm.swarm.core import Swarm, WalkingConfig, Task, check_positive, default_params
from jaxswarm.swarm.rfd.alleys import blind_alleys
from jaxswarm.swarm.rfd.river import (add_compensated, check_greedy_drops, gradients,
                                      river_swarm, sediment_where_stuck)
from jaxswarm.swarm.walking import (FORCED, Walk, edge_table, goal_log_distance, neighbour_slots,
                                    on_walk)
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import move_lengths

EROSION_LAWS = ("linear", "exponential")
"""How ``rfd_star``'s drops erode their paths: eq. 4, or its exponential form."""
EROSION_PATHS = ("arrived", "travelled")
"""Whose paths ``rfd_star`` erodes: the drops that reached the goal, or every drop's."""

MAX_LOG_EROSION = 60.0
"""Cap on ``log(p_base ** gradient)`` in the exponential erosion (float32 overflows near 88)."""


RFDConfig = WalkingConfig
"""The original RFD has only the sizes (``num_agents`` is D, the drops per iteration)."""


@dataclasses.dataclass(frozen=True)
class RFDStarConfig(WalkingConfig):
    """Static sizes and switches of RFD* (the defaults are the paper's algorithm).

    Attributes:
      erosion_law: one of ``EROSION_LAWS``.
      erode: one of ``EROSION_PATHS``: the paths of the drops that arrived (Algorithm 1's
        "complete paths") or of every drop (the text's "all travelled paths").
      greedy_drops: ours: how many drops (the first ones) take their most likely move.
      fill_blind_alleys: ours: a stuck drop fills its whole blind alley with ``sediment``.
      max_climb: ours: the steepest uphill gradient a drop takes (None: any, as the paper).
    """

    erosion_law: str = "linear"
    erode: str = "arrived"
    greedy_drops: int = 0
    fill_blind_alleys: bool = False
    max_climb: float | None = None

    def __post_init__(self):
        super().__post_init__()
        check_greedy_drops(self.greedy_drops, self.num_agents)
        if self.erosion_law not in EROSION_LAWS:
            raise ValueError(f"unknown erosion_law {self.erosion_law!r}; "
                             f"choose one of {', '.join(EROSION_LAWS)}")
        if self.erode not in EROSION_PATHS:
            raise ValueError(f"unknown erode {self.erode!r}; "
                             f"choose one of {', '.join(EROSION_PATHS)}")
        if self.max_climb is not None:
            check_positive("max_climb", self.max_climb, allow_zero=True)


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
      p_base: base of the exponential transition weight ``p_base ** gradient`` (eq. 6).
      alpha: exponent of the goal-distance heuristic ``1 / d_j ** alpha`` (eq. 6).
      initial_height: altitude of every node but the goal at the start.
      erosion: E in eq. 4.
      sediment: what a stuck drop deposits where it stands (with ``fill_blind_alleys``: on every
        node of its blind alley).
    """

    p_base: jax.Array
    alpha: jax.Array
    initial_height: jax.Array
    erosion: jax.Array
    sediment: jax.Array


DEFAULT_RFD = default_params(RFDParams, initial_height=1.0, erosion=765.0167, sediment=1.157309,
                             omega=0.00023811474, delta=0.02945256)
"""The setting RFD's calibration found (``tunes/rfd.toml``, ``results/calibration``: on held-out
maps at least as good as erosion = 1 and sediment = omega = delta = 0.1 everywhere, a mean gap
of 6.66 against 7.12); the initial height only sets the unit of the altitudes."""
DEFAULT_RFD_STAR = default_params(RFDStarParams, p_base=50.0, alpha=50.0, initial_height=1.0,
                                  erosion=50.0, sediment=0.3)


def rfd_transition(graph: Graph, task: Task, altitude, params: RFDParams):
    """f32[N, K] log-weight table of eq. 1 for altitudes f32[N]."""
    _, gradient = gradients(graph, altitude)
    weight = jnp.where(gradient > 0, gradient,
                       jnp.where(gradient < 0, params.omega / jnp.abs(gradient), params.delta))
    return edge_table(graph, jnp.log(weight).T)


def rfd_star_transition(config: RFDStarConfig, graph: Graph, task: Task, altitude,
                        params: RFDStarParams):
    """f32[N, K] log-weight table of eq. 6 for altitudes f32[N]: ``gradient * log p_base - alpha
    * log d_j``, the goal forced whenever adjacent, and (``max_climb``) steeper climbs banned."""
    heads, gradient = gradients(graph, altitude)
    logw = (gradient * jnp.log(params.p_base)
            - params.alpha * neighbour_slots(graph, goal_log_distance(graph, task.goal)))
    if config.max_climb is not None:
        logw = jnp.where(gradient < -config.max_climb, -jnp.inf, logw)
    logw = jnp.where(heads == task.goal, FORCED, logw)
    return edge_table(graph, logw.T)


def erosion_change(graph: Graph, altitude, drops: Walk, eroding, erosion, p_base=None):
    """Eqs. 4 and 5: f32[N], the change of every altitude f32[N] when the drops ``eroding``
    (bool[A]) of a walk of ``D = A`` drops erode their paths.

    Each move ``i -> j`` of an eroding drop asks node ``i`` for ``erosion / ((N - 1) D)`` times
    ``max(gradient, 0)`` (eq. 4) or, given ``p_base``, times ``p_base ** gradient`` (the
    exponential form); with ``p_base``, node ``i`` gives at most its altitude minus the lowest
    altitude among the nodes its eroding moves go to (nothing if none is lower). Every node then
    gains the eroded total divided by ``N - 1`` (eq. 5).
    """
    eroded = on_walk(_eroded, drops.log, (altitude, eroding, erosion, p_base), graph,
                      used=eroding)
    return ordered_sum(eroded) / (altitude.shape[0] - 1) - eroded


def _eroded(rows, run, graph: Graph):
    """f32[N] what each node gives to the moves of ``rows`` (``(path [A, W + 1], slots
    [A, W])``) of the eroding drops of ``run``'s ``(altitude f32[N], eroding bool[A], erosion,
    p_base)`` (eq. 4, before eq. 5 shares it out); the same on any width that holds the moves (a move not made
    asks for nothing, and the scatters add in move order:
    :func:`~jaxswarm.swarm.walking.moves.on_walk`)."""
    path, slots = rows
    here, there = path[:, :-1], path[:, 1:]
    altitude, eroding, erosion, p_base = run
    n = altitude.shape[0]
    moved = (slots >= 0) & eroding[:, None]
    here = jnp.where(moved, here, 0)
    there = jnp.where(moved, there, 0)
    distance = move_lengths(graph, here, slots)
    gradient = (altitude[here] - altitude[there]) / jnp.where(moved, distance, 1.0)
    rate = erosion / ((n - 1) * eroding.shape[0])
    if p_base is None:
        asked = jnp.where(moved, rate * jnp.maximum(gradient, 0.0), 0.0)
        return jnp.zeros_like(altitude).at[here].add(asked)
    # p_base ** gradient, capped so that a cliff cannot overflow float32
    shape = exp(jnp.minimum(gradient * jnp.log(p_base), MAX_LOG_EROSION))
    asked = jnp.zeros_like(altitude).at[here].add(jnp.where(moved, rate * shape, 0.0))
    outlet = jnp.full_like(altitude, jnp.inf).at[jnp.where(moved, here, n)].min(
        altitude[there], mode="drop")
    return jnp.minimum(asked, jnp.maximum(altitude - outlet, 0.0))


def erode(graph: Graph, altitude, residual, drops: Walk, eroding, erosion, p_base=None):
    """``(altitude f32[N], residual f32[N])`` after :func:`erosion_change`, added by compensated
    summation (:func:`~jaxswarm.swarm.rfd.river.add_compensated`)."""
    return add_compensated(altitude, residual,
                           erosion_change(graph, altitude, drops, eroding, erosion, p_base))


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


def build_rfd(config: WalkingConfig) -> Swarm:
    """The original River Formation Dynamics (eqs. 1-5), with :class:`RFDParams`."""
    def reshape(graph, task, altitude, residual, table, drops, params):
        altitude, residual = add_compensated(
            altitude, residual, sediment_where_stuck(graph.num_nodes, drops, params.sediment))
        return erode(graph, altitude, residual, drops, drops.arrived, params.erosion)

    return river_swarm("rfd", config, transition=rfd_transition, reshape=reshape,
                       greedy_drops=0, default_params=DEFAULT_RFD, check_params=_check_rfd)


def build_rfd_star(config: RFDStarConfig) -> Swarm:
    """The modified RFD* (eq. 6 with eqs. 4-5), with :class:`RFDStarParams`."""
    def transition(graph, task, altitude, params):
        return rfd_star_transition(config, graph, task, altitude, params)

    def reshape(graph, task, altitude, residual, table, drops, params):
        if config.fill_blind_alleys:
            sediment = jnp.where(blind_alleys(graph, table, drops), params.sediment, 0.0)
        else:
            sediment = sediment_where_stuck(graph.num_nodes, drops, params.sediment)
        altitude, residual = add_compensated(altitude, residual, sediment)
        eroding = drops.arrived if config.erode == "arrived" else jnp.ones_like(drops.arrived)
        exponential = config.erosion_law == "exponential"
        return erode(graph, altitude, residual, drops, eroding, params.erosion,
                     params.p_base if exponential else None)

    return river_swarm("rfd_star", config, transition=transition, reshape=reshape,
                       greedy_drops=config.greedy_drops, default_params=DEFAULT_RFD_STAR,
                       check_params=_check_rfd_star)
