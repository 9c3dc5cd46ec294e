"""Space-time A*: one agent's fewest-steps path among reserved nodes and moves (compiled).

A state is ``(node, step)``; each step the agent waits or moves along a valid edge, at a cost of
one. :func:`search` plans around a :class:`Reservations` table of what the other agents hold:
each node at each step ``t < H`` (a move into a node whose holder comes the other way is a swap,
forbidden), the nodes held for good, single forbidden moves (CBS's edge constraints) and the
steps between which the agent must come to rest at its goal (target reasoning's length
constraints). From step ``H`` on nothing moves, so a state reaching it is finished by the static
shortest path around the parked nodes: the search stores at most ``(H + 1) N`` states, ends on
every instance, and accepts the goal at step ``t`` only if no reservation touches it at ``t`` or
later. The numba-compiled heap pops the lowest f, then (with a conflict avoidance table) the path
meeting the fewest other agents, then the latest step, then the lowest node, so a solution is a
pure function of its input.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from jaxswarm.exact.kernels import inline, jit
from jaxswarm.multiagent.agents import UNREACHABLE, breadth_first
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.graph import Graph

FREE, FORBIDDEN = -1, -2
"""``holder`` entries that are not agents."""
FOUND, EXHAUSTED, LIMIT = 0, 1, 2
"""Search outcomes."""
MET_CAP = 1023
"""The most agents met a path's tie-break counts (more count as this many)."""


@dataclasses.dataclass
class Reservations:
    """What other agents hold, for :func:`search` (see the module docstring).

    Attributes:
      holder: i32[H, N] agent (or FREE, FORBIDDEN) per step and node.
      parked_from: i32[N] the step from which a node is held for good (UNREACHABLE: never).
      banned: i32[M, 3] forbidden moves ``(t, u, v)``, each with t < H.
      earliest_finish: the first step from which the agent may stay at its goal (at most H).
      latest_finish: the last step from which it may start staying there (UNREACHABLE: any).
    """

    holder: np.ndarray
    parked_from: np.ndarray
    banned: np.ndarray
    earliest_finish: int = 0
    latest_finish: int = UNREACHABLE

    @classmethod
    def empty(cls, num_nodes: int, steps: int = 0) -> "Reservations":
        """Nothing held, over a table of ``steps`` rows."""
        return cls(np.full((steps, num_nodes), FREE, np.int32),
                   np.full(num_nodes, UNREACHABLE, np.int32), np.zeros((0, 3), np.int32))

    def reserve(self, agent: int, path: np.ndarray) -> None:
        """Hold ``path`` (i32[L], ending at the agent's goal) for ``agent``: its nodes at steps
        0..L-1 (the table grows to at least L rows, so a swap into its last move is seen) and
        its goal from step L - 1 on."""
        steps = len(path)
        if steps > self.holder.shape[0]:
            grown = np.full((steps, self.holder.shape[1]), FREE, np.int32)
            grown[:self.holder.shape[0]] = self.holder
            self.holder = grown
        self.holder[np.arange(steps), path] = agent
        self.parked_from[path[-1]] = steps - 1

    def last_use(self, node: int) -> int:
        """The last step < H at which ``node`` is held or forbidden (-1 if none)."""
        held = np.nonzero(self.holder[:, node] != FREE)[0]
        return int(held[-1]) if held.size else -1


def static_field(graph: Graph, goal: int, blocked: np.ndarray) -> np.ndarray:
    """i32[N]: steps from every node to ``goal`` avoiding the ``blocked`` nodes (bool[N]),
    UNREACHABLE where there is no way."""
    arrays = edge_arrays(graph)
    return breadth_first(arrays.rev_indptr, arrays.rev_tails, goal, blocked)


def search(graph: Graph, start: int, goal: int, heuristic: np.ndarray, reservations: Reservations,
           *, max_expansions: int = 10_000_000,
           avoid: np.ndarray | None = None) -> tuple[np.ndarray | None, int, int]:
    """Fewest-steps path of one agent from ``start`` to ``goal`` around the reservations.

    Args:
      graph: the map (its valid edges are the moves).
      start, goal: node indices.
      heuristic: i32[N] the fewest steps from every node to ``goal`` on the map, ignoring the
        other agents (``hop_fields``; exact: with no node parked it is also the static way to
        the goal once nothing moves).
      reservations: what the other agents hold.
      max_expansions: stop after expanding this many states.
      avoid: optional i32[T, N] a conflict avoidance table (:func:`occupancy`): of the paths of
        fewest steps, the one meeting the fewest agents on their nodes (step t >= T reads row
        T - 1); None: ties as the module docstring orders them.

    Returns:
      ``(path i32[L] or None, expanded states, outcome)``, outcome FOUND, EXHAUSTED (no path
      exists) or LIMIT.
    """
    arrays = edge_arrays(graph)
    heuristic = np.ascontiguousarray(heuristic, np.int32)
    parked = reservations.parked_from
    blocked = (parked < UNREACHABLE) & (np.arange(len(parked)) != goal)
    # Without parked nodes the static way to the goal is the heuristic's own field.
    finish = static_field(graph, goal, blocked) if blocked.any() else heuristic
    keep_from = max(reservations.last_use(goal) + 1, reservations.earliest_finish)
    avoid = np.zeros((0, graph.num_nodes), np.int32) if avoid is None else avoid
    path, expanded, outcome = _search(
        arrays.indptr, arrays.heads, heuristic, finish, start, goal, reservations.holder, parked,
        reservations.banned, keep_from, reservations.latest_finish, max_expansions,
        np.ascontiguousarray(avoid, np.int32))
    return (path if outcome == FOUND else None), int(expanded), int(outcome)


def occupancy(padded: np.ndarray, num_nodes: int) -> np.ndarray:
    """i32[T, N]: per step, how many of the paths ``padded`` (i32[B, T], each resting at its
    end after it; B may be 0) are on each node (the last row stands for every later step)."""
    steps = padded.shape[1]
    cells = (np.arange(steps, dtype=np.int64) * num_nodes + padded).ravel()
    return np.bincount(cells, minlength=steps * num_nodes).reshape(steps, num_nodes).astype(
        np.int32)


@inline
def _push(heap, size, key):
    if size == heap.shape[0]:
        grown = np.empty(2 * size, np.int64)
        grown[:size] = heap[:size]
        heap = grown
    i = size
    while i > 0:
        up = (i - 1) >> 1
        if heap[up] <= key:
            break
        heap[i] = heap[up]
        i = up
    heap[i] = key
    return heap, size + 1


@inline
def _pop(heap, size):
    top = heap[0]
    size -= 1
    last = heap[size]
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and heap[child + 1] < heap[child]:
            child += 1
        if heap[child] >= last:
            break
        heap[i] = heap[child]
        i = child
    heap[i] = last
    return top, size


@inline
def _open(holder, parked, horizon, v, t):
    """Whether node v is free at step t."""
    return t < parked[v] and (t >= horizon or holder[t, v] == -1)


@inline
def _allowed(holder, banned, horizon, u, v, t):
    """Whether the move u -> v from step t is no swap and not banned."""
    if t + 1 < horizon:
        other = holder[t, v]
        if other >= 0 and holder[t + 1, u] == other:
            return False
    for i in range(banned.shape[0]):
        if banned[i, 0] == t and banned[i, 1] == u and banned[i, 2] == v:
            return False
    return True


@inline
def _met(avoid, v, t):
    """Agents the avoidance table has on node v at step t (0 without a table)."""
    if avoid.shape[0] == 0:
        return 0
    return avoid[min(t, avoid.shape[0] - 1), v]


@jit
def _search(indptr, heads, heuristic, finish, start, goal, holder, parked, banned, keep_from,
            latest_finish, max_expansions, avoid):
    # A key packs (f, agents met, -t, node): the least f, then the fewest met, then the latest
    # step. f is at least keep_from, the earliest step the agent may end at its goal: with a
    # late finish forced, the search runs deep down one path instead of through every state
    # that could still reach the goal before then. A state whose f is past latest_finish cannot
    # finish in time (f is a lower bound of its finish) and is not pushed. A state is closed
    # when first popped; one reached again meeting fewer agents before that is pushed again
    # (its older key is stale).
    horizon, n = holder.shape
    layers = horizon + 1
    met = np.full(layers * n, MET_CAP + 1, np.int32)
    closed = np.zeros(layers * n, np.bool_)
    parent = np.empty(layers * n, np.int32)
    heap = np.empty(1024, np.int64)
    size = 0
    empty = np.empty(0, np.int32)
    if not _open(holder, parked, horizon, start, 0):
        return empty, 0, EXHAUSTED
    f0 = heuristic[start] if horizon > 0 else finish[start]
    if f0 >= UNREACHABLE or max(f0, keep_from) > latest_finish:
        return empty, 0, EXHAUSTED
    met[start] = 0
    heap, size = _push(heap, size, _key(max(f0, keep_from), 0, layers, horizon, 0, n, start))
    expanded = 0
    while size > 0:
        key, size = _pop(heap, size)
        v = key % n
        t = horizon - (key // n) % layers
        c = (key // (n * layers)) % (MET_CAP + 1)
        state = t * n + v
        if closed[state] or c != met[state]:
            continue
        closed[state] = True
        if t == horizon or (v == goal and t >= keep_from):
            return _unwind(indptr, heads, finish, parent, n, v, t, horizon), expanded, FOUND
        if expanded == max_expansions:
            return empty, expanded, LIMIT
        expanded += 1
        nt = t + 1
        for e in range(indptr[v] - 1, indptr[v + 1]):
            w = v if e < indptr[v] else heads[e]  # a wait first, then the moves
            state = nt * n + w
            if closed[state] or not _open(holder, parked, horizon, w, nt):
                continue
            if w != v and not _allowed(holder, banned, horizon, v, w, t):
                continue
            remaining = finish[w] if nt == horizon else heuristic[w]
            if remaining >= UNREACHABLE:
                continue
            f = max(nt + remaining, keep_from)
            meets = min(c + _met(avoid, w, nt), MET_CAP)
            if f > latest_finish or meets >= met[state]:
                continue
            met[state] = meets
            parent[state] = v
            heap, size = _push(heap, size, _key(f, meets, layers, horizon, nt, n, w))
    return empty, expanded, EXHAUSTED


@inline
def _key(f, meets, layers, horizon, t, n, v):
    return ((np.int64(f) * (MET_CAP + 1) + meets) * layers + horizon - t) * n + v


@jit
def _unwind(indptr, heads, finish, parent, n, v, t, horizon):
    """The path to state (v, t), then (at the horizon) down the static field to the goal."""
    tail = finish[v] if t == horizon else 0
    path = np.empty(t + tail + 1, np.int32)
    node = v
    for step in range(t, -1, -1):
        path[step] = node
        if step > 0:
            node = parent[step * n + node]
    node = v
    for step in range(t + 1, t + tail + 1):
        for e in range(indptr[node], indptr[node + 1]):
            if finish[heads[e]] == finish[node] - 1:
                node = heads[e]
                break
        path[step] = node
    return path
