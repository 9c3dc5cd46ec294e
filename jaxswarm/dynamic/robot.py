"""A robot that finds blocked cells and passages as it walks, and re-plans from where it stands.

The Max-Min ACO paper's Algorithm 1, for any planner. The world is a map the robot knows and an
:class:`~jaxswarm.dynamic.events.Event` of hidden blocks (cells that are obstacles, passages with a
thin wall) it does not know. Until it stands on the goal, or ``max_plans`` plans were made:

1. plan from where the robot stands with what it knows;
2. walk the plan: before each move the robot sees the move (the cell ahead, the two cells a
   diagonal squeezes between, the passage); if the move is blocked in the world it stays on the
   node before and adds what it saw to its map (:func:`walk_plan`);
3. re-plan from there, keeping memory: a swarm's memory rule adapts it to the new start and the
   new blocks (:func:`jaxswarm.dynamic.events.change`: Improved Max-Min ACO keeps its pheromone
   and its Bug2-like first ant walks again, RFD keeps its altitudes, ...) and its run continues; D*
   Lite repairs its search. ``memory="wipe"`` starts every plan from fresh memory instead, to
   measure what keeping it buys.

:func:`swarm_robot` is one jitted program (vmap it over keys, maps of one shape, tasks and
hidden blocks); :func:`dstar_robot` runs D* Lite on the host. Both return a :class:`RobotWalk`;
:func:`check_world` names what makes a world unusable, and :func:`hidden_blocks` draws seeded
blocks on the robot's way.
"""
from __future__ import annotations

import functools
import time
from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.dynamic.events import NO_NODE, Event, apply_event, change, make_event
from jaxswarm.exact import astar, replanner
from jaxswarm.swarm.core import Swarm, Task, make_task
from jaxswarm.swarm.executor import retried, run
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import as_node, path_length, step_slots

MEMORY = ("keep", "wipe")
"""What a swarm's memory does at a re-plan: adapted by its rule and kept, or started afresh."""


class Leg(NamedTuple):
    """The robot walking one plan (see :func:`walk_plan`).

    Attributes:
      stop: i32[] index into the plan of the node the robot stands on afterwards.
      reached: bool[] it stands on the plan's last node (the goal).
      length: f32[] the length it walked.
      seen: the :class:`~jaxswarm.dynamic.events.Event` of what it found (``start`` where it
        stands, ``block`` i32[3] cells, ``close`` i32[1, 2] passage; all -1 when the plan was not
        blocked).
    """

    stop: jax.Array
    reached: jax.Array
    length: jax.Array
    seen: Event


class RobotWalk(NamedTuple):
    """What the robot did (a pytree; P = ``max_plans``, L = a plan's length).

    Attributes:
      reached: bool[] it stands on the goal.
      travelled: f32[] the length it walked.
      plans: i32[] the plans it made (the first and every re-plan).
      iterations: i32[] swarm iterations over all plans (0 for D* Lite).
      moves: i32[] agent moves over all plans (the swarm's useful work; 0 for D* Lite).
      trajectory: i32[P * (L - 1) + 1] the nodes it stood on, in order, -1 padded.
      plan_paths: i32[P, L] each plan's path from where the robot stood, -1 padded (all -1 for
        a plan not made, or one that found no path).
      seen: :class:`~jaxswarm.dynamic.events.Event` with a leading axis P: what it found at the
        end of each plan.
      overflowed: bool[] a swarm's walk had no room in its log for its moves
        (:class:`~jaxswarm.swarm.core.Trace`): :func:`swarm_robot` walks again with room for
        every move; set only where a caller maps it (None for D* Lite).
    """

    reached: jax.Array
    travelled: jax.Array
    plans: jax.Array
    iterations: jax.Array
    moves: jax.Array
    trajectory: jax.Array
    plan_paths: jax.Array
    seen: Event
    overflowed: Any = None


def nothing_seen(num_nodes) -> Event:
    """The Event of a plan that met no block: every field -1 (``num_nodes`` i32[])."""
    none = jnp.int32(NO_NODE)
    return Event(start=none, goal=none, block=jnp.full((3,), NO_NODE, jnp.int32),
                 unblock=jnp.full((0,), NO_NODE, jnp.int32),
                 close=jnp.full((1, 2), NO_NODE, jnp.int32),
                 open=jnp.full((0, 2), NO_NODE, jnp.int32), num_nodes=jnp.int32(num_nodes))


@jax.jit
def walk_plan(world: Graph, known: Graph, path) -> Leg:
    """The robot walks ``path`` (i32[L], -1 padded, from where it stands) until the goal or the
    first move that is blocked in ``world`` though valid on ``known``.

    Before each move it sees the move: the cell ahead, the two cells a diagonal squeezes
    between, and the passage. At a blocked move it stays on the node before it, and ``seen``
    holds what it saw there that its map did not: the blocked cells and the closed passage. An
    all -1 ``path`` (no plan) walks nowhere and reaches nothing.
    """
    path = jnp.asarray(path)
    slots = step_slots(known, path)
    is_step = (path[:-1] >= 0) & (path[1:] >= 0)
    here, slot = jnp.maximum(path[:-1], 0), jnp.maximum(slots, 0)
    blocked = is_step & ~world.valid_edges()[here, slot]
    hit = jnp.any(blocked)
    stop = jnp.where(hit, jnp.argmax(blocked), jnp.sum(path >= 0) - 1)
    index = jnp.arange(path.shape[0])
    walked = path_length(known, jnp.where(index <= stop, path, NO_NODE))
    u, k = here[stop], slot[jnp.minimum(stop, slots.shape[0] - 1)]
    cells = jnp.concatenate([path[stop + 1][None], known.corner[u, k]])
    safe = jnp.maximum(cells, 0)
    news = hit & (cells >= 0) & known.free[safe] & ~world.free[safe]
    closed = hit & known.open[u, k] & ~world.open[u, k]
    seen = nothing_seen(known.num_nodes)._replace(
        start=jnp.where(hit, u, NO_NODE), block=jnp.where(news, cells, NO_NODE),
        close=jnp.where(closed, jnp.stack([u, k]), NO_NODE)[None])
    return Leg(stop=stop.astype(jnp.int32), reached=(path[0] >= 0) & ~hit,
               length=jnp.where(stop > 0, walked, 0.0), seen=seen)


def swarm_robot(swarm: Swarm, key, known: Graph, task: Task, hidden: Event, params, *,
                iterations: int = 100, patience: int | None = 30, max_plans: int = 16,
                memory: str = "keep") -> RobotWalk:
    """The robot with a swarm as its planner (jittable and vmappable: one compiled program for a
    batch of keys, maps of one shape, tasks and hidden blocks).

    Args:
      swarm: the planner (static).
      key: PRNG key; the first plan runs from ``swarm.init``, plan ``p`` on ``fold_in(key, p)``.
      known: the map the robot knows.
      task: its start and goal.
      hidden: the blocks the robot does not know (``block`` cells, ``close`` passages; check
        with :func:`check_world` first).
      params: the swarm's Params.
      iterations, patience: each plan is a :func:`jaxswarm.swarm.run` (continuing the memory)
        with these (static).
      max_plans: the step limit: plans at most, the first included (static); a plan that found
        no path counts too (the next one continues its run).
      memory: one of ``MEMORY`` (static).

    Returns:
      A :class:`RobotWalk`.
    """
    if memory not in MEMORY:
        raise ValueError(f"unknown memory {memory!r}; choose one of {', '.join(MEMORY)}")
    if max_plans < 1:
        raise ValueError(f"max_plans must be at least 1, got {max_plans}")
    return retried(
        lambda swarm: _swarm_robot(swarm, key, known, task, hidden, params, iterations,
                                   patience, max_plans, memory),
        swarm, lambda walk: walk.overflowed)


@functools.partial(jax.jit, static_argnums=(0, 6, 7, 8, 9))
def _swarm_robot(swarm, key, known, task, hidden, params, iterations, patience, max_plans,
                 memory):
    world = apply_event(hidden, known, task)[0]
    init_key, plan_key = jax.random.split(key)
    state = swarm.init(init_key, known, task, params)
    length = swarm.best(state).path.shape[0]
    trajectory = jnp.full((max_plans * (length - 1) + 1,), NO_NODE, jnp.int32)
    walk = RobotWalk(reached=jnp.array(False), travelled=jnp.float32(0.0), plans=jnp.int32(0),
                     iterations=jnp.int32(0), moves=jnp.int32(0),
                     trajectory=trajectory.at[0].set(task.start),
                     plan_paths=jnp.full((max_plans, length), NO_NODE, jnp.int32),
                     seen=jax.tree_util.tree_map(lambda x: jnp.stack([x] * max_plans),
                                                 nothing_seen(known.num_nodes)),
                     overflowed=jnp.array(False))

    def going(carry):
        walk = carry[0]
        return ~walk.reached & (walk.plans < max_plans)

    def plan_and_walk(carry):
        walk, state, known, task, position = carry
        p = walk.plans
        state, trace = run(swarm, jax.random.fold_in(plan_key, p), known, task, params,
                           iterations=iterations, patience=patience, state=state)
        plan = swarm.best(state)
        path = jnp.where(plan.found, plan.path, NO_NODE)
        leg = walk_plan(world, known, path)
        steps = jnp.arange(length)
        stood = jnp.where((steps >= 1) & (steps <= leg.stop), position + steps,
                          walk.trajectory.shape[0])
        walk = RobotWalk(
            reached=leg.reached, travelled=walk.travelled + leg.length, plans=p + 1,
            iterations=walk.iterations + trace.iterations,
            moves=walk.moves + jnp.sum(trace.moves),
            trajectory=walk.trajectory.at[stood].set(path, mode="drop"),
            plan_paths=walk.plan_paths.at[p].set(path),
            seen=jax.tree_util.tree_map(lambda all_, one: all_.at[p].set(one), walk.seen,
                                        leg.seen),
            overflowed=walk.overflowed | trace.overflowed)

        def replan_from(state):
            if memory == "keep":
                return change(swarm, state, leg.seen, known, task, params)
            after, new_task = apply_event(leg.seen, known, task)
            fresh = swarm.init(jax.random.fold_in(init_key, p + 1), after, new_task, params)
            return fresh, after, new_task

        state, known, task = jax.lax.cond(leg.seen.start >= 0, replan_from,
                                          lambda state: (state, known, task), state)
        return walk, state, known, task, position + jnp.where(path[0] >= 0, leg.stop, 0)

    walk = jax.lax.while_loop(going, plan_and_walk,
                              (walk, state, known, task, jnp.int32(0)))[0]
    return walk


def dstar_robot(known: Graph, start, goal, hidden: Event, *,
                max_plans: int = 16) -> tuple[RobotWalk, float]:
    """Host-side: the robot with D* Lite as its planner, which repairs its search at every
    re-plan (:func:`jaxswarm.exact.replanner`).

    Args:
      known: the map the robot knows.
      start, goal: (x, y) cells or node indices.
      hidden: the blocks the robot does not know (see :func:`check_world`).
      max_plans: the step limit: plans at most, the first included.

    Returns:
      ``(walk, seconds)``: a :class:`RobotWalk` (host arrays; L = N) and the seconds spent in
      D* Lite's ``solve`` and ``update`` calls.
    """
    task = make_task(known, start, goal)
    world = apply_event(hidden, known, task)[0]
    planner = replanner(known, int(task.start), int(task.goal))
    began = time.perf_counter()
    plan = planner.solve()
    seconds = time.perf_counter() - began
    trajectory, plans, seen = [int(task.start)], [], []
    travelled, reached = 0.0, False
    while not reached and len(plans) < max_plans:
        path = np.asarray(plan.path)
        leg = jax.device_get(walk_plan(world, known, path))
        plans.append(path)
        seen.append(leg.seen)
        trajectory += [int(node) for node in path[1:int(leg.stop) + 1]]
        travelled += float(leg.length)
        reached = bool(leg.reached)
        if int(leg.seen.start) >= 0:
            known, task = apply_event(leg.seen, known, task)
            began = time.perf_counter()
            plan = planner.update(known, start=int(task.start))
            seconds += time.perf_counter() - began
    count, length = len(plans), known.num_nodes
    plan_paths = np.full((max_plans, length), NO_NODE, np.int32)
    plan_paths[:count] = plans
    stood = np.full(max_plans * (length - 1) + 1, NO_NODE, np.int32)
    stood[:len(trajectory)] = trajectory
    blank = jax.device_get(nothing_seen(length))
    seen = jax.tree_util.tree_map(lambda *x: np.stack(x),
                                  *(seen + [blank] * (max_plans - count)))
    return RobotWalk(reached=np.bool_(reached), travelled=np.float32(travelled),
                     plans=np.int32(count), iterations=np.int32(0), moves=np.int32(0),
                     trajectory=stood, plan_paths=plan_paths, seen=seen), seconds


def check_world(known: Graph, start, goal, hidden: Event, *, name: str = "world") -> float:
    """Host-side: raise ValueError naming what makes a robot's world unusable, else return the
    optimum with full knowledge (the shortest path once the hidden blocks are in place).

    Unusable: a start or goal off the map or blocked on the known map; hidden blocks made for
    another map, that open cells or passages, move the start or goal, or block the start or the
    goal; no path from the start to the goal once the hidden blocks are in place.
    """
    task = Task(start=jnp.int32(as_node(known, start, name=f"{name}: start")),
                goal=jnp.int32(as_node(known, goal, name=f"{name}: goal")))
    if int(hidden.num_nodes) != known.num_nodes:
        raise ValueError(f"{name}: the hidden blocks were made for a map of "
                         f"{int(hidden.num_nodes)} nodes; this map has {known.num_nodes}")
    if (np.any(np.asarray(hidden.unblock) >= 0) or np.any(np.asarray(hidden.open) >= 0)
            or int(hidden.start) >= 0 or int(hidden.goal) >= 0):
        raise ValueError(f"{name}: hidden blocks may only block cells and close passages")
    blocked = set(np.asarray(hidden.block).tolist())
    for point, node in (("start", int(task.start)), ("goal", int(task.goal))):
        if node in blocked:
            raise ValueError(f"{name}: a hidden block is on the {point} (node {node})")
    world = apply_event(hidden, known, task)[0]
    full = astar(world, int(task.start), int(task.goal))
    if not bool(full.found):
        raise ValueError(f"{name}: unreachable: no path from the start (node {int(task.start)}) "
                         f"to the goal (node {int(task.goal)}) once the hidden blocks are in place")
    return float(full.cost)


def hidden_blocks(known: Graph, start, goal, *, count: int, seed: int,
                  passages: bool | None = None) -> Event:
    """Host-side: ``count`` seeded hidden blocks that the robot will meet.

    Each block lands on a random move of the shortest path of the world so far (the known map
    with the blocks placed before it), never the first or last node, and only where the goal
    stays reachable: the robot that follows its best plan meets every one of them.

    Args:
      known: the map the robot knows.
      start, goal: (x, y) cells or node indices.
      count: blocks to place.
      seed: NumPy seed of the draws.
      passages: close passages (thin walls) instead of blocking cells; default: on maps
        without obstacle cells (thin-wall path maps).

    Returns:
      An :class:`~jaxswarm.dynamic.events.Event` with ``block`` (cells) or ``close`` (passages)
      of ``count`` entries.

    Raises:
      ValueError: the goal cannot be reached from the start on ``known`` itself, or fewer than
        ``count`` places keep the goal reachable.
    """
    task = make_task(known, start, goal)
    given = start, goal
    start, goal = int(task.start), int(task.goal)
    if passages is None:
        passages = bool(np.all(np.asarray(known.free)))
    rng = np.random.default_rng(seed)
    cells, pairs = [], []
    world = known
    for placed in range(count):
        nodes = astar(world, start, goal).nodes()
        if placed == 0 and not len(nodes):
            raise ValueError(f"the goal {given[1]} cannot be reached from the start {given[0]} "
                             "on the map itself, before any hidden block")
        for t in rng.permutation(np.arange(1, len(nodes) - 1)):
            a, b = int(nodes[t]), int(nodes[t + 1])
            trial = make_event(known, block=cells + [b] * (not passages),
                               close=pairs + [(a, b)] * passages)
            candidate = apply_event(trial, known, task)[0]
            if b != goal and bool(astar(candidate, start, goal).found):
                cells, pairs, world = (cells + [b] * (not passages),
                                       pairs + [(a, b)] * passages, candidate)
                break
        else:
            raise ValueError(f"only {placed} of {count} hidden blocks keep the goal reachable")
    return make_event(known, block=cells, close=pairs)
