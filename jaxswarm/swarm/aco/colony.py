"""What every ant colony shares: pheromone on edges, the transition rule, deposits, one iteration.

Pheromone ``tau`` lives on edges (``f32[N, K]``, one value per neighbour slot, kept equal on an
edge and its reverse). Each iteration (a population) all ants walk from the start, never
revisiting a node, choosing the next node ``j`` with probability proportional to

    tau_ij^alpha * eta_ij^beta / d_j^alpha_goal

where ``eta_ij`` is ``1 / length(i, j)`` or, for Improved Max-Min ACO, the desirability of the
move's direction (``(1 + cos angle) / 2 + DIRECTION_FLOOR``; the paper gives no formula), and the
goal-distance term is ACO*'s. Then the colony updates its pheromone from what the ants did.
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.swarm.aco.bug2 import direction_cosine
from jaxswarm.swarm.core import (ParamError, Swarm, Task, best_solution, check_positive, keep_best,
                                 shown)
from jaxswarm.swarm.walking import (FORCED, edge_table, goal_log_distance, heads, step_budget,
                                     walk)
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import step_slots

DIRECTION_FLOOR = 1e-3
"""Added to the direction desirability so that a move straight away from the goal stays possible."""


@dataclasses.dataclass(frozen=True)
class ACOState:
    """Memory of an ant colony run (a pytree).

    Attributes:
      key: PRNG key for the next iteration.
      pheromone: f32[N, K] tau on each edge slot (equal on an edge and its reverse).
      best_path: i32[L] best path found so far, -1 padded.
      best_cost: f32[] its length (inf before any ant arrived).
    """

    key: jax.Array
    pheromone: jax.Array
    best_path: jax.Array
    best_cost: jax.Array


jax.tree_util.register_dataclass(
    ACOState, data_fields=["key", "pheromone", "best_path", "best_cost"], meta_fields=[])


def pheromone_rule(state: ACOState, before: Graph, after: Graph, old: Task, new: Task,
                   params) -> ACOState:
    """The ant colonies' memory rule for a change of the map or the goal: pheromone kept on every
    edge; an edge valid now that was not before (a cell or passage opened) starts at ``tau0``, as
    every edge did at the start."""
    new_edges = after.valid_edges() & ~before.valid_edges()
    return dataclasses.replace(state, pheromone=jnp.where(new_edges, params.tau0,
                                                          state.pheromone))


def transition_rule(graph: Graph, task: Task, pheromone, params, *, direction: bool = False,
                    goal_distance: bool = False, beta=None):
    """f32[N, K] log-weight table ``alpha log tau + beta log eta (- alpha_goal log d_j)``.

    Args:
      graph, task: the map and the goal.
      pheromone: f32[N, K] tau.
      params: the colony's Params (``alpha``, ``beta``; ``alpha_goal`` with ``goal_distance``).
      direction: eta is the direction desirability (Improved Max-Min) instead of 1 / length.
      goal_distance: ACO*: divide by ``d_j ** alpha_goal``, the goal forced whenever adjacent.
      beta: the heuristic exponent, if not ``params.beta`` (the Improved first ant's).
    """
    if direction:
        eta = (1.0 + direction_cosine(graph, task.goal)) / 2.0 + DIRECTION_FLOOR
    else:
        eta = 1.0 / jnp.where(graph.nbr >= 0, graph.cost, 1.0)
    beta = params.beta if beta is None else beta
    logw = params.alpha * jnp.log(pheromone) + beta * jnp.log(eta)
    if goal_distance:
        neighbour = heads(graph)
        logw = logw - params.alpha_goal * goal_log_distance(graph, task.goal)[neighbour]
        logw = jnp.where(neighbour == task.goal, FORCED, logw)
    return edge_table(graph, logw)


def deposit(graph: Graph, pheromone, nodes, slots, amount):
    """f32[N, K] ``pheromone`` with ``amount[a]`` added on every edge (nodes[a, t], slots[a, t])
    (i32[A, T], -1 slots skipped) and on its reverse edge."""
    moved = slots >= 0
    rows = jnp.where(moved, nodes, 0)
    cols = jnp.maximum(slots, 0).astype(jnp.int32)
    value = jnp.where(moved, amount[:, None], 0.0)
    heads = graph.nbr[rows, cols]
    back = graph.rev[rows, cols]
    pheromone = pheromone.at[rows, cols].add(value)
    # One-way edges have no reverse slot: their index n is out of bounds and dropped.
    return pheromone.at[jnp.where(back >= 0, heads, graph.num_nodes),
                        jnp.maximum(back, 0)].add(value, mode="drop")


def reinforce(graph: Graph, pheromone, path, amount):
    """f32[N, K] ``pheromone`` with the scalar ``amount`` added on every edge of one padded path
    (i32[L]), both directions."""
    return deposit(graph, pheromone, path[None, :-1], step_slots(graph, path)[None],
                   amount[None])


Update = Callable[..., jax.Array]
"""``(graph, pheromone f32[N, K], ants Walk, best_path i32[L], best_cost f32[], info StepInfo,
params) -> f32[N, K]``: the pheromone after a population walked."""


def colony(name: str, config, *, default_params, update: Update, init_best=None,
           direction: bool = False, goal_distance: bool = False, ties: bool = False) -> Swarm:
    """An ant colony Swarm: each iteration its ants walk, the best path is kept, then ``update``.

    Args:
      name: registry name.
      config: the colony's Config (``num_agents`` and ``max_steps`` are read).
      default_params: its default Params.
      update: the pheromone update (see :data:`Update`).
      init_best: optional ``(key, graph, task, pheromone, params, length) -> (path i32[length],
        cost f32[])``: a first best path, found before the first population, and found again
        after every change of the map or the task (see :func:`first_path_rule`).
      direction, goal_distance: the transition rule's terms (see :func:`transition_rule`).
      ties: a path as short as the best so far replaces it.
    """
    def init(key, graph: Graph, task: Task, params) -> ACOState:
        length = step_budget(graph, config.max_steps) + 1
        pheromone = jnp.full(graph.nbr.shape, params.tau0, jnp.float32)
        best_path, best_cost = jnp.full((length,), -1, jnp.int32), jnp.float32(jnp.inf)
        if init_best is not None:
            key, first_key = jax.random.split(key)
            best_path, best_cost = init_best(first_key, graph, task, pheromone, params, length)
        return ACOState(key=key, pheromone=pheromone, best_path=best_path, best_cost=best_cost)

    def step(state: ACOState, graph: Graph, task: Task, params):
        key, walk_key = jax.random.split(state.key)
        table = transition_rule(graph, task, state.pheromone, params, direction=direction,
                                goal_distance=goal_distance)
        ants = walk(walk_key, graph, table, task.start, task.goal,
                    num_agents=config.num_agents,
                    max_steps=step_budget(graph, config.max_steps), walker=config.walker)
        best_path, best_cost, info = keep_best(ants, state.best_path, state.best_cost,
                                               ties=ties)
        pheromone = update(graph, state.pheromone, ants, best_path, best_cost, info, params)
        return ACOState(key=key, pheromone=pheromone, best_path=best_path,
                        best_cost=best_cost), info

    return Swarm(name=name, config=config, init=jax.jit(init), step=jax.jit(step),
                 best=best_solution, default_params=default_params, check_params=check_params)


def first_path_rule(init_best):
    """The memory rule of a colony with a first ant (Improved Max-Min ACO): :func:`pheromone_rule`,
    then the first ant walks again from the (new) start on the changed map, guided by the kept
    pheromone, and its path becomes the best (the paper's Algorithm 1, where every re-plan
    begins with the Bug2-like ant)."""
    def rule(state: ACOState, before: Graph, after: Graph, old: Task, new: Task,
             params) -> ACOState:
        state = pheromone_rule(state, before, after, old, new, params)
        key, first_key = jax.random.split(state.key)
        best_path, best_cost = init_best(first_key, after, new, state.pheromone, params,
                                         state.best_path.shape[0])
        return ACOState(key=key, pheromone=state.pheromone, best_path=best_path,
                        best_cost=best_cost)

    return rule


_RULES = {"rho": "positive", "q": "positive", "alpha": "non-negative", "beta": "non-negative",
          "beta_first": "non-negative", "alpha_goal": "non-negative", "tau0": "positive",
          "tau_min": "positive", "tau_max": "positive"}


def check_params(params) -> None:
    """Host-side check of a colony's Params: every value finite and in range.

    Raises:
      ParamError: naming the bad value.
    """
    for name, value in params._asdict().items():
        check_positive(name, value, allow_zero=_RULES[name] == "non-negative")
    if np.any(np.asarray(params.rho) > 1):
        raise ParamError("rho", f"must be at most 1, got {shown(params.rho)}")
    if "tau_max" in params._fields and np.any(np.asarray(params.tau_min)
                                              > np.asarray(params.tau_max)):
        raise ParamError("tau_min", f"({shown(params.tau_min)}) exceeds tau_max "
                                    f"({shown(params.tau_max)})")
