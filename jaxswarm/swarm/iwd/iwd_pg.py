"""IWD_PG (``iwd_pg``): the paper's generalised IWD on a partitioned graph.

Each iteration is an IWD iteration (:mod:`.iwd`: the drops walk, and those that reach the goal
change the soil, or another of IWD's readings) followed by IWD_PG's stages, each a static switch
of :class:`IWDPGConfig` so that experiments can turn it off:

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
:func:`jaxswarm.dynamic.events.change`) the soil is kept as IWD keeps it and the memory is
emptied: its paths may cross the change.

The module holds IWD_PG's config and state, and its stages as functions of a ``_Setup`` (the
config and the local searches' swarm) that :func:`build_iwd_pg` binds: the iteration, the
measuring of the drops' (smoothed) paths, the memory operators, the intersection stage with its
steps on the memory's pairs, and the section local search.
"""
from __future__ import annotations

import dataclasses
import functools
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.core import Swarm, Task, best_solution, keep_best
from jaxswarm.swarm.iwd import fuzzy
from jaxswarm.swarm.iwd.intersect import (closest_inner_pairs, first_intersection,
                                          second_intersection)
from jaxswarm.swarm.iwd.iwd import (STANDARD_IWD, SOIL_LABEL, IWDConfig, IWDParams, build_iwd,
                                    check_iwd, drop_walk, initial_soil, soil_after_best,
                                    soil_per_node, soil_rule)
from jaxswarm.swarm.iwd.local import connect_all, splice_if_shorter
from jaxswarm.swarm.iwd.memory import Memory, empty_memory, last_position, remember
from jaxswarm.swarm.iwd.smooth import smooth_paths
from jaxswarm.swarm.walking import Walk, step_budget
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import path_length


@dataclasses.dataclass(frozen=True)
class IWDPGConfig(IWDConfig):
    """Static sizes and switches of IWD_PG (every operator on by default); the drops' own
    (``num_agents``, ``local_updates``, ``backtrack``) are IWD's (:class:`~.iwd.IWDConfig`), and
    the local searches' drops follow them too.

    Attributes:
      smooth, first_intersection, second_intersection, local_search, fuzzy: the stages (see the
        module docstring).
      memory_size: paths the memory holds (at least 2).
      sections: sections the fuzzy scores split the map into.
      local_agents, local_iterations: the size of a local search's IWD run.
      local_span: moves on each side of a child's joint that its local search covers.
      operator_patience: iterations without progress before the memory operators run.
    """

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


class _Setup(NamedTuple):
    """What the stages of one built IWD_PG share.

    Attributes:
      config: its static sizes and switches.
      local: the ``iwd`` swarm of its local searches (``local_agents`` drops).
    """

    config: IWDPGConfig
    local: Swarm


class _Pairs(NamedTuple):
    """The memory's pairs (0, q), q = 1..P (P = M - 1), that the intersection operators cross.

    Attributes:
      best: i32[L] the best path (the memory's first).
      others: i32[P, L] the other remembered paths.
      present: bool[P] both paths of the pair are there (their costs are finite).
    """

    best: jax.Array
    others: jax.Array
    present: jax.Array


class _Offspring(NamedTuple):
    """The children of the pairs (0, q), q = 1..P, as the intersection operators build them.

    Attributes:
      paths: i32[P, 2, L] each pair's child with the best path's head (column 0) and the child
        with path q's head (column 1).
      costs: f32[P, 2] their lengths, inf where the pair has no child.
      evaluations: i32[] the fitness calls so far.
    """

    paths: jax.Array
    costs: jax.Array
    evaluations: jax.Array


class _Spans(NamedTuple):
    """Sub-paths for local searches to shorten.

    Attributes:
      paths: i32[B, L] the paths.
      begins, ends: i32[B] the positions of each sub-path's first and last node.
    """

    paths: jax.Array
    begins: jax.Array
    ends: jax.Array


def _init(config: IWDPGConfig, key, graph: Graph, task: Task, params: IWDParams) -> IWDPGState:
    """The soil at ``initial_soil`` everywhere (f32[N, K]) and an empty memory of
    ``memory_size`` paths as long as a walk can be (i32[M, L])."""
    length = step_budget(graph, config.max_steps) + 1
    return IWDPGState(key=key, soil=initial_soil(graph, params),
                      memory=empty_memory(config.memory_size, length), stale=jnp.int32(0))


def _step(setup: _Setup, state: IWDPGState, graph: Graph, task: Task, params: IWDParams):
    """One IWD_PG iteration: the drops walk (and change the soil), their paths are smoothed and
    measured, the best of them gets the global soil update, all are offered to the memory, and
    the memory operators run once the best has not improved for ``operator_patience``
    iterations. Returns ``(state, StepInfo)``."""
    config = setup.config
    key, walk_key, operator_key = jax.random.split(state.key, 3)
    drops = drop_walk(walk_key, graph, task, state.soil, params,
                      num_agents=config.num_agents, max_steps=config.max_steps,
                      local_updates=config.local_updates, backtrack=config.backtrack,
                      walker=config.walker)
    paths, lengths = _measured_paths(graph, drops, smooth=config.smooth,
                                     implementation=config.walker.implementation)
    _, _, info = keep_best(drops, state.best_path, state.best_cost, paths=paths,
                           lengths=lengths)
    costs = jnp.where(drops.arrived, lengths, jnp.inf)
    soil = soil_after_best(graph, drops, lambda drop: paths[drop], costs, params)
    memory = remember(state.memory, paths, costs)
    stale = jnp.where(memory.costs[0] < state.best_cost, 0, state.stale + 1)
    run_operators = (stale >= config.operator_patience) & jnp.isfinite(memory.costs[0])
    walked = memory
    memory, extra, overflowed = jax.lax.cond(
        run_operators, lambda m: _operators(setup, operator_key, graph, m, params),
        lambda m: (m, jnp.int32(0), jnp.array(False)), memory)
    stale = jnp.where(memory.costs[0] < state.best_cost, 0, stale)
    # Drops that all took one path have converged only if the operators found nothing.
    converged = info.converged & ~(memory.costs[0] < walked.costs[0])
    return (IWDPGState(key=key, soil=soil, memory=memory, stale=stale),
            info._replace(evaluations=info.evaluations + extra, converged=converged,
                          overflowed=info.overflowed | overflowed))


def _measured_paths(graph: Graph, drops: Walk, *, smooth: bool, implementation: str | None):
    """The drops' paths, with ``smooth`` each one that arrived through the global smooth
    operator (native or on XLA as ``implementation``, the walker's, says), and their lengths:
    ``(paths i32[A, L], lengths f32[A])`` (a drop that did not arrive keeps its walked length).
    IWD_PG's few drops' paths are written out whole: smoothing and the memory take every
    arrived one."""
    paths = (smooth_paths(graph, drops.path, drops.arrived, implementation) if smooth
             else drops.path)
    lengths = jnp.where(drops.arrived, jax.vmap(lambda p: path_length(graph, p))(paths),
                        drops.length)
    return paths, lengths


class _Found(NamedTuple):
    """What a batch of local searches found (:func:`~.local.connect_all`).

    Attributes:
      paths: i32[B, L] each search's best path; costs: f32[B] its length (inf for none);
      calls: i32[B] its fitness calls.
      overflowed: bool[B] a walk of the search had no room in its log.
    """

    paths: jax.Array
    costs: jax.Array
    calls: jax.Array
    overflowed: jax.Array


class _Stage(NamedTuple):
    """One memory operator: the local searches it asks for and what it makes of them, both
    from the memory as the stage finds it.

    Attributes:
      searches: B, the local searches it asks for (static; 0 for none).
      ask: ``(memory) -> ((keys key[B], heres i32[B], theres i32[B]), plan)``: each search's
        key and the nodes it connects, and what ``apply`` needs of the work that chose them
        (arrays, or None).
      apply: ``(memory, plan, _Found) -> (memory, evaluations i32[])`` (plan and found None
        for a stage without searches).
    """

    searches: int
    ask: Callable
    apply: Callable


def _operators(setup: _Setup, key, graph: Graph, memory: Memory, params: IWDParams):
    """The memory operators that are switched on, the intersection operators first, then the
    section local search: ``(memory, evaluations i32[], overflowed bool[])`` (a local search's
    walk had no room in its log), the memory sorted again without duplicates. Each stage's
    local searches run as one batch of the searches it asks for (a batch of small runs of its
    own size: a run's result does not depend on the others of its batch, whose drops read their
    own soil, which changes after their walk, ``local_updates="arrived"``)."""
    config = setup.config
    intersection_key, section_key = jax.random.split(key)
    stages = []
    if config.first_intersection or config.second_intersection:
        stages.append(_intersection_stage(setup, intersection_key, graph, memory))
    if config.local_search:
        stages.append(_section_stage(setup, section_key, graph))
    evaluations, overflowed = jnp.int32(0), jnp.array(False)
    for stage in stages:
        searches, plan = stage.ask(memory) if stage.searches else (None, None)
        found = _search(setup, graph, params, *searches) if searches else None
        memory, count = stage.apply(memory, plan, found)
        evaluations += count
        if found is not None:
            overflowed |= jnp.any(found.overflowed)
    return (remember(empty_memory(*memory.paths.shape), memory.paths, memory.costs),
            evaluations, overflowed)


def _search(setup: _Setup, graph: Graph, params: IWDParams, keys, heres, theres) -> _Found:
    """The local searches (one batch) from ``heres`` to ``theres`` (i32[B]) with ``keys``."""
    return _Found(*connect_all(keys, graph, heres, theres, params, swarm=setup.local,
                               iterations=setup.config.local_iterations))


class _Crossing(NamedTuple):
    """The intersection operators' plan for the memory's pairs.

    Attributes:
      pairs: the pairs (:class:`_Pairs`).
      offspring: the first operator's children (:class:`_Offspring`).
      crossing: bool[P] the present pairs that share an inner node.
      around: the children's sub-paths around their joints (:class:`_Spans`, 2P rows), or None
        without the first operator's local search.
      closest: ``(i, j)`` i32[P] the pairs' closest inner nodes, or None without the second
        operator.
    """

    pairs: _Pairs
    offspring: _Offspring
    crossing: jax.Array
    around: _Spans | None
    closest: tuple | None


def _intersection_stage(setup: _Setup, key, graph: Graph, memory: Memory) -> _Stage:
    """The intersection operators on the pairs (0, q) of ``memory`` (the memory they run on:
    they run first) as a :class:`_Stage`: each parent is replaced by its child where that is
    shorter. Their local searches (around the first operator's joints, and the second's
    connections) run as one batch; a search whose result no pair uses (around the joints of a
    pair that does not cross, or connecting a pair that does) runs from its first node to
    itself, where no drop walks. With both operators a pair needs the first's two searches or
    the second's one, never all three: the batch holds two per pair (:func:`_packed`)."""
    config = setup.config
    num_pairs = config.memory_size - 1
    improve_first = config.first_intersection and config.local_search
    both = improve_first and config.second_intersection
    searches = (2 * num_pairs if improve_first else 0) + (
        num_pairs if config.second_intersection else 0)
    plan = _crossing_plan(setup, graph, memory)

    def ask(memory):
        heres, theres = [], []
        if improve_first:
            rows = jnp.arange(2 * num_pairs)
            here = plan.around.paths[rows, plan.around.begins]
            heres.append(here)
            theres.append(jnp.where(jnp.repeat(plan.crossing, 2),
                                    plan.around.paths[rows, plan.around.ends], here))
        if config.second_intersection:
            here = plan.pairs.best[plan.closest[0]]
            heres.append(here)
            theres.append(jnp.where(plan.pairs.present & ~plan.crossing, plan.pairs.others[
                jnp.arange(num_pairs), plan.closest[1]], here))
        asked = (jax.random.split(key, searches), jnp.concatenate(heres),
                 jnp.concatenate(theres))
        if both:
            packed, _ = _packed(plan.crossing)
            asked = tuple(x[packed] for x in asked)
        return asked, None

    def apply(memory, _, found):
        if both:
            found = jax.tree_util.tree_map(lambda x: x[_packed(plan.crossing)[1]], found)
        offspring = plan.offspring
        if improve_first:
            offspring = _improved_at_joints(
                graph, offspring, plan.around, plan.crossing, found.paths[:2 * num_pairs],
                found.costs[:2 * num_pairs], found.calls[:2 * num_pairs])
        if config.second_intersection:
            offspring = _with_second_children(graph, plan.pairs, plan.crossing, offspring,
                                              plan.closest, found.paths[-num_pairs:],
                                              found.calls[-num_pairs:])
        return _replace_parents(memory, offspring.paths, offspring.costs), offspring.evaluations

    return _Stage(searches=2 * num_pairs if both else searches, ask=ask, apply=apply)


def _packed(crossing: jax.Array):
    """The intersection stage's 3P searches (the first operator's two per pair, rows 2q and
    2q + 1, then the second's, row 2P + q) in a batch of 2P, for ``crossing`` (bool[P]): slot
    2q runs search 2q where pair q crosses, else search 2P + q; slot 2q + 1 runs search 2q + 1.
    Every search whose result a pair uses has a slot (the others run from a node to itself).

    Returns:
      ``(packed, unpacked)``: i32[2P] the search each slot runs, and i32[3P] the slot each
      search's result is read from (a search without a slot reads one whose result the pair
      does not use).
    """
    num_pairs = crossing.shape[0]
    pairs = jnp.arange(num_pairs)
    packed = jnp.stack([jnp.where(crossing, 2 * pairs, 2 * num_pairs + pairs),
                        2 * pairs + 1], axis=1).reshape(-1)
    unpacked = jnp.concatenate([jnp.arange(2 * num_pairs), 2 * pairs])
    return packed, unpacked


def _crossing_plan(setup: _Setup, graph: Graph, memory: Memory) -> _Crossing:
    """The intersection operators' :class:`_Crossing` of the memory's pairs (0, q)."""
    config = setup.config
    pairs = _Pairs(best=memory.paths[0], others=memory.paths[1:],
                   present=jnp.isfinite(memory.costs[0]) & jnp.isfinite(memory.costs[1:]))
    offspring, joints, crossing = _first_children(graph, pairs, on=config.first_intersection)
    around = (_around_joints(offspring.paths, joints, config.local_span)
              if config.first_intersection and config.local_search else None)
    closest = (closest_inner_pairs(graph, pairs.best, pairs.others)
               if config.second_intersection else None)
    return _Crossing(pairs=pairs, offspring=offspring, crossing=crossing, around=around,
                     closest=closest)


def _first_children(graph: Graph, pairs: _Pairs, *, on: bool):
    """The first operator's children of the pairs: ``(offspring, joints i32[P, 2], crossing
    bool[P])``, the children (cost inf unless the operator is ``on`` and the pair is present and
    shares an inner node: it crosses) with two fitness calls per crossing pair, and the position
    in each child where the other parent's part begins. When the operator is off no pair
    crosses, and its children are the pairs themselves (never used: their cost is inf)."""
    num_pairs = pairs.others.shape[0]
    if not on:
        paths = jnp.stack([jnp.broadcast_to(pairs.best, pairs.others.shape), pairs.others], 1)
        return (_Offspring(paths=paths, costs=jnp.full((num_pairs, 2), jnp.inf),
                           evaluations=jnp.int32(0)),
                jnp.zeros((num_pairs, 2), jnp.int32), jnp.zeros((num_pairs,), bool))
    first = jax.vmap(lambda b: first_intersection(graph, pairs.best, b))(pairs.others)
    crossing = jnp.isfinite(first.costs[:, 0]) & pairs.present
    offspring = _Offspring(paths=first.paths,
                           costs=jnp.where(crossing[:, None], first.costs, jnp.inf),
                           evaluations=2 * jnp.sum(crossing, dtype=jnp.int32))
    return offspring, first.joints, crossing


def _around_joints(paths: jax.Array, joints: jax.Array, span: int) -> _Spans:
    """The children ``paths`` (i32[P, 2, L]) in 2P rows, each with its sub-path from ``span``
    moves before to ``span`` moves after its joint (``joints`` i32[P, 2]), within the path."""
    flat = paths.reshape((-1,) + paths.shape[-1:])
    begins = jnp.maximum(joints.reshape(-1) - span, 0)
    ends = jnp.minimum(joints.reshape(-1) + span, jax.vmap(last_position)(flat))
    return _Spans(paths=flat, begins=begins, ends=ends)


def _improved_at_joints(graph: Graph, offspring: _Offspring, around: _Spans, crossing, middles,
                        middle_costs, calls) -> _Offspring:
    """The children with the local searches' paths ``middles`` (i32[2P, L], of lengths
    ``middle_costs`` f32[2P]) spliced in where they are shorter than the sub-paths ``around``
    their joints. The searches' fitness calls (``calls`` i32[2P]) and one per spliced path count
    for the crossing pairs (``crossing`` bool[P]); the others keep no child."""
    improved, improved_costs, spliced = jax.vmap(
        lambda p, b, e, m, c: splice_if_shorter(graph, p, b, e, m, c))(
        around.paths, around.begins, around.ends, middles, middle_costs)
    used = jnp.repeat(crossing, 2)
    evaluations = offspring.evaluations + jnp.sum(jnp.where(used, calls + spliced, 0))
    return _Offspring(paths=improved.reshape(offspring.paths.shape),
                      costs=jnp.where(crossing[:, None],
                                      improved_costs.reshape(offspring.costs.shape), jnp.inf),
                      evaluations=evaluations)


def _with_second_children(graph: Graph, pairs: _Pairs, crossing, offspring: _Offspring,
                          closest, connections, calls) -> _Offspring:
    """The children, where a present pair does not cross (``crossing`` bool[P]), replaced by
    the second operator's across ``connections`` (i32[P, L]: the local searches' paths between
    the pair's closest inner nodes, at positions ``closest``, two i32[P]). Those pairs' searches'
    fitness calls (``calls`` i32[P]) count, and two per pair with children."""
    apart = pairs.present & ~crossing
    i, j = closest
    second = jax.vmap(lambda b, i, j, c: second_intersection(graph, pairs.best, b, i, j, c))(
        pairs.others, i, j, connections)
    evaluations = offspring.evaluations + jnp.sum(jnp.where(apart, calls, 0))
    evaluations += 2 * jnp.sum(apart & jnp.isfinite(second.costs[:, 0]), dtype=jnp.int32)
    return _Offspring(paths=jnp.where(apart[:, None, None], second.paths, offspring.paths),
                      costs=jnp.where(apart[:, None], second.costs, offspring.costs),
                      evaluations=evaluations)


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


def _section_stage(setup: _Setup, key, graph: Graph) -> _Stage:
    """Local search on one section's sub-path of each remembered path, the sections split
    along an axis drawn at random, as a :class:`_Stage`: each path is replaced by its
    improvement where that is shorter (a search's calls count, and one for a spliced path)."""
    config = setup.config
    axis_key, section_key, search_key = jax.random.split(key, 3)

    def ask(memory):
        axis = jax.random.bernoulli(axis_key).astype(jnp.int32)
        present = jnp.isfinite(memory.costs)
        section = _draw_sections(section_key, graph, memory.paths, present, axis, config)
        begins, ends = _section_spans(graph, memory.paths, section, axis, config.sections)
        rows = jnp.arange(config.memory_size)
        return ((jax.random.split(search_key, config.memory_size), memory.paths[rows, begins],
                 memory.paths[rows, ends]), (begins, ends))

    def apply(memory, spans, found):
        paths, costs, spliced = jax.vmap(
            lambda p, b, e, m, c: splice_if_shorter(graph, p, b, e, m, c))(
            memory.paths, *spans, found.paths, found.costs)
        present = jnp.isfinite(memory.costs)
        better = present & (costs < memory.costs)
        evaluations = found.calls + spliced.astype(jnp.int32)
        return (Memory(paths=jnp.where(better[:, None], paths, memory.paths),
                       costs=jnp.where(better, costs, memory.costs)),
                jnp.sum(jnp.where(present, evaluations, 0)))

    return _Stage(searches=config.memory_size, ask=ask, apply=apply)


def _draw_sections(key, graph: Graph, paths, present, axis, config: IWDPGConfig) -> jax.Array:
    """i32[M]: for each path (i32[M, L]; ``present`` bool[M]), the one of ``sections`` sections
    along ``axis`` (i32[], 0 for x, 1 for y) that its local search works in, drawn among those
    it enters with weight ``1 - score`` of the fuzzy section scores (``fuzzy``) or uniformly."""
    lengths = jax.vmap(lambda p: fuzzy.section_lengths(graph, p, axis, config.sections))(paths)
    enters = lengths > 0
    if config.fuzzy:
        weight = 1.0 - fuzzy.section_scores(lengths, present)
    else:
        weight = jnp.ones_like(lengths)
    # A section every path enters with score 1 still gets a small chance.
    weight = jnp.where(enters, jnp.maximum(weight, 1e-3), 0.0)
    keys = jax.random.split(key, config.memory_size)
    return jax.vmap(lambda k, w: jax.random.categorical(k, jnp.log(w)))(keys, weight)


def _section_spans(graph: Graph, paths, section, axis, sections: int):
    """``(begins, ends)`` i32[M]: the first and last positions of each path's (i32[M, L]) nodes
    inside its ``section`` (i32[M]) along ``axis``; (0, 0) for a path with none there."""
    node_section = fuzzy.section_of(graph, graph.xy[jnp.maximum(paths, 0), axis], axis,
                                    sections)
    inside = (node_section == section[:, None]) & (paths >= 0)
    position = jnp.arange(paths.shape[1])
    begins = jnp.min(jnp.where(inside, position, paths.shape[1]), axis=1)
    ends = jnp.maximum(jnp.max(jnp.where(inside, position, -1), axis=1), 0)
    return jnp.minimum(begins, ends), ends


def change_rule(state: IWDPGState, before: Graph, after: Graph, old: Task, new: Task,
           params: IWDParams) -> IWDPGState:
    """IWD_PG's rule for a change of the map or the goal: the soil as IWD keeps it
    (:func:`~.iwd.soil_rule`), the memory emptied (its paths may cross the change)."""
    return dataclasses.replace(soil_rule(state, before, after, old, new, params),
                               memory=empty_memory(*state.memory.paths.shape),
                               stale=jnp.int32(0))


def build_iwd_pg(config: IWDPGConfig) -> Swarm:
    """IWD_PG (see the module docstring), with IWD's :class:`~.iwd.IWDParams` at their standard
    values (:data:`~.iwd.STANDARD_IWD`: IWD_PG's calibration, ``tunes/iwd_pg.toml``, found no
    setting at least as good on every held-out map): its init, step and change rule, the step's
    stages sharing one local-search swarm."""
    local = build_iwd(IWDConfig(num_agents=config.local_agents, max_steps=config.max_steps,
                                local_updates=config.local_updates,
                                backtrack=config.backtrack, walker=config.walker))
    setup = _Setup(config=config, local=local)
    return Swarm(name="iwd_pg", config=config, init=jax.jit(functools.partial(_init, config)),
                 step=jax.jit(functools.partial(_step, setup)), best=best_solution,
                 default_params=STANDARD_IWD, check_params=check_iwd)
