"""PIBT: priority inheritance with backtracking (Okumura, Machida, Défago and Tamura, AIJ 2022).

One step moves every agent at once. Agents are taken by priority; each tries its candidate nodes
(its neighbours and its own node) in the order of its distance field (ties broken by a keyed
random number per node), skipping a node that another agent already takes next or that would
swap it with the agent there. Taking a node held by an agent that has not moved yet makes that
agent *inherit* the priority: it must move out first, recursively, and when it cannot, the node
is given up and the next candidate tried (backtracking). An agent left without a candidate stays.
Priorities grow by one per step away from the goal and drop to their fractional part at it, so
the agent that has waited longest goes first.

PIBT alone is incomplete (agents can circle for ever, or block a corridor); it is the
configuration generator of LaCAM (:mod:`jaxswarm.multiagent.lacam`), which adds constraints
(agents whose next node is fixed before PIBT runs) and a search over configurations that is
complete.

The step is numba-compiled as the exact planners are (:mod:`jaxswarm.exact.kernels`): the
recursion becomes an explicit stack, and the keyed tie-breaks come from a SplitMix64 counter, so
a step is a pure function of its inputs.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from jaxswarm.exact.kernels import inline, jit
from jaxswarm.multiagent.agents import UNREACHABLE, agent_nodes, cut_off, hop_fields
from jaxswarm.multiagent.limits import check_count
from jaxswarm.multiagent.plan import Plan, arrival_steps
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.graph import Graph

NONE = -1
"""No agent (on a node), or no next node yet (of an agent)."""


@dataclasses.dataclass(frozen=True, eq=False)
class Moves:
    """What a PIBT step reads of an instance: the map's moves and the agents' distance fields.

    Attributes:
      indptr: i64[N + 1]; the nodes one move from ``u`` are ``heads[indptr[u]:indptr[u + 1]]``.
      heads: i32[E] the heads of the valid edges.
      fields: i32[A, N] steps from every node to each agent's goal (``UNREACHABLE``: none).
      goals: i32[A] the agents' goals.
      candidates: the most candidate nodes of one agent (the largest degree, plus staying).
    """

    indptr: np.ndarray
    heads: np.ndarray
    fields: np.ndarray
    goals: np.ndarray
    candidates: int

    @classmethod
    def build(cls, graph: Graph, goals: np.ndarray, fields: np.ndarray) -> "Moves":
        """The moves of ``graph`` (its valid edges) with the agents' ``goals`` (i32[A]) and
        ``fields`` (i32[A, N], :func:`~jaxswarm.multiagent.agents.hop_fields`)."""
        arrays = edge_arrays(graph)
        return cls(indptr=arrays.indptr, heads=arrays.heads,
                   fields=np.ascontiguousarray(fields, np.int32),
                   goals=np.ascontiguousarray(goals, np.int32),
                   candidates=int(np.diff(arrays.indptr).max(initial=0)) + 1)


class Workspace:
    """The buffers of :func:`configuration`, made once per instance and reused every step.

    Attributes:
      occupied_now: i32[N] the agent on each node (NONE: none); all NONE between calls.
      occupied_next: i32[N] the agent taking each node next; all NONE between calls.
      stack: i32[A, 3 + C] the explicit recursion: agent, next candidate, swap partner (NONE:
        none), then its candidates.
      counts: i32[A] how many candidates each stack frame holds.
      keys: u64[C] the sort keys of one frame's candidates.
      random: u64[1] the SplitMix64 counter of the tie-breaks.
    """

    def __init__(self, moves: Moves, seed: int = 0):
        agents, nodes = moves.fields.shape
        self.occupied_now = np.full(nodes, NONE, np.int32)
        self.occupied_next = np.full(nodes, NONE, np.int32)
        self.stack = np.zeros((agents, 3 + moves.candidates), np.int32)
        self.counts = np.zeros(agents, np.int32)
        self.keys = np.zeros(moves.candidates, np.uint64)
        self.random = np.array([(seed * 0x9E3779B97F4A7C15) % 2**64], np.uint64)


def configuration(moves: Moves, work: Workspace, current: np.ndarray, order: np.ndarray,
                  fixed: np.ndarray, fixed_to: np.ndarray, following: np.ndarray, *,
                  swap: bool = False) -> bool:
    """One PIBT step from ``current``: every agent's next node, written to ``following``.

    With ``swap`` (LaCAM*'s successor generator, Okumura, IJCAI 2023), an agent that meets
    another it can only pass by swapping places (head on in a corridor, both needing the other's
    side) tries its candidates in reverse, stepping back, and on its first one pulls the other
    into the node it leaves; repeated over steps, the two swap where the corridor widens.

    Args:
      moves: the instance.
      work: its buffers (left clean for the next call).
      current: i32[A] every agent's node.
      order: i32[A] the agents, highest priority first.
      fixed: i32[F] agents whose next node is given (LaCAM's constraints; empty for PIBT).
      fixed_to: i32[F] their next nodes.
      following: i32[A] out: every agent's next node.
      swap: the swap operation above.

    Returns:
      True when every agent got a next node with no two agents on one node and no two
      swapping; False when the fixed moves collide, or when an agent with no free candidate
      would stay where a fixed agent moves in (``following`` is then not a configuration).
      Without fixed agents the step always succeeds: an agent with no free candidate stays.
    """
    return bool(compiled_configuration(moves.indptr, moves.heads, moves.fields, moves.goals,
                                       current, order, fixed, fixed_to, following,
                                       work.occupied_now, work.occupied_next, work.stack,
                                       work.counts, work.keys, work.random, swap))


@inline
def _splitmix(state):
    state[0] += np.uint64(0x9E3779B97F4A7C15)
    z = state[0]
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@inline
def _candidates(indptr, heads, fields, agent, node, stack, frame, counts, keys, random):
    """Write ``agent``'s candidates (its neighbours and ``node``) to stack frame ``frame``,
    nearest to its goal first, ties in a keyed random order."""
    count = 0
    for e in range(indptr[node], indptr[node + 1] + 1):
        v = heads[e] if e < indptr[node + 1] else node
        distance = fields[agent, v]
        key = (np.uint64(min(distance, 0x7FFFFFFF)) << np.uint64(32)) | (
            _splitmix(random) >> np.uint64(32))
        i = count
        while i > 0 and keys[i - 1] > key:  # insertion sort of at most degree + 1 entries
            keys[i] = keys[i - 1]
            stack[frame, 3 + i] = stack[frame, 2 + i]
            i -= 1
        keys[i] = key
        stack[frame, 3 + i] = v
        count += 1
    stack[frame, 0] = agent
    stack[frame, 1] = 0
    stack[frame, 2] = NONE
    counts[frame] = count


@jit
def compiled_configuration(indptr, heads, fields, goals, current, order, fixed, fixed_to,
                           following, occupied_now, occupied_next, stack, counts, keys, random,
                           swap):
    """:func:`configuration` for compiled callers (LaCAM's search loop): the arrays of
    :class:`Moves` and :class:`Workspace` spelled out; returns the same bool."""
    for a in range(current.shape[0]):
        following[a] = NONE
        occupied_now[current[a]] = a
    ok = _fix(current, fixed, fixed_to, following, occupied_now, occupied_next)
    for r in range(current.shape[0]):
        if not ok:
            break
        if following[order[r]] == NONE:
            ok = _inherit(indptr, heads, fields, goals, current, order[r], following,
                          occupied_now, occupied_next, stack, counts, keys, random, swap)
    for a in range(current.shape[0]):
        occupied_now[current[a]] = NONE
        if following[a] != NONE:
            occupied_next[following[a]] = NONE
    for k in range(fixed.shape[0]):
        occupied_next[fixed_to[k]] = NONE
    return ok


@inline
def _fix(current, fixed, fixed_to, following, occupied_now, occupied_next):
    """Give the fixed agents their next nodes; False if two share one or two swap."""
    ok = True
    for k in range(fixed.shape[0]):
        a, v = fixed[k], fixed_to[k]
        if occupied_next[v] != NONE:
            ok = False
        following[a] = v
        occupied_next[v] = a
    for k in range(fixed.shape[0]):
        a, v = fixed[k], fixed_to[k]
        other = occupied_now[v]
        if other != NONE and other != a and following[other] == current[a]:
            ok = False
    return ok


@inline
def _inherit(indptr, heads, fields, goals, current, root, following, occupied_now,
             occupied_next, stack, counts, keys, random, swap):
    """PIBT from ``root`` (not yet moved): the recursion on an explicit stack. False when an
    agent left to stay finds a fixed agent moving onto its node."""
    ok = True
    depth = 1
    _candidates(indptr, heads, fields, root, current[root], stack, 0, counts, keys, random)
    if swap:
        _plan_swap(indptr, heads, fields, goals, current, following, occupied_now, stack, 0,
                   counts)
    child = -1  # -1: a fresh frame; 0: its child failed; 1: its child succeeded
    while depth > 0:
        frame = depth - 1
        a = stack[frame, 0]
        if child == 1:
            _pull(current, following, occupied_next, stack, frame)
            depth -= 1
            continue
        child = 0
        while stack[frame, 1] < counts[frame]:
            v = stack[frame, 3 + stack[frame, 1]]
            stack[frame, 1] += 1
            other = occupied_now[v]
            if occupied_next[v] != NONE or (other != NONE and following[other] == current[a]):
                continue  # taken, or a swap
            following[a] = v
            occupied_next[v] = a
            if other != NONE and other != a and following[other] == NONE:
                _candidates(indptr, heads, fields, other, current[other], stack, depth,
                            counts, keys, random)
                if swap:
                    _plan_swap(indptr, heads, fields, goals, current, following, occupied_now,
                               stack, depth, counts)
                depth += 1
                child = -1
            else:
                _pull(current, following, occupied_next, stack, frame)
                child = 1
                depth -= 1
            break
        if child == 0:  # no candidate left: stay (the node the parent asked for is given back)
            here = current[a]
            holder = occupied_next[here]
            if holder != NONE and holder != a and following[holder] == here and (
                    depth == 1 or stack[depth - 2, 0] != holder):
                ok = False  # a fixed agent moves in
            following[a] = here
            occupied_next[here] = a
            depth -= 1
    return ok


@inline
def _pull(current, following, occupied_next, stack, frame):
    """After the agent of ``frame`` moved to its first candidate: its swap partner, if it has
    one that has not moved yet, takes the node it leaves."""
    a, partner = stack[frame, 0], stack[frame, 2]
    here = current[a]
    if (partner != NONE and stack[frame, 1] == 1 and following[partner] == NONE
            and occupied_next[here] == NONE):
        following[partner] = here
        occupied_next[here] = partner


@inline
def _plan_swap(indptr, heads, fields, goals, current, following, occupied_now, stack, frame,
               counts):
    """Find the swap partner of the agent of ``frame`` (none when it wants to stay): the agent
    on its first candidate, if the two must and can swap, else a neighbour that must swap with
    it; with one, reverse the frame's candidates and record the partner."""
    a = stack[frame, 0]
    here, first = current[a], stack[frame, 3]
    if first == here:
        return
    partner = NONE
    other = occupied_now[first]
    if (other != NONE and following[other] == NONE
            and _swap_required(indptr, heads, fields, goals, occupied_now, a, other, here, first)
            and _swap_possible(indptr, heads, goals, occupied_now, first, here)):
        partner = other
    else:
        for e in range(indptr[here], indptr[here + 1]):
            other = occupied_now[heads[e]]
            if other == NONE or first == current[other]:
                continue
            if (_swap_required(indptr, heads, fields, goals, occupied_now, other, a, here, first)
                    and _swap_possible(indptr, heads, goals, occupied_now, first, here)):
                partner = other
                break
    if partner != NONE:
        count = counts[frame]
        for i in range(count // 2):
            j = count - 1 - i
            stack[frame, 3 + i], stack[frame, 3 + j] = stack[frame, 3 + j], stack[frame, 3 + i]
        stack[frame, 2] = partner


@inline
def _corridor_step(indptr, heads, goals, occupied_now, behind, ahead):
    """``(ways on, next node)`` from ``ahead`` leaving ``behind``: its neighbours but
    ``behind`` and dead ends held by an agent at its goal, and the last of them."""
    ways, onward = indptr[ahead + 1] - indptr[ahead], NONE
    for e in range(indptr[ahead], indptr[ahead + 1]):
        u = heads[e]
        held = occupied_now[u]
        if u == behind or (indptr[u + 1] - indptr[u] == 1 and held != NONE
                           and goals[held] == u):
            ways -= 1
        else:
            onward = u
    return ways, onward


@inline
def _swap_required(indptr, heads, fields, goals, occupied_now, pusher, puller, pusher_at,
                   puller_at):
    """Whether ``pusher`` (on ``pusher_at``) and ``puller`` (on ``puller_at``) can only pass
    each other by swapping: following the corridor ahead of the pusher while it leads the pusher
    closer to its goal, no branch opens, and each is better off on the other's side."""
    behind, ahead = pusher_at, puller_at
    while fields[pusher, ahead] < fields[pusher, behind]:
        ways, onward = _corridor_step(indptr, heads, goals, occupied_now, behind, ahead)
        if ways >= 2:
            return False  # a branch: they can pass without swapping
        if ways <= 0:
            break
        behind, ahead = ahead, onward
    return (fields[puller, behind] < fields[puller, ahead]
            and (fields[pusher, behind] == 0 or fields[pusher, ahead] < fields[pusher, behind]))


@inline
def _swap_possible(indptr, heads, goals, occupied_now, pusher_at, puller_at):
    """Whether pulling along the corridor from ``puller_at`` (away from ``pusher_at``) reaches a
    branch where the two can swap before it loops back or ends."""
    behind, ahead = pusher_at, puller_at
    while ahead != pusher_at:
        ways, onward = _corridor_step(indptr, heads, goals, occupied_now, behind, ahead)
        if ways >= 2:
            return True
        if ways <= 0:
            return False
        behind, ahead = ahead, onward
    return False


def initial_priorities(moves: Moves, starts: np.ndarray) -> np.ndarray:
    """f64[A] the first priorities: each agent's distance to its goal over the number of nodes
    (in [0, 1), so the first step goes to the farthest agents)."""
    agents = np.arange(len(starts))
    distances = moves.fields[agents, starts].astype(np.float64)
    return np.where(distances >= UNREACHABLE, 0.0, distances) / moves.fields.shape[1]


@inline
def next_priorities(priorities, nodes, goals, out):
    """Write to ``out`` (f64[A], may be ``priorities`` itself) the priorities after a step to
    ``nodes`` (i32[A]): one more for every agent away from its goal (``goals``, i32[A]), the
    fractional part for one at it. Compiled, for LaCAM's loop as for :func:`pibt`."""
    for a in range(goals.shape[0]):
        p = priorities[a]
        out[a] = p - np.floor(p) if nodes[a] == goals[a] else p + 1.0


@inline
def by_priority(priorities):
    """i32[A] the agents, highest priority first (ties by agent number: a stable sort).
    Compiled, for LaCAM's loop as for :func:`pibt`."""
    return np.argsort(-priorities, kind="mergesort").astype(np.int32)


@dataclasses.dataclass(frozen=True)
class PIBTConfig:
    """The options of :func:`pibt`, checked when made.

    Attributes:
      max_steps: give up after this many steps (at least 1).
      seed: the key of the tie-breaks (at least 0).

    Raises:
      TypeError, ValueError: an option that is not a whole number in its range, naming it.
    """

    max_steps: int = 1000
    seed: int = 0

    def __post_init__(self):
        check_count("max_steps", self.max_steps)
        check_count("seed", self.seed, least=0)


def pibt(graph: Graph, starts, goals, **options) -> Plan:
    """PIBT steps from the starts until every agent is at its goal at once.

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      **options: those of :class:`~jaxswarm.multiagent.pibt.PIBTConfig` (``max_steps``, ``seed``).

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``planner="pibt"``); not solved when an
      agent's goal cannot be reached (naming it) or after ``max_steps`` (naming an agent still
      away). ``stats``: ``steps``, ``field_seconds`` (the distance fields) and ``seconds`` (the
      steps).

    Raises:
      TypeError, ValueError: a bad option (see :class:`~jaxswarm.multiagent.pibt.PIBTConfig`),
        naming it, before any search.
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`).
    """
    config = PIBTConfig(**options)
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    fields = hop_fields(graph, goal_nodes)
    field_seconds = time.perf_counter() - began
    stats = dict(field_seconds=field_seconds)
    blocked = cut_off(graph, fields, start_nodes, goal_nodes)
    if blocked is not None:
        return Plan(start_nodes[:, None], np.zeros(len(start_nodes), np.int32), solved=False,
                    planner="pibt", reason=blocked[1], agent=blocked[0],
                    stats=dict(stats, steps=0, seconds=0.0))
    moves = Moves.build(graph, goal_nodes, fields)
    work = Workspace(moves, config.seed)
    searching = time.perf_counter()
    configurations = [start_nodes]
    priorities = initial_priorities(moves, start_nodes)
    empty = np.zeros(0, np.int32)
    current = start_nodes
    while not np.array_equal(current, goal_nodes) and len(configurations) <= config.max_steps:
        following = np.empty_like(current)
        configuration(moves, work, current, by_priority(priorities), empty, empty, following)
        next_priorities(priorities, following, goal_nodes, priorities)
        configurations.append(following)
        current = following
    paths = np.stack(configurations, axis=1)
    stats |= dict(steps=len(configurations) - 1, seconds=time.perf_counter() - searching)
    if not np.array_equal(current, goal_nodes):
        away = int(np.nonzero(current != goal_nodes)[0][0])
        return Plan(paths, arrival_steps(paths, goal_nodes), solved=False, planner="pibt",
                    reason=f"agent {away} (and {int((current != goal_nodes).sum()) - 1} more) "
                           f"not at its goal after {config.max_steps} steps", agent=away,
                    stats=stats)
    return Plan(paths, arrival_steps(paths, goal_nodes), solved=True, planner="pibt",
                stats=stats)
