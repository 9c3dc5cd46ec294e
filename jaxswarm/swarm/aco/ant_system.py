"""The RFD paper's ant colonies: Ant System (eqs. 7-9) and ACO*.

* ``ant_system``: each ant at ``i`` moves to ``j`` with probability ``tau_ij / sum_l tau_il``
  (eq. 7: ``alpha = 1``, ``beta = 0``; ``eta_ij = 1 / length(i, j)`` with ``beta > 0`` is an
  option). After the walk, evaporation ``tau <- (1 - rho) tau`` (eq. 9) and, for every ant that
  reached the goal, ``Q / f(S)`` on each edge of its path ``S`` of length ``f(S)`` (eq. 8).
* ``aco_star``: Ant System divided by ``d_j ** alpha_goal``, the straight-line distance from
  ``j`` to the goal, "as in the denominator of eq. 6". It divides by ``d_goal = 0``, so the goal
  is taken whenever adjacent.

Arithmetic, not algorithm: after evaporation ``tau`` is kept at least ``TAU_FLOOR``, the
smallest normal float32 (``jnp.finfo(jnp.float32).tiny``, about 1.18e-38). In the paper's
arithmetic eq. 9 never makes ``tau`` zero; in float32 ``(1 - rho) ** t`` leaves the normal range
after about 38 evaporations at ``rho = 0.9`` and becomes 0 (XLA on CPU flushes subnormals to
zero), its log is ``-inf`` and the edge is impassable. With ``rho = 0.9`` on alley20, after 60
iterations of 32 ants (seed 0), all 1,560 edges of ``ant_system`` and 1,480 of ``aco_star``'s
were at 0 without the floor. At the floor an edge keeps a log-weight of about ``-87.3 alpha``:
it is drawn with odds of about 1e-38 against an edge at ``tau = 1``, and where every edge of a
node lies at the floor the ant draws among them evenly instead of being stuck. Every ``tau``
that stays in the normal range is computed bit for bit as without the floor (pheromone kept in
log space would round every update differently); the floor only changes the odds between edges
that both lie below 1.18e-38. The Max-Min colonies floor at ``tau_min`` already.
"""
from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.aco.colony import colony, deposit
from jaxswarm.swarm.core import Swarm, WalkingConfig, default_params
from jaxswarm.swarm.walking import on_walk

TAU_FLOOR = float(jnp.finfo(jnp.float32).tiny)
"""The least ``tau`` after evaporation: the smallest normal float32 (arithmetic, see above)."""


class AntSystemParams(NamedTuple):
    """Numbers of Ant System (f32 scalars, traced).

    Attributes:
      rho: evaporation rate in (0, 1] (eq. 9).
      q: Q, the deposit numerator (eq. 8: a path of length f deposits Q / f per edge).
      alpha: pheromone exponent (1 in eq. 7).
      beta: exponent of eta = 1 / edge length (0 in eq. 7).
      tau0: initial pheromone on every edge.
    """

    rho: jax.Array
    q: jax.Array
    alpha: jax.Array
    beta: jax.Array
    tau0: jax.Array


class ACOStarParams(NamedTuple):
    """Numbers of ACO*: Ant System's and ``alpha_goal``, the exponent of the goal distance."""

    rho: jax.Array
    q: jax.Array
    alpha: jax.Array
    beta: jax.Array
    alpha_goal: jax.Array
    tau0: jax.Array


DEFAULT_ANT_SYSTEM = default_params(AntSystemParams, rho=0.24973664, q=0.18096372, alpha=1.0,
                                    beta=0.0, tau0=1.0)
"""The paper gives eq. 7's exponents (alpha = 1, beta = 0); rho and Q are the setting Ant
System's calibration found (``tunes/ant_system.toml``, ``results/calibration``: on held-out maps
at least as good as rho = 0.1, Q = 1 everywhere, a mean gap of 7.75 against 7.85); tau0 is ours
(a run depends on Q and tau0 only through Q / tau0)."""
DEFAULT_ACO_STAR = default_params(ACOStarParams, rho=0.1, q=1.0, alpha=1.0, beta=0.0,
                                  alpha_goal=50.0, tau0=1.0)
"""The paper gives eq. 7's exponents (alpha = 1, beta = 0); rho, Q, tau0 and alpha_goal are
ours (ACO*'s calibration, ``tunes/aco_star.toml``, found no setting at least as good on every
held-out map)."""


def ant_system_update(graph, pheromone, ants, best_path, best_cost, info, params):
    """Eq. 9 (kept at least ``TAU_FLOOR``), then eq. 8 for every ant that arrived: f32[N, K]
    pheromone."""
    evaporated = jnp.maximum((1.0 - params.rho) * pheromone, TAU_FLOOR)
    return on_walk(_deposit_moves, ants.log,
                    (evaporated, jnp.where(ants.arrived, params.q / ants.length, 0.0)), graph,
                    used=ants.arrived)


def _deposit_moves(rows, run, graph):
    """:func:`~.colony.deposit` of ``run``'s ``(pheromone f32[N, K], amount f32[A])`` on the
    moves of ``rows`` (``(path [A, W + 1], slots [A, W])``); the same on any width that holds
    them (a move not made adds nothing, and the scatter adds in move order:
    :func:`~jaxswarm.swarm.walking.moves.on_walk`)."""
    path, slots = rows
    pheromone, amount = run
    return deposit(graph, pheromone, path[:, :-1], slots, amount)


def build_ant_system(config: WalkingConfig) -> Swarm:
    """Ant System (RFD paper eqs. 7-9), with :class:`AntSystemParams`."""
    return colony("ant_system", config, default_params=DEFAULT_ANT_SYSTEM,
                  update=ant_system_update)


def build_aco_star(config: WalkingConfig) -> Swarm:
    """ACO*: Ant System with the goal-distance heuristic, with :class:`ACOStarParams`."""
    return colony("aco_star", config, default_params=DEFAULT_ACO_STAR,
                  update=ant_system_update, goal_distance=True)
