"""A new swarm in one file (docs/extending.md): trail followers. Each iteration ``num_agents``
agents walk from the start, each move to node j drawn with weight ``(1 + trail_j) ** follow /
d_j ** pull`` (d_j its straight-line distance to the goal); then every node's trail evaporates
by ``decay`` and the nodes of the best path so far gain ``deposit``."""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.core import (ParamError, Swarm, WalkingConfig, best_solution, check_positive,
                                 default_params, keep_best)
from jaxswarm.swarm.registry import Entry, register
from jaxswarm.swarm.walking import edge_table, goal_log_distance, heads, step_budget, walk


class TrailParams(NamedTuple):
    """The numbers a sweep varies (f32[] each): ``follow`` and ``pull``, the weights of the trail
    and of the goal; ``deposit``, what the best path lays; ``decay``, the share that evaporates."""

    follow: jax.Array
    pull: jax.Array
    deposit: jax.Array
    decay: jax.Array


DEFAULT_TRAIL = default_params(TrailParams, follow=1.0, pull=4.0, deposit=1.0, decay=0.1)


def check_trail(params: TrailParams) -> None:
    """Host-side: every param finite and at least 0, ``decay`` at most 1 (raises ParamError)."""
    for name, value in params._asdict().items():
        check_positive(name, value, allow_zero=True)
    if np.any(np.asarray(params.decay) > 1):
        raise ParamError("decay", f"must be at most 1, got {params.decay}")


@dataclasses.dataclass(frozen=True)
class TrailState:
    """The memory between iterations: ``trail`` f32[N], the best path i32[L] and its length."""

    key: jax.Array
    trail: jax.Array
    best_path: jax.Array
    best_cost: jax.Array


jax.tree_util.register_dataclass(TrailState, ["key", "trail", "best_path", "best_cost"], [])


def build_trail(config: WalkingConfig) -> Swarm:
    """The trail followers with ``config``'s sizes (its walker options handed on unread)."""
    def init(key, graph, task, params) -> TrailState:
        length = step_budget(graph, config.max_steps) + 1
        return TrailState(key=key, trail=jnp.zeros(graph.num_nodes, jnp.float32),
                          best_path=jnp.full((length,), -1, jnp.int32),
                          best_cost=jnp.float32(jnp.inf))

    def step(state: TrailState, graph, task, params: TrailParams):
        key, walk_key = jax.random.split(state.key)
        node = (params.follow * jnp.log1p(state.trail)
                - params.pull * goal_log_distance(graph, task.goal))
        agents = walk(walk_key, graph, edge_table(graph, node[heads(graph)]), task.start,
                      task.goal, num_agents=config.num_agents,
                      max_steps=step_budget(graph, config.max_steps), walker=config.walker)
        best_path, best_cost, info = keep_best(agents, state.best_path, state.best_cost)
        nodes = jnp.where(best_path >= 0, best_path, graph.num_nodes)  # -1 padding: dropped
        on_best = jnp.zeros(graph.num_nodes, bool).at[nodes].set(True, mode="drop")
        laid = jnp.where(on_best & jnp.isfinite(best_cost), params.deposit, 0.0)
        trail = (1.0 - params.decay) * state.trail + laid
        return TrailState(key=key, trail=trail, best_path=best_path, best_cost=best_cost), info

    return Swarm(name="trail", config=config, init=jax.jit(init), step=jax.jit(step),
                 best=best_solution, default_params=DEFAULT_TRAIL, check_params=check_trail)


register("trail", Entry(WalkingConfig, build_trail, label="trail (example)",
                        source="docs/extending.md: agents on a trail the best path lays",
                        faithful=False))
