"""The equations of Intelligent Water Drops (Shah-Hosseini's IWD, as the IWD_PG paper uses it),
numbered as that paper numbers them. Soil lives on directed edge slots (``f32[N, K]``); a drop
carries a velocity and the soil it has taken. Moving ``i -> j``:

* choice (eqs. 1-3, :func:`choice_log_weights`): ``p(i, j) ~ f(soil(i, j))^alpha h(j)^beta``,
  ``f(s) = 1 / (eps_s + g(s))``, ``g(s) = s - min(0, the least soil among the choices)``;
* velocity (Shah-Hosseini's, unnumbered): ``vel += a_v / (b_v + c_v soil(i, j)^2)``;
* soil taken (eq. 4, :func:`soil_taken`): ``dsoil = a_s / (b_s + c_s time^2)``, ``time = HUD(i,
  j) / max(eps_v, vel)`` with the velocity after the move;
* local update (eqs. 5, 6): ``soil(i, j) = (1 - rho_n) soil(i, j) - rho_n dsoil``, the drop's
  ``soil += dsoil``; after the walk for the drops that arrived (:func:`arrived_update`) or as
  they walk (:data:`SOIL`), as :mod:`.iwd`'s ``local_updates`` chooses;
* global update (Shah-Hosseini's, :func:`global_update`) of the iteration-best path.

Ours, where the paper leaves them open (``docs/papers.md`` says why): ``HUD(i, j) = hud_scale``
times the edge's length, ``h(j) = 1 / d_j``, ``d_j`` the straight-line distance to the goal.
"""
from __future__ import annotations

import functools

import jax
import jax.numpy as jnp

from jaxswarm.runtime.arithmetic import integer_power, log, ordered_cumsum
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
    # The smallest soil as a chain of elementwise minima over the (few, static) slots rather
    # than a reduction: XLA fuses it into the log-weights' kernel instead of running a kernel of
    # its own at every step of the walk (a minimum is exact in any order).
    choices = jnp.where(admissible, soil_rows, jnp.inf)
    smallest = functools.reduce(jnp.minimum, [choices[:, k] for k in range(choices.shape[1])])
    g = soil_rows - jnp.minimum(smallest, 0.0)[:, None]  # shifted only when negative
    log_f = -log(params.eps_s[:, None] + g)
    return jnp.where(admissible, params.alpha[:, None] * log_f, 0.0)


def velocity_gain(params, soil):
    """The velocity a drop gains crossing an edge with ``soil`` (the unnumbered update)."""
    return params.a_v / (params.b_v + params.c_v * soil ** 2)


def velocity_after(params, velocity, soil):
    """The velocity after crossing an edge with ``soil``."""
    return velocity + velocity_gain(params, soil)


def soil_taken(params, length, velocity):
    """Eq. 4: the soil a drop at ``velocity`` takes from an edge of ``length``, whose HUD is
    ``hud_scale * length``."""
    time = params.hud_scale * length / jnp.maximum(params.eps_v, velocity)
    return params.a_s / (params.b_s + params.c_s * time ** 2)


def initial_state(params) -> jax.Array:
    """f32[2] a drop's state when it starts: the initial velocity, no soil."""
    return jnp.stack([params.initial_velocity, jnp.zeros_like(params.initial_velocity)])


def local_update(params, soil, move: Move, graph: Graph):
    """The velocity update and eqs. 4-6 for one lockstep step: ``(soil f32[R, N, K], states
    f32[l, 2])`` after the moves of ``move`` (``params`` per lane)."""
    slot = jnp.maximum(move.slot, 0)
    # Gathered anew rather than picked from the rows the choice read: XLA then fuses a one-float
    # gather here instead of the choice's whole row gather.
    before = soil[move.run, move.here, slot]
    velocity = velocity_after(params, move.state[:, VELOCITY], before)
    taken = soil_taken(params, move_lengths(graph, move.here, slot), velocity)
    keep = 1.0 - params.rho_n
    groups = move.groups
    lanes = move.run.shape[0]  # no group has more drops
    removed = groups.group_sum(jnp.where(
        move.moving,
        params.rho_n * integer_power(keep, groups.count - 1 - groups.rank, lanes) * taken, 0.0))
    # The first drop of each edge's group writes the edge's soil once: no two writes collide.
    row = jnp.where(groups.first, move.run, soil.shape[0])  # dropped
    soil = soil.at[row, move.here, slot].set(
        before * integer_power(keep, groups.count, lanes) - removed, mode="drop",
        unique_indices=True)
    state = jnp.where(move.moving[:, None],
                      jnp.stack([velocity, move.state[:, CARRIED] + taken], axis=-1), move.state)
    return soil, state


SOIL = StepHook(state_width=2, initial_state=initial_state, log_weights=choice_log_weights,
                update=local_update, native="iwd_soil")
"""The walker hook of drops that change the soil as they walk: soil memory ``f32[N, K]`` per
run, eqs. 1-6."""


SOIL_CHOICE = StepHook(state_width=0, initial_state=lambda params: jnp.zeros((0,), jnp.float32),
                       log_weights=choice_log_weights, native="iwd_soil_choice")
"""The walker hook of drops that read the soil and leave it as it is during the walk (eqs. 1-3;
their updates come after it, :func:`arrived_update`)."""


def walked_soil(graph: Graph, soil, here, slots, params):
    """The velocity update and eq. 4 along whole walks over ``soil`` (f32[N, K], as the drops
    met it): ``(taken f32[A, S], velocity f32[A])``, the soil each move took (0 where ``slots``,
    i8/i16/i32[A, S], is -1) and each drop's velocity at its end, for moves leaving the nodes
    ``here`` (i32[A, S], a path's nodes but its last)."""
    moved = slots >= 0
    here = jnp.where(moved, here, 0)
    slot = jnp.maximum(slots, 0).astype(jnp.int32)
    gained = jnp.where(moved, velocity_gain(params, soil[here, slot]), 0.0)
    velocity = params.initial_velocity + ordered_cumsum(gained, axis=1)
    taken = jnp.where(moved, soil_taken(params, move_lengths(graph, here, slots), velocity), 0.0)
    return taken, velocity[:, -1]


def arrived_update(graph: Graph, soil, here, slots, taken, params):
    """Eq. 5 for the moves of one drop that arrived, applied after the walk: f32[N, K] ``soil``
    after each move's edge lost ``rho_n`` of the soil there and ``rho_n`` times the soil the
    move took. A drop crosses a directed edge at most once, so its moves write distinct edges.

    Args:
      graph: the map.
      soil: f32[N, K] the soil before (after the drops before it in agent order).
      here: i32[S] the node each move leaves (a path's nodes but its last); slots: i8/i16/i32[S]
        the moves' slots, -1 where no move was made (no update).
      taken: f32[S] the soil each move took (:func:`walked_soil`).
      params: the IWD params (scalars).
    """
    row = jnp.where(slots >= 0, here, graph.num_nodes)  # out of range: dropped
    column = jnp.maximum(slots, 0).astype(jnp.int32)
    before = soil[jnp.minimum(row, graph.num_nodes - 1), column]
    updated = (1.0 - params.rho_n) * before - params.rho_n * taken
    return soil.at[row, column].set(updated, mode="drop")


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
