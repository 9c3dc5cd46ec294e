"""IWD_PG (``iwd_pg``): the paper's generalised IWD on a partitioned graph.

Each iteration is an IWD iteration (:mod:`.iwd`: the drops walk and change the soil as they go)
followed by IWD_PG's stages, each a static switch of :class:`IWDPGConfig` so that experiments
can turn it off:

1. ``smooth``: every drop's path through the global smooth operator (:mod:`.smooth`) before it
   is measured; the iteration's best (smoothed) path gets the global soil update;
2. the memory of the ``memory_size`` best distinct paths (:mod:`.memory`), offered every
   arrived path;
3. when the best has not improved for ``operator_patience`` iterations ("if there is no progress
   in successive generations then more heuristic operations will be performed"), the memory
   operators, on the pairs (best, other) of the memory:

   * ``first_intersection``: children across a shared node (:mod:`.intersect`), each improved
     by local search within ``local_span`` moves of its joint (with ``local_search``);
   * ``second_intersection``: for a pair without a shared node, children across a local
     search's connection of their closest inner nodes;
   * a child replaces its parent only if shorter;
   * ``local_search``: each remembered path improved by a local search on its sub-path inside
     one section of the map, the section drawn with probability ``1 - score`` of the fuzzy
     section scores (``fuzzy``, :mod:`.fuzzy`) or uniformly among the sections it enters
     (``fuzzy=False``).

Local searches are small IWD runs (``local_agents`` drops, ``local_iterations`` iterations,
fresh soil: :mod:`.local`) of one batch each stage, all through the shared walker. Every
complete path measured counts as a fitness call: the drops that arrived, the local searches'
drops that arrived, each child and each spliced path. After a change of the map (see
:func:`jaxswarm.dynamic.events.change`) the soil is kept as IWD keeps it and the memory is emptied: its
paths may cross the change.
"""
from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp

from jaxswarm.swarm.core import Swarm, SwarmConfig, Task, best_solution, keep_best
from jaxswarm.swarm.iwd import fuzzy
from jaxswarm.swarm.iwd.intersect import (closest_inner_pair, first_intersection,
                                          second_intersection)
from jaxswarm.swarm.iwd.iwd import (DEFAULT_IWD, SOIL_LABEL, IWDConfig, IWDParams, build_iwd,
                                    check_iwd, drop_walk, initial_soil, soil_after_best,
                                    soil_per_node, soil_rule)
from jaxswarm.swarm.iwd.local import connect, improve_between, splice_if_shorter
from jaxswarm.swarm.iwd.memory import Memory, empty_memory, last_position, remember
from jaxswarm.swarm.iwd.smooth import smooth_path
from jaxswarm.swarm.walking import step_budget
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import path_length


@dataclasses.dataclass(frozen=True)
class IWDPGConfig(SwarmConfig):
    """Static sizes and switches of IWD_PG (every operator on by default).

    Attributes:
      num_agents: drops per iteration (50).
      smooth, first_intersection, second_intersection, local_search, fuzzy: the stages (see the
        module docstring).
      memory_size: paths the memory holds (at least 2).
      sections: sections the fuzzy scores split the map into.
      local_agents, local_iterations: the size of a local search's IWD run.
      local_span: moves on each side of a child's joint that its local search covers.
      operator_patience: iterations without progress before the memory operators run.
    """

    num_agents: int = 50
    smooth: bool = True
    first_intersection: bool = True
    second_intersection: bool = True
    local_search: bool = True
    fuzzy: bool = True
    memory_size: int = 5
    sections: int = 4
    local_agents: int = 10
    local_iterations: int = 10
    local_span: int = 8
    operator_patience: int = 1

    def __post_init__(self):
        super().__post_init__()
        for name in ("sections", "local_agents", "local_iterations", "local_span",
                     "operator_patience"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be at least 1, got {getattr(self, name)}")
        if self.memory_size < 2:
            raise ValueError(f"memory_size must be at least 2, got {self.memory_size}")


@dataclasses.dataclass(frozen=True)
class IWDPGState:
    """Memory of an IWD_PG run (a pytree).

    Attributes:
      key: PRNG key for the next iteration.
      soil: f32[N, K] soil on each directed edge slot.
      memory: the best distinct paths (:class:`~.memory.Memory`), best first.
      stale: i32[] iterations since the best last improved.
    """

    key: jax.Array
    soil: jax.Array
    memory: Memory
    stale: jax.Array

    @property
    def best_path(self) -> jax.Array:
        """i32[L] the best path so far (the memory's first)."""
        return self.memory.paths[0]

    @property
    def best_cost(self) -> jax.Array:
        """f32[] its length (inf before any drop arrived)."""
        return self.memory.costs[0]


jax.tree_util.register_dataclass(
    IWDPGState, data_fields=["key", "soil", "memory", "stale"], meta_fields=[])


def _replace_parents(memory: Memory, paths, costs) -> Memory:
    """The memory after children ``paths`` (i32[M - 1, 2, L]) of lengths ``costs`` (f32[M - 1,
    2]) of the pairs (0, q), q = 1..M-1: path q is replaced by its child (column 1) when that is
    shorter, path 0 by the shortest of its children (column 0) when that is shorter."""
    better_q = costs[:, 1] < memory.costs[1:]
    new_paths = memory.paths.at[1:].set(jnp.where(better_q[:, None], paths[:, 1],
                                                  memory.paths[1:]))
    new_costs = memory.costs.at[1:].set(jnp.where(better_q, costs[:, 1], memory.costs[1:]))
    best = jnp.argmin(costs[:, 0])
    better_0 = costs[best, 0] < memory.costs[0]
    new_paths = new_paths.at[0].set(jnp.where(better_0, paths[best, 0], new_paths[0]))
    new_costs = new_costs.at[0].set(jnp.where(better_0, costs[best, 0], new_costs[0]))
    return Memory(paths=new_paths, costs=new_costs)


def build_iwd_pg(config: IWDPGConfig) -> Swarm:
    """IWD_PG (see the module docstring), with IWD's :class:`~.iwd.IWDParams`."""
    local = build_iwd(IWDConfig(num_agents=config.local_agents, max_steps=config.max_steps))
    size = config.memory_size

    def init(key, graph: Graph, task: Task, params: IWDParams) -> IWDPGState:
        length = step_budget(graph, config.max_steps) + 1
        return IWDPGState(key=key,
                          soil=initial_soil(graph, params),
                          memory=empty_memory(size, length), stale=jnp.int32(0))

    def connect_all(key, graph, heres, theres, params):
        """Small IWD runs (one batch through the walker) from ``heres`` to ``theres``
        (i32[B]): ``(paths i32[B, L], costs f32[B], evaluations i32[B])``."""
        keys = jax.random.split(key, heres.shape[0])
        return jax.vmap(lambda k, here, there: connect(
            k, graph, here, there, params, swarm=local,
            iterations=config.local_iterations))(keys, heres, theres)

    def intersections(key, graph, memory: Memory, params):
        """The intersection operators on the pairs (0, q): ``(memory, evaluations)``. Their
        local searches (around the first operator's joints, and the second's connections) run
        as one batch."""
        a, others = memory.paths[0], memory.paths[1:]
        pairs = others.shape[0]
        pair = jnp.isfinite(memory.costs[0]) & jnp.isfinite(memory.costs[1:])
        first = jax.vmap(lambda b: first_intersection(graph, a, b))(others)
        crossing = (jnp.isfinite(first.costs[:, 0]) & pair if config.first_intersection
                    else jnp.zeros((pairs,), bool))
        kids_paths = first.paths
        kids_costs = jnp.where(crossing[:, None], first.costs, jnp.inf)
        evaluations = 2 * jnp.sum(crossing, dtype=jnp.int32)
        heres, theres = [], []
        improve_first = config.first_intersection and config.local_search
        if improve_first:
            flat = kids_paths.reshape((-1,) + a.shape)
            begins = jnp.maximum(first.joints.reshape(-1) - config.local_span, 0)
            ends = jnp.minimum(first.joints.reshape(-1) + config.local_span,
                               jax.vmap(last_position)(flat))
            rows = jnp.arange(flat.shape[0])
            heres.append(flat[rows, begins])
            theres.append(flat[rows, ends])
        if config.second_intersection:
            i, j = jax.vmap(lambda b: closest_inner_pair(graph, a, b))(others)
            heres.append(a[i])
            theres.append(others[jnp.arange(pairs), j])
        if not heres:
            return _replace_parents(memory, kids_paths, kids_costs), evaluations
        paths, costs, calls = connect_all(key, graph, jnp.concatenate(heres),
                                          jnp.concatenate(theres), params)
        if improve_first:
            improved, improved_costs, spliced = jax.vmap(
                lambda p, b, e, m, c: splice_if_shorter(graph, p, b, e, m, c))(
                flat, begins, ends, paths[:2 * pairs], costs[:2 * pairs])
            used = jnp.repeat(crossing, 2)
            evaluations += jnp.sum(jnp.where(used, calls[:2 * pairs] + spliced, 0))
            kids_paths = improved.reshape(kids_paths.shape)
            kids_costs = jnp.where(crossing[:, None], improved_costs.reshape(kids_costs.shape),
                                   jnp.inf)
        if config.second_intersection:
            apart = pair & ~crossing
            second = jax.vmap(lambda b, i, j, c: second_intersection(graph, a, b, i, j, c))(
                others, i, j, paths[-pairs:])
            evaluations += jnp.sum(jnp.where(apart, calls[-pairs:], 0))
            evaluations += 2 * jnp.sum(apart & jnp.isfinite(second.costs[:, 0]), dtype=jnp.int32)
            kids_paths = jnp.where(apart[:, None, None], second.paths, kids_paths)
            kids_costs = jnp.where(apart[:, None], second.costs, kids_costs)
        return _replace_parents(memory, kids_paths, kids_costs), evaluations

    def section_search(key, graph, memory: Memory, params):
        """Local search on one section's sub-path of each remembered path: ``(memory,
        evaluations)``."""
        axis_key, section_key, search_key = jax.random.split(key, 3)
        axis = jax.random.bernoulli(axis_key).astype(jnp.int32)
        lengths = jax.vmap(lambda p: fuzzy.section_lengths(graph, p, axis, config.sections))(
            memory.paths)
        present = jnp.isfinite(memory.costs)
        enters = lengths > 0
        if config.fuzzy:
            weight = 1.0 - fuzzy.section_scores(lengths, present)
        else:
            weight = jnp.ones_like(lengths)
        # A section every path enters with score 1 still gets a small chance.
        weight = jnp.where(enters, jnp.maximum(weight, 1e-3), 0.0)
        keys = jax.random.split(section_key, size)
        section = jax.vmap(lambda k, w: jax.random.categorical(k, jnp.log(w)))(keys, weight)
        node_section = fuzzy.section_of(graph, graph.xy[jnp.maximum(memory.paths, 0), axis],
                                        axis, config.sections)
        inside = (node_section == section[:, None]) & (memory.paths >= 0)
        position = jnp.arange(memory.paths.shape[1])
        begins = jnp.min(jnp.where(inside, position, memory.paths.shape[1]), axis=1)
        ends = jnp.max(jnp.where(inside, position, -1), axis=1)
        begins = jnp.minimum(begins, jnp.maximum(ends, 0))
        paths, costs, evals = jax.vmap(lambda k, p, b, e: improve_between(
            k, graph, p, b, e, params, swarm=local, iterations=config.local_iterations))(
            jax.random.split(search_key, size), memory.paths, begins, jnp.maximum(ends, 0))
        better = present & (costs < memory.costs)
        return (Memory(paths=jnp.where(better[:, None], paths, memory.paths),
                       costs=jnp.where(better, costs, memory.costs)),
                jnp.sum(jnp.where(present, evals, 0)))

    def operators(key, graph, memory: Memory, params):
        intersection_key, section_key = jax.random.split(key)
        evaluations = jnp.int32(0)
        if config.first_intersection or config.second_intersection:
            memory, count = intersections(intersection_key, graph, memory, params)
            evaluations += count
        if config.local_search:
            memory, count = section_search(section_key, graph, memory, params)
            evaluations += count
        # Sorted again, duplicates dropped.
        return remember(empty_memory(*memory.paths.shape), memory.paths, memory.costs), \
            evaluations

    def step(state: IWDPGState, graph: Graph, task: Task, params: IWDParams):
        key, walk_key, operator_key = jax.random.split(state.key, 3)
        drops = drop_walk(walk_key, graph, task, state.soil, params,
                          num_agents=config.num_agents, max_steps=config.max_steps)
        paths = drops.path
        if config.smooth:
            # Every drop's path is smoothed (under vmap a cond would run both sides anyway); a
            # drop that did not arrive keeps its path.
            smoothed = jax.vmap(lambda p: smooth_path(graph, p))(paths)
            paths = jnp.where(drops.arrived[:, None], smoothed, paths)
        lengths = jnp.where(drops.arrived, jax.vmap(lambda p: path_length(graph, p))(paths),
                            drops.length)
        _, _, info = keep_best(drops._replace(path=paths, length=lengths), state.best_path,
                               state.best_cost)
        costs = jnp.where(drops.arrived, lengths, jnp.inf)
        soil = soil_after_best(graph, drops, paths, costs, params)
        memory = remember(state.memory, paths, costs)
        stale = jnp.where(memory.costs[0] < state.best_cost, 0, state.stale + 1)
        run_operators = (stale >= config.operator_patience) & jnp.isfinite(memory.costs[0])
        walked = memory
        memory, extra = jax.lax.cond(
            run_operators, lambda m: operators(operator_key, graph, m, params),
            lambda m: (m, jnp.int32(0)), memory)
        stale = jnp.where(memory.costs[0] < state.best_cost, 0, stale)
        # Drops that all took one path have converged only if the operators found nothing.
        converged = info.converged & ~(memory.costs[0] < walked.costs[0])
        return (IWDPGState(key=key, soil=soil, memory=memory, stale=stale),
                info._replace(evaluations=info.evaluations + extra, converged=converged))

    def adapt(state, before, after, old, new, params):
        return dataclasses.replace(soil_rule(state, before, after, old, new, params),
                                   memory=empty_memory(*state.memory.paths.shape),
                                   stale=jnp.int32(0))

    return Swarm(name="iwd_pg", config=config, init=jax.jit(init), step=jax.jit(step),
                 best=best_solution, default_params=DEFAULT_IWD, check_params=check_iwd,
                 memory=soil_per_node, memory_label=SOIL_LABEL, adapt=adapt)
