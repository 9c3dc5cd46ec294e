"""The walk loop shared by drops and ants: agents queued over a fixed set of busy lanes.

``A`` agents start at one node. The algorithm hands the walker one log-weight per edge,
``f32[N, K]`` (its transition rule evaluated once per walk: pheromone, altitude gradients and
heuristics do not change while the agents walk). At each move an agent gathers its node's row,
keeps the admissible slots (an edge with a finite log-weight to a node it has not visited in this
walk; on grids and path maps the neighbours are the node plus fixed slot offsets, so only the
log-weights are gathered), and draws one slot through the masked sampler (:mod:`.sampler`; a
greedy agent takes its most likely slot instead, ties drawn at random). An agent stops when it
reaches the goal, when it has no admissible neighbour ("stuck"), or when its step budget runs out.
That step of every lane is :func:`.lanes.step`; this module holds the queue that hands agents to
lanes, the loop over blocks of steps, the results it writes and the batching rule.

The loop steps a fixed number of lanes (:func:`lanes_for`) ``STEPS_PER_REFILL`` moves at a time,
refills the lanes whose agent stopped from a queue, and compacts the last few walkers onto fewer
lanes; random streams belong to agents, not lanes (:func:`.streams.uniforms`), so neither the
lanes nor batching change any walk. :func:`walk`'s ``vmap`` rule puts every run's agents in one
queue; a per-step hook (:mod:`.hooks`) carries memory that changes while the agents walk; moves
go to a journal (:mod:`.journal`) and then to each run's :class:`~.log.MoveLog`.
``docs/walker.md`` tells how each of these works and why.
"""
from __future__ import annotations

import functools
from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
from jax.custom_batching import custom_vmap

from jaxswarm.runtime.batching import fold_runs, unfold_runs
from jaxswarm.swarm.walking import bits, native
from jaxswarm.swarm.walking.hooks import UNCLAIMED, StepHook
from jaxswarm.swarm.walking.lanes import (Lanes, WalkInputs, initial_state, lane_status,
                                          start_visited, step)
from jaxswarm.swarm.walking.journal import Journal, append, empty_journal, ordered_logs
from jaxswarm.swarm.walking.options import WalkerOptions
from jaxswarm.swarm.walking.log import (BLOCK, MoveLog, agent_path,
                                        known_overflowed, paths, room_blocks, walked_lengths)
from jaxswarm.swarm.walking.tables import step_budget
from jaxswarm.world.graph import NO_NODE, Graph
from jaxswarm.world.lattice import lattice_length, slot_offsets

LANES = 1024
"""The most lanes one walk loop steps: more no longer speed a step up (their visited sets leave the
caches; measured: ``docs/performance.md``)."""

AGENTS_PER_LANE = 8
"""A loop of ``count`` agents steps about ``count // AGENTS_PER_LANE`` lanes (at least
``FEWEST_LANES``, at most ``LANES``): each lane walks several agents one after another, so the
lanes stay busy while the queue lasts and only the last agents' lanes wait for the slowest. A
lane-step's fixed cost is shared by its lanes, so fewer, busier lanes make more moves a second
(measured: ``docs/performance.md``)."""

FEWEST_LANES = 128
"""The fewest lanes a loop of more agents steps (see ``AGENTS_PER_LANE``): below it a step's
fixed cost is no longer shared out."""

STEPS_PER_REFILL = BLOCK
"""Moves a lane makes between two refills (an agent that stops within them idles until then)."""

REFILL_SHARE = 2
"""At most ``lanes // REFILL_SHARE`` lanes take a new agent per refill: copying a stopped agent's
visited set out costs a row of words, so the copy is sized for the usual number of stops, and
any more stopped lanes wait for the next refill."""

COMPACT_SHARE = 4
"""When the queue is empty and at most ``lanes // COMPACT_SHARE`` agents still walk, the walk
goes on with only them, in a batch of that many lanes; again and again as agents stop (see
``SMALLEST_COMPACTION``), so a walk's last agents do not keep every lane stepping."""

SMALLEST_COMPACTION = 16
"""The lanes a walk narrows to, after its first narrowing, are at least this many: every
narrowing is one more loop to compile, and on maze100 narrowing on down to 2 lanes made the
walks above no faster (a step of a few lanes costs its kernels' fixed overhead)."""


class Walk(NamedTuple):
    """What a walk produced (a pytree).

    Attributes:
      log: every agent's moves (:class:`~.log.MoveLog`): read them through :func:`.log.paths`,
        :func:`.log.columns`, :meth:`agent_path` or
        :func:`~jaxswarm.swarm.walking.moves.on_walk`; :attr:`path` and :attr:`slots` write
        them out padded to the step budget.
      length: f32[A] walked length (sum of edge costs). On grids and path maps the moves are
        counted by kind (:func:`jaxswarm.world.lattice.lattice_length`), so the same moves in any
        order give the same float; on general graphs the edge costs are summed.
      arrived: bool[A] reached the goal.
      stuck: bool[A] stopped with no admissible neighbour (before arriving).
      position: i32[A] the node each agent stopped at.
      visited: u32[A, ceil(N / 32)] the nodes on each agent's path as a packed bit set (bit
        ``n % 32`` of word ``n // 32`` is node ``n``); see :func:`visited_nodes`.
      moves: i32[A] moves each agent made.
      lane_steps: i32[] lane-steps the loop executed (lanes times steps, summed over the loop's
        phases); ``sum(moves) / lane_steps`` is the share of the machine's work that moved an
        agent. A batch of walks shares one loop, so each gets the batch's total.
      state: f32[A, E] each agent's own state when it stopped (with a hook; else None).
      memory: the hook's memory after the walk (with a hook; else None).
    """

    log: MoveLog
    length: jax.Array
    arrived: jax.Array
    stuck: jax.Array
    position: jax.Array
    visited: jax.Array
    moves: jax.Array
    lane_steps: jax.Array
    state: Any = None
    memory: Any = None

    @property
    def path(self) -> jax.Array:
        """i32[..., A, L] nodes visited, starting with the start node, -1 padded
        (``L = max_steps + 1``): the log's moves written out at the full budget, for small
        walks and tests (a large walk's rules read the log, cut to the moves they need)."""
        return _padded(self.log)[0]

    @property
    def slots(self) -> jax.Array:
        """i8[..., A, L - 1] (i16 on graphs of more than 127 slots) neighbour slot of each move
        (``path[a, t + 1] = nbr[path[a, t], slot]``), -1 after the agent stopped; like
        :attr:`path`, written out from the log."""
        return _padded(self.log)[1]

    def agent_path(self, agent: jax.Array) -> jax.Array:
        """i32[max_steps + 1] agent ``agent``'s (i32[]) path, -1 padded."""
        return agent_path(self.log, agent, self.log.max_steps + 1)


def _padded(log: MoveLog):
    """The log's paths and slots, written out at the full budget (:func:`_written_out`).

    Raises:
      ValueError: the log (concrete, not traced) overflowed: its rows would be wrong.
    """
    if known_overflowed(log.overflowed):
        raise ValueError("the walk's log had no room for all its moves: walk again with a "
                         "larger log (jaxswarm.swarm.walking.EVERY_MOVE has room for "
                         "every move)")
    return _written_out(log)


@jax.jit
def _written_out(log: MoveLog):
    """:func:`.log.paths` at the full budget, over any leading batch axes of ``log``."""
    read = paths
    for _ in range(log.moves.ndim - 1):
        read = jax.vmap(read)
    return read(log)


def visited_nodes(walk: Walk, num_nodes: int, which: jax.Array | None = None) -> jax.Array:
    """bool[N]: the nodes on the paths of the agents selected by ``which`` (bool[A]; all
    agents when None), read from the walk's packed visited sets (cheaper than scattering the
    padded paths)."""
    return bits.union(walk.visited, num_nodes, which)


@functools.partial(jax.jit, static_argnames=("num_agents", "max_steps", "greedy_agents", "hook",
                                             "walker"))
def walk(key: jax.Array, graph: Graph, log_weights: jax.Array, start, goal, *, num_agents: int,
         max_steps: int, greedy_agents: int = 0, hook: StepHook | None = None, memory=None,
         hook_params=None, walker: WalkerOptions = WalkerOptions()) -> Walk:
    """Walk ``num_agents`` agents from ``start`` towards ``goal``.

    Args:
      key: PRNG key; the same key gives the same walk (see :func:`.streams.uniforms`).
      graph: the map.
      log_weights: f32[N, K] unnormalised log-probability of each edge (see
        :func:`~jaxswarm.swarm.walking.tables.edge_table`); ``-inf`` where the edge may not be
        taken (no neighbour, not valid on the current map, or excluded by the algorithm),
        ``FORCED`` where it must be.
      start, goal: i32[] node indices (may be traced).
      num_agents: A (static).
      max_steps: the step budget (static); paths hold ``max_steps + 1`` nodes.
      greedy_agents: how many agents (the first ones; static) always take their most likely
        admissible move, ties drawn at random, instead of sampling.
      hook: memory that changes at every step (static; see :mod:`.hooks`), or None.
      memory: the hook's memory before the walk (a pytree).
      hook_params: the hook's numbers (a pytree of traced scalars).
      walker: the room of the walk's log and the implementation that walks (static,
        :class:`~.options.WalkerOptions`); a walk that made more moves than its log has room
        for says it overflowed (:mod:`.log`).

    Returns:
      A :class:`Walk`. One compiled program per set of static options and shapes, called alone
      or inside ``jit``; under ``vmap`` the walks of the batch share one queue (module
      docstring).
    """
    seed = jax.random.bits(key, (1, 2), jnp.uint32)
    memory, hook_params = (jax.tree_util.tree_map(lambda x: jnp.asarray(x)[None], tree)
                           for tree in (memory, hook_params))  # one run
    walks = _batched_walk(num_agents, max_steps, greedy_agents, hook, walker.log_moves,
                          step_budget(graph, None), native.implementation(hook, walker.implementation))(
        seed, graph, log_weights[None], jnp.asarray(start, jnp.int32)[None],
        jnp.asarray(goal, jnp.int32)[None], memory, hook_params)
    return jax.tree_util.tree_map(lambda x: x[0], walks)


@functools.lru_cache(maxsize=None)
def _batched_walk(num_agents: int, max_steps: int, greedy_agents: int, hook: StepHook | None,
                  log_moves: int | None, default_budget: int, implementation: str = "lanes"):
    """``(seed u32[R, 2], graph, log_weights f32[R, N, K], start i32[R], goal i32[R], memory,
    hook_params) -> Walk`` with a leading run axis R on everything but the graph (the table's
    may be 1), whose ``vmap`` folds the mapped axis into R; the room of each run's log as
    :func:`~.log.room_blocks` gives it for ``log_moves`` and the map's ``default_budget``;
    walked by the lanes (:func:`_walk_runs`) or, ``implementation="native"``, by the native
    kernel (:func:`.native.walk_runs`)."""
    shape = dict(num_agents=num_agents, max_steps=max_steps, greedy_agents=greedy_agents,
                 hook=hook, log_moves=log_moves, default_budget=default_budget)
    walk_impl = _native_walk_runs if implementation == "native" else _walk_runs

    @custom_vmap
    def walk_runs(seed, graph, log_weights, start, goal, memory, hook_params):
        return walk_impl(seed, graph, log_weights, start, goal, memory, hook_params, **shape)

    @walk_runs.def_vmap
    def batch_rule(axis_size, in_batched, seed, graph, log_weights, start, goal, memory,
                  hook_params):
        seed_b, graph_b, weights_b, start_b, goal_b, memory_b, params_b = in_batched
        if any(jax.tree_util.tree_leaves(graph_b)):
            # Walks on different maps cannot share a table of offsets: one loop per map.
            plain = functools.partial(walk_impl, **shape)
            axes = tuple(jax.tree_util.tree_map(lambda b: 0 if b else None, b)
                         for b in in_batched)
            out = jax.vmap(plain, in_axes=axes)(seed, graph, log_weights, start, goal, memory,
                                                hook_params)
            return out, jax.tree_util.tree_map(lambda _: True, out)

        fold = functools.partial(fold_runs, axis_size=axis_size)
        seed, start, goal = fold(seed, seed_b), fold(start, start_b), fold(goal, goal_b)
        # One table for the whole batch stays one table (the walk reads it for every run).
        if weights_b or log_weights.shape[0] > 1:
            log_weights = fold(log_weights, weights_b)
        memory = jax.tree_util.tree_map(fold, memory, memory_b)
        # Numbers shared by the batch stay one run's (the lanes then need no gather of them);
        # numbers an inner vmap gave each of its runs are shared by this one's members alike.
        hook_params = jax.tree_util.tree_map(
            lambda p, b: fold(p, b) if b or p.shape[0] > 1 else p, hook_params, params_b)
        out = jax.tree_util.tree_map(  # sizes spelled out: a hook's state may be empty
            lambda x: unfold_runs(x, axis_size),
            walk_runs(seed, graph, log_weights, start, goal, memory, hook_params))
        return out, jax.tree_util.tree_map(lambda _: True, out)

    return walk_runs


class Results(NamedTuple):
    """What each agent of a loop did (leading axis: its agents), written when it stops; the
    fields are the :class:`Walk`'s."""

    position: jax.Array
    visited: jax.Array
    moves: jax.Array
    diagonal: jax.Array
    arrived: jax.Array
    stuck: jax.Array
    state: Any = None


class Queue(NamedTuple):
    """The agents of one loop (its results' rows: agent ``f`` is agent ``f % num_agents`` of
    run ``f // num_agents``) and the order in which they take a lane.

    Attributes:
      count: the number of rows (static).
      run_of_row: i32[count] each row's run.
      order: i32[count] the rows that walk (their run does not start at its goal) first, in
        row order, then the others.
      live: i32[] how many rows walk: the queue's entries ``0 .. live - 1``.
    """

    count: int
    run_of_row: jax.Array
    order: jax.Array
    live: jax.Array


class Loop(NamedTuple):
    """The loop's carry: the lanes, the results, the journal of moves, the queue's next entry,
    the lane-steps, and with a hook its memory and, when the hook writes, the claims buffer
    that groups each step's moves (:func:`~.hooks.edge_groups`; None without)."""

    lanes: Lanes
    results: Results
    journal: Journal
    next_queued: jax.Array
    lane_steps: jax.Array
    memory: Any = None
    claims: Any = None


def _walk_runs(seed, graph: Graph, log_weights, start, goal, memory, hook_params, *,
               num_agents: int, max_steps: int, greedy_agents: int,
               hook: StepHook | None, log_moves: int | None, default_budget: int) -> Walk:
    """The walks of R runs on one map through one queue (leading axis R on every input; the
    table's and the hook params' may be 1, shared by every run), each run's log with the room
    :func:`~.log.room_blocks` gives it."""
    runs = start.shape[0]
    blocks = room_blocks(num_agents, max_steps, log_moves, default_budget)
    inputs = WalkInputs(
        graph=graph, log_weights=log_weights, seed=seed, start=start, goal=goal, hook=hook,
        hook_params=hook_params, num_agents=num_agents, max_steps=max_steps,
        greedy_agents=greedy_agents,
        slot_dtype=jnp.int8 if graph.max_degree <= 127 else jnp.int16,
        offsets=jnp.asarray(slot_offsets(graph)) if graph.is_grid else None)
    results, journal, lane_steps, memory = _walk_agents(inputs, runs * num_agents, blocks,
                                                        memory)
    logs = ordered_logs(journal, results.moves, inputs.start, num_agents, blocks, max_steps)
    if graph.is_grid:
        length = lattice_length(results.moves, results.diagonal)
    else:  # general graphs (small): the edge costs summed along the rows
        length = walked_lengths(graph, logs).reshape(-1)
    per_agent = dict(length=length, arrived=results.arrived, stuck=results.stuck,
                     position=results.position, visited=results.visited, moves=results.moves,
                     state=results.state)
    return Walk(**{name: None if x is None else x.reshape((runs, num_agents) + x.shape[1:])
                   for name, x in per_agent.items()},
                log=logs, lane_steps=jnp.full((runs,), lane_steps, jnp.int32), memory=memory)


def _native_walk_runs(seed, graph: Graph, log_weights, start, goal, memory, hook_params,
                      **shape) -> Walk:
    """:func:`_walk_runs` as one native kernel call (:func:`.native.walk_runs`), which replays
    this module's schedule of lanes for the outputs that depend on it."""
    count = start.shape[0] * shape["num_agents"]
    writes = shape["hook"] is not None and shape["hook"].writes
    schedule = (count if writes else lanes_for(count), REFILL_SHARE, COMPACT_SHARE,
                SMALLEST_COMPACTION)
    return Walk(**native.walk_runs(seed, graph, log_weights, start, goal, memory, hook_params,
                                   schedule=schedule, **shape))


def _walk_agents(inputs: WalkInputs, count: int, blocks: int, memory):
    """Walk the ``count`` agents of a batch of runs in one loop: the agents of runs with
    somewhere to go are queued, the others keep their initial results. The lanes take queued
    agents until the queue is empty and at most ``lanes // COMPACT_SHARE`` of them walk; those
    then go on in that many lanes, narrowed again as they stop (``SMALLEST_COMPACTION``).

    Args:
      inputs: the walk's inputs (R runs).
      count: R times the agents per run (static).
      blocks: each run's log's blocks (static): the journal has room for R times as many.
      memory: the hook's memory before the walk, leading axis R (None without a hook).

    Returns:
      ``(Results, Journal, lane_steps i32[], memory)``, the results' rows in agent order (agent
      ``f`` is agent ``f % num_agents`` of run ``f // num_agents``), the blocks of moves, and
      the memory after the walk.
    """
    queue = _queue(inputs, count)
    initial = _initial_results(inputs, queue)
    writes = inputs.hook is not None and inputs.hook.writes
    # Agents that write a memory they all read walk together (docs/walker.md).
    num_lanes = count if writes else lanes_for(count)
    claims = None if not writes else jnp.full(
        (inputs.start.shape[0] * inputs.graph.num_nodes,), UNCLAIMED, jnp.int32)
    journal = empty_journal(inputs.start.shape[0] * blocks, count, inputs.slot_dtype)
    loop = Loop(lanes=_fresh_lanes(inputs, queue, jnp.arange(num_lanes)), results=initial,
                journal=journal, next_queued=jnp.minimum(jnp.int32(num_lanes), queue.live),
                lane_steps=jnp.int32(0), memory=memory, claims=claims)
    few = num_lanes // COMPACT_SHARE
    loop = _flush(inputs, queue, jax.lax.while_loop(
        functools.partial(_keeps_queueing, queue, few),
        lambda loop: _refill(inputs, queue, _block(inputs, loop)), loop))
    while few:  # one narrower loop each, statically unrolled
        fewer = few // COMPACT_SHARE
        fewer = fewer if fewer >= SMALLEST_COMPACTION else 0
        loop = _flush(inputs, queue, jax.lax.while_loop(
            lambda loop, fewer=fewer: _walking_count(loop.lanes) > fewer,
            functools.partial(_block, inputs), _compact(queue, loop, few)))
        few = fewer
    return loop.results, loop.journal, loop.lane_steps, loop.memory


def lanes_for(count: int) -> int:
    """The lanes a loop of ``count`` agents steps (static): ``count // AGENTS_PER_LANE``, at
    least ``FEWEST_LANES`` and at most ``LANES``, never more than ``count``."""
    return min(count, LANES, max(FEWEST_LANES, count // AGENTS_PER_LANE))


def _queue(inputs: WalkInputs, count: int) -> Queue:
    """The loop's ``count`` rows (static) in the order they take a lane: the agents of runs
    whose start is not their goal (``inputs.start``, ``inputs.goal`` i32[R]) first."""
    rows = jnp.arange(count, dtype=jnp.int32)
    run_of_row = rows // inputs.num_agents
    live_row = inputs.start[run_of_row] != inputs.goal[run_of_row]
    return Queue(count=count, run_of_row=run_of_row,
                 order=jnp.argsort(~live_row, stable=True).astype(jnp.int32),
                 live=jnp.sum(live_row))


def _initial_results(inputs: WalkInputs, queue: Queue) -> Results:
    """Every row's results before it walks: at its run's start, which it has visited, no move,
    arrived when the start is the goal."""
    count, run_of_row = queue.count, queue.run_of_row
    here = inputs.start[run_of_row]
    return Results(
        position=here, visited=start_visited(inputs, here),
        moves=jnp.zeros((count,), jnp.int32), diagonal=jnp.zeros((count,), jnp.int32),
        arrived=here == inputs.goal[run_of_row], stuck=jnp.zeros((count,), bool),
        state=initial_state(inputs, run_of_row))


def _fresh_lanes(inputs: WalkInputs, queue: Queue, queued: jax.Array) -> Lanes:
    """Lanes holding the queue's entries ``queued`` (i32[l]; ``>= queue.live``: none, the lane
    empty and not walking), at their run's start."""
    count = queue.count
    holds = queued < queue.live
    agent = jnp.where(holds, queue.order[jnp.minimum(queued, count - 1)], count)
    run = queue.run_of_row[jnp.minimum(agent, count - 1)]
    zeros, no = jnp.zeros(queued.shape, jnp.int32), jnp.zeros(queued.shape, bool)
    return Lanes(agent=agent, run=run,
                 status=lane_status(inputs.start[run], zeros, zeros, holds, no, no),
                 visited=start_visited(inputs, inputs.start[run]),
                 state=initial_state(inputs, run))


def _block(inputs: WalkInputs, loop: Loop) -> Loop:
    """``STEPS_PER_REFILL`` lockstep moves of every lane (:func:`.lanes.step`). The moves go to
    small step-major blocks (``slot_dtype`` and i32 ``[STEPS_PER_REFILL, l]``, one contiguous
    row per step); each lane whose agent moved appends its block to the journal (blocks past
    its room are lost, and counted)."""
    lanes = loop.lanes
    width = lanes.agent.shape[0]

    def step_into_blocks(i, inner):
        lanes, memory, claims, slots, nodes = inner
        lanes, memory, claims, slot, node = step(inputs, lanes, memory, claims)
        # Row ``i`` as a slice update (``.at[i].set`` would bound and wrap ``i`` first: three
        # more kernels at every step).
        return (lanes, memory, claims, jax.lax.dynamic_update_index_in_dim(slots, slot, i, 0),
                jax.lax.dynamic_update_index_in_dim(nodes, node, i, 0))

    first_move = lanes.moves
    slots = jnp.full((STEPS_PER_REFILL, width), -1, inputs.slot_dtype)
    nodes = jnp.full((STEPS_PER_REFILL, width), NO_NODE, jnp.int32)
    lanes, memory, claims, slots, nodes = jax.lax.fori_loop(
        0, STEPS_PER_REFILL, step_into_blocks, (lanes, loop.memory, loop.claims, slots, nodes))
    journal = append(loop.journal, nodes, slots, lanes.agent, first_move,
                     moved=lanes.moves > first_move)
    return loop._replace(lanes=lanes, journal=journal, memory=memory, claims=claims,
                         lane_steps=loop.lane_steps + width * STEPS_PER_REFILL)


def _stopped(queue: Queue, lanes: Lanes) -> jax.Array:
    """bool[l] the lanes holding an agent that no longer walks."""
    return (lanes.agent < queue.count) & ~lanes.walking


def _walking_count(lanes: Lanes) -> jax.Array:
    """i32[] how many lanes walk."""
    return jnp.sum(lanes.walking)


def _keeps_queueing(queue: Queue, few: int, loop: Loop) -> jax.Array:
    """bool[]: the queue holds agents still, or more than ``few`` (static) lanes walk."""
    return (loop.next_queued < queue.live) | (_walking_count(loop.lanes) > few)


def _retire(inputs: WalkInputs, queue: Queue, results: Results, lanes: Lanes,
            which: jax.Array) -> Results:
    """``results`` with the agents of lanes ``which`` (i32[r], ``>= l`` for none) stored: their
    position, visited set, moves, diagonal moves, arrival, stop and (with a hook) state."""
    width = lanes.agent.shape[0]
    held = jnp.minimum(which, width - 1)
    row = jnp.where(which < width, lanes.agent[held], queue.count)
    kept = ("position", "visited", "moves", "diagonal", "arrived", "stuck") + (
        ("state",) if inputs.hook is not None else ())
    return results._replace(**{
        name: getattr(results, name).at[row].set(getattr(lanes, name)[held], mode="drop")
        for name in kept})


def _refill(inputs: WalkInputs, queue: Queue, loop: Loop) -> Loop:
    """Up to ``l // REFILL_SHARE`` lanes whose agent stopped store it and take the queue's next
    entries (or are emptied when the queue is); ``loop.next_queued`` (i32[]) moves past them."""
    lanes = loop.lanes
    width = lanes.agent.shape[0]
    which = jnp.nonzero(_stopped(queue, lanes), size=max(width // REFILL_SHARE, 1),
                        fill_value=width)[0]
    results = _retire(inputs, queue, loop.results, lanes, which)
    taken = which < width
    fresh = _fresh_lanes(inputs, queue,
                         jnp.where(taken, loop.next_queued + jnp.cumsum(taken) - 1, queue.count))
    lanes = jax.tree_util.tree_map(
        lambda old, new: old.at[jnp.where(taken, which, width)].set(new, mode="drop"),
        lanes, fresh)
    return loop._replace(lanes=lanes, results=results,
                         next_queued=jnp.minimum(loop.next_queued + jnp.sum(taken), queue.live))


def _flush(inputs: WalkInputs, queue: Queue, loop: Loop) -> Loop:
    """Every stopped agent still in a lane stored, its lane emptied."""
    lanes = loop.lanes
    width = lanes.agent.shape[0]
    done = _stopped(queue, lanes)
    results = _retire(inputs, queue, loop.results, lanes, jnp.where(done, jnp.arange(width), width))
    return loop._replace(results=results,
                         lanes=lanes._replace(agent=jnp.where(done, queue.count, lanes.agent)))


def _compact(queue: Queue, loop: Loop, few: int) -> Loop:
    """The loop with its ``l`` lanes narrowed to ``few`` (static), holding the agents that still
    walk (at most ``few``: the queue is empty); the spare ones are empty."""
    num_lanes = loop.lanes.agent.shape[0]
    which = jnp.nonzero(loop.lanes.walking, size=few, fill_value=num_lanes)[0]
    lanes = jax.tree_util.tree_map(lambda x: x[jnp.minimum(which, num_lanes - 1)], loop.lanes)
    spare = which >= num_lanes  # holds a copy of some lane: not walking, no agent
    lanes = lanes._replace(
        status=lane_status(lanes.position, lanes.moves, lanes.diagonal, lanes.walking & ~spare,
                           lanes.arrived, lanes.stuck),
        agent=jnp.where(spare, queue.count, lanes.agent))
    return loop._replace(lanes=lanes)
