"""The equations of Intelligent Water Drops (Shah-Hosseini's IWD, as the IWD_PG paper uses it).

Soil lives on directed edge slots (``f32[N, K]``). A drop carries a velocity and the soil it has
taken. Moving ``i -> j`` (all drops of a lockstep step read the soil as it was at its start):

* choice (eqs. 1-3): ``p(i, j)`` proportional to ``f(soil(i, j))^alpha * h(j)^beta`` over the
  admissible unvisited ``j``, ``f(s) = 1 / (eps_s + g(s))``, ``g(s) = s`` when the smallest soil
  among the choices is ``>= 0``, else ``s - min``;
* velocity (eq. 4): ``vel += a_v / (b_v + c_v * soil(i, j)^2)``;
* soil taken (eq. 5): ``dsoil = a_s / (b_s + c_s * time^2)``, ``time = HUD(i, j) / max(eps_v,
  vel)`` with the velocity after the move and HUD the edge's length;
* local update (eq. 6): ``soil(i, j) = (1 - rho_n) * soil(i, j) - rho_n * dsoil``; the drop's
  soil ``+= dsoil``. Drops crossing one edge in one step apply their updates one after another
  in the order of the walker's lanes (:mod:`~jaxswarm.swarm.walking.hooks`): with ``c`` of
  them, ``soil = (1 - rho_n)^c soil - rho_n * sum_r (1 - rho_n)^(c - 1 - r) dsoil_r`` over
  their ranks ``r``;
* global update of the iteration-best path (``N_IB`` nodes, its drop's soil ``soil_IB``), on its
  edges: ``soil = (1 + rho_IWD) * soil - rho_IWD * soil_IB / (N_IB - 1)``.

``h(j)``, the goal-distance desirability, is not written out in the paper ("the closest node to
the destination will be selected with more probability"): ours is ``1 / d_j``, ``d_j`` the
straight-line distance from ``j`` to the goal, so a drop next to the goal moves into it (as
ACO*'s ants do).
"""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxswarm.swarm.walking import FORCED, goal_log_distance, heads
from jaxswarm.swarm.walking.hooks import Move, StepHook
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import move_lengths
from jaxswarm.world.paths import step_slots

VELOCITY, CARRIED = 0, 1
"""Columns of a drop's state ``f32[2]``: its velocity and the soil it carries."""


def choice_log_weights(params, soil_rows, admissible) -> jax.Array:
    """f32[l, K] ``alpha * log f(soil(i, j))`` (eqs. 2-3) over each lane's admissible slots
    (0 elsewhere); ``params`` per lane (f32[l] fields)."""
    smallest = jnp.min(jnp.where(admissible, soil_rows, jnp.inf), axis=-1)
    g = soil_rows - jnp.minimum(smallest, 0.0)[:, None]  # shifted only when negative
    log_f = -jnp.log(params.eps_s[:, None] + g)
    return jnp.where(admissible, params.alpha[:, None] * log_f, 0.0)


def velocity_after(params, velocity, soil):
    """Eq. 4: the velocity after crossing an edge with ``soil``."""
    return velocity + params.a_v / (params.b_v + params.c_v * soil ** 2)


def soil_taken(params, length, velocity):
    """Eq. 5: the soil a drop at ``velocity`` takes from an edge of ``length`` (its HUD)."""
    time = length / jnp.maximum(params.eps_v, velocity)
    return params.a_s / (params.b_s + params.c_s * time ** 2)


def initial_state(params) -> jax.Array:
    """f32[2] a drop's state when it starts: the initial velocity, no soil."""
    return jnp.stack([params.initial_velocity, jnp.zeros_like(params.initial_velocity)])


def local_update(params, soil, move: Move, graph: Graph):
    """Eqs. 4-6 for one lockstep step: ``(soil f32[R, N, K], states f32[l, 2])`` after the
    moves of ``move`` (``params`` per lane)."""
    slot = jnp.maximum(move.slot, 0)
    # Gathered anew rather than picked from the rows the choice read: XLA then fuses a one-float
    # gather here instead of the choice's whole row gather.
    before = soil[move.run, move.here, slot]
    velocity = velocity_after(params, move.state[:, VELOCITY], before)
    taken = soil_taken(params, move_lengths(graph, move.here, slot), velocity)
    keep = 1.0 - params.rho_n
    groups = move.groups
    removed = groups.group_sum(jnp.where(
        move.moving, params.rho_n * keep ** (groups.count - 1 - groups.rank) * taken, 0.0))
    # The first drop of each edge's group writes the edge's soil once: no two writes collide.
    row = jnp.where(groups.first, move.run, soil.shape[0])  # dropped
    soil = soil.at[row, move.here, slot].set(before * keep ** groups.count - removed,
                                             mode="drop", unique_indices=True)
    state = jnp.where(move.moving[:, None],
                      jnp.stack([velocity, move.state[:, CARRIED] + taken], axis=-1), move.state)
    return soil, state


SOIL = StepHook(state_width=2, initial_state=initial_state, log_weights=choice_log_weights,
                update=local_update)
"""The walker hook of water drops: soil memory ``f32[N, K]`` per run, eqs. 1-6."""


def goal_log_desirability(graph: Graph, goal) -> jax.Array:
    """f32[N, K] ``log h(j)`` of each slot's neighbour, ``h(j) = 1 / d_j``; a move into the goal
    (``d = 0``, ``h`` infinite) is forced."""
    neighbour = heads(graph)
    return jnp.where(neighbour == goal, FORCED, -goal_log_distance(graph, goal)[neighbour])


def global_update(graph: Graph, soil, path, carried, params):
    """The soil after the global update of one path (i32[L], -1 padded; its drop carried
    ``carried``): ``(1 + rho_IWD) soil - rho_IWD carried / (N_IB - 1)`` on its edges."""
    slots = step_slots(graph, path)
    nodes = jnp.sum(path >= 0)
    on_path = slots >= 0
    rows = jnp.where(on_path, path[:-1], graph.num_nodes)
    columns = jnp.maximum(slots, 0)
    share = carried / jnp.maximum(nodes - 1, 1)
    updated = (1.0 + params.rho_iwd) * soil[jnp.minimum(rows, graph.num_nodes - 1), columns] \
        - params.rho_iwd * share
    return soil.at[rows, columns].set(updated, mode="drop")
