"""LaCAM*'s graph of explored configurations and its Dijkstra update (Okumura, IJCAI 2023).

Every configuration the search finds keeps its cost from the starts (``g``), a lower bound of its
cost to the goals (``h``), its parent on the cheapest way known, and its neighbours: the
configurations generated from it, each once, with the cost of the step to them. A step costs the
agents not resting at their goals through it (on their goals before and after): the *sum of
loss*, LaCAM*'s objective. When a known configuration is generated again, the edge is added and
the saving, if any, is passed on to every configuration reached more cheaply through it (a
Dijkstra update over the known edges); those whose cost now falls below the best solution's must
be searched again, as the reference implementation (Kei18/lacam2, ``Planner::rewrite``) pushes
them back on the open stack.

The configurations are rows of growing arrays, found by their nodes through an open-addressing
hash table; each one's neighbours are a linked list of edges, and the edges a hash set of
``(source, target)`` pairs, so that a step met again adds no edge. The search reads and writes
them from its compiled loop (:mod:`jaxswarm.multiagent.lacam`) with the ``@inline`` functions
below, on the tuple :attr:`Explored.arrays`; this class owns the arrays and grows them between
the loop's calls.
"""
from __future__ import annotations

import heapq

import numpy as np

from jaxswarm.exact.kernels import inline, jit

NONE = -1
"""No configuration (the root's parent, an empty slot), or no edge (a neighbour list's end)."""


class Explored:
    """The configurations of one search, their costs, parents and neighbour sets.

    Attributes:
      goals: i32[A] the agents' goals.
      nodes: i32[capacity, A] each configuration's nodes (rows below ``size``); row ``size`` is
        where the next configuration is written before it is looked up (:func:`spare`).
      cost: i64[capacity] each configuration's cost from the starts (``g``), sum of loss.
      bound: i64[capacity] a lower bound of its cost to the goals (``h``).
      parent: i64[capacity] the previous configuration on its cheapest known way (NONE: root).
      first: i64[capacity] its first edge (NONE: no neighbours yet).
      settled: i64[capacity] the Dijkstra update's output (see :func:`connect`).
      slots: i64[2 * capacity] the hash table of the configurations' ids (NONE: empty).
      edge_next: i64[edge capacity] the next edge of the same configuration (NONE: last).
      edge_head: i64[edge capacity] the configuration an edge leads to.
      edge_cost: i64[edge capacity] the edge's step cost.
      links: i64[2 * edge capacity] the hash set of the edges as ``source << 32 | target``
        (NONE: empty).
      counts: i64[2] the numbers of configurations (``size``) and of edges.
    """

    def __init__(self, goals: np.ndarray, capacity: int = 1024):
        self.goals = np.ascontiguousarray(goals, np.int32)
        self.nodes = np.empty((capacity, len(goals)), np.int32)
        self.cost, self.bound, self.parent, self.first, self.settled = (
            np.empty(capacity, np.int64) for _ in range(5))
        self.slots = np.full(2 * capacity, NONE, np.int64)
        self.edge_next, self.edge_head, self.edge_cost = (
            np.empty(capacity, np.int64) for _ in range(3))
        self.links = np.full(2 * capacity, NONE, np.int64)
        self.counts = np.zeros(2, np.int64)

    @property
    def size(self) -> int:
        """The number of configurations; ids are 0..size-1 in the order they were found."""
        return int(self.counts[0])

    @property
    def arrays(self) -> tuple:
        """What the ``@inline`` functions of this module take as ``explored``."""
        return (self.goals, self.nodes, self.cost, self.bound, self.parent, self.first,
                self.settled, self.slots, self.edge_next, self.edge_head, self.edge_cost,
                self.links, self.counts)

    def add_root(self, nodes: np.ndarray, bound: int) -> int:
        """Add the first configuration, ``nodes`` (i32[A]), with lower bound ``bound``; its id."""
        self.nodes[0] = nodes
        self.cost[0], self.bound[0], self.parent[0], self.first[0] = 0, bound, NONE, NONE
        self.counts[0] = 1
        _rebuild(self.nodes, 1, self.slots, self.links[:0], self.links)
        return 0

    def reserve(self, configurations: int, edges: int) -> None:
        """Grow the arrays (doubling) so that ``configurations`` more configurations, the spare
        row included, and ``edges`` more edges fit."""
        size, count = self.counts
        if size + configurations <= len(self.cost) and count + edges <= len(self.edge_head):
            return
        self.nodes, self.cost, self.bound, self.parent, self.first, self.settled = (
            grown(a, size + configurations) for a in (self.nodes, self.cost, self.bound,
                                                      self.parent, self.first, self.settled))
        self.edge_next, self.edge_head, self.edge_cost = (
            grown(a, count + edges) for a in (self.edge_next, self.edge_head, self.edge_cost))
        links = self.links
        self.slots = np.full(2 * len(self.cost), NONE, np.int64)
        self.links = np.full(2 * len(self.edge_head), NONE, np.int64)
        _rebuild(self.nodes, size, self.slots, links, self.links)

    def way(self, last: int) -> list[np.ndarray]:
        """The configurations (i32[A] each) from the root to ``last`` along the parents."""
        out = []
        while last != NONE:
            out.append(self.nodes[last].copy())
            last = int(self.parent[last])
        return out[::-1]


def grown(array: np.ndarray, needed: int) -> np.ndarray:
    """``array`` with its rows doubled until ``needed`` rows fit (itself if they do), the new
    rows uninitialised."""
    capacity = len(array)
    while capacity < needed:
        capacity *= 2
    if capacity == len(array):
        return array
    out = np.empty((capacity,) + array.shape[1:], array.dtype)
    out[:len(array)] = array
    return out


@inline
def _mix(h):
    """SplitMix64's finaliser: every bit of ``h`` (u64) moves every bit of the result."""
    h = (h ^ (h >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    h = (h ^ (h >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return h ^ (h >> np.uint64(31))


@inline
def _slot(nodes, slots, row):
    """The slot of configuration ``row`` (i32[A]) in ``slots``: where its id is, or the empty
    slot where it goes (linear probing; ``slots`` is a power of two long)."""
    h = np.uint64(0xCBF29CE484222325)
    for a in range(row.shape[0]):
        h = (h ^ np.uint64(row[a])) * np.uint64(0x100000001B3)
    mask = np.uint64(slots.shape[0] - 1)
    s = np.int64(_mix(h) & mask)
    while slots[s] != NONE:
        known = slots[s]
        same = True
        for a in range(row.shape[0]):
            if nodes[known, a] != row[a]:
                same = False
                break
        if same:
            break
        s = np.int64((np.uint64(s) + np.uint64(1)) & mask)
    return s


@inline
def _link_slot(links, key):
    """The slot of edge ``key`` (``source << 32 | target``) in ``links``, or the empty slot where
    it goes."""
    mask = np.uint64(links.shape[0] - 1)
    s = np.int64(_mix(np.uint64(key)) & mask)
    while links[s] != NONE and links[s] != key:
        s = np.int64((np.uint64(s) + np.uint64(1)) & mask)
    return s


@jit
def _rebuild(nodes, size, slots, old_links, links):
    """Fill the empty tables ``slots`` with the configurations 0..size-1 of ``nodes`` and
    ``links`` with the edges of the table ``old_links``."""
    for known in range(size):
        slots[_slot(nodes, slots, nodes[known])] = known
    for key in old_links:
        if key != NONE:
            links[_link_slot(links, key)] = key


@inline
def spare(explored):
    """i32[A] the row the next configuration is written to before :func:`find` (the arrays
    hold room for it between the loop's calls, :meth:`Explored.reserve`)."""
    (_, nodes, _, _, _, _, _, _, _, _, _, _, counts) = explored
    return nodes[counts[0]]


@inline
def find(explored):
    """``(id, slot)``: the id of the configuration in :func:`spare` (NONE if it is new) and its
    slot in the hash table, for :func:`add`."""
    (_, nodes, _, _, _, _, _, slots, _, _, _, _, counts) = explored
    s = _slot(nodes, slots, nodes[counts[0]])
    return slots[s], s


@inline
def add(explored, slot, parent, bound):
    """Add the new configuration in :func:`spare` (``slot``: from :func:`find`), reached from
    ``parent`` (an id) with lower bound ``bound`` to the goals; the edge from the parent is
    added. Returns its id."""
    (_, _, cost, bound_of, parent_of, first, _, slots, _, _, _, _, counts) = explored
    new = counts[0]
    counts[0] += 1
    slots[slot] = new
    bound_of[new] = bound
    parent_of[new] = parent
    first[new] = NONE
    cost[new] = cost[parent] + _link(explored, parent, new, (parent << 32) | new)
    return new


@inline
def _link(explored, source, target, key):
    """Add the edge ``source -> target`` (its ``key`` not in ``links`` yet); returns its step
    cost: the agents not resting at their goals through the step."""
    (goals, nodes, _, _, _, first, _, _, edge_next, edge_head, edge_cost, links, counts) = explored
    links[_link_slot(links, key)] = key
    step = 0
    for a in range(goals.shape[0]):
        if nodes[source, a] != goals[a] or nodes[target, a] != goals[a]:
            step += 1
    edge = counts[1]
    counts[1] += 1
    edge_head[edge] = target
    edge_cost[edge] = step
    edge_next[edge] = first[source]
    first[source] = edge
    return step


@inline
def connect(explored, source, target, limit):
    """Record that ``target`` (an id) was generated from ``source`` again, and pass any saving
    on (the Dijkstra update).

    Args:
      explored: :attr:`Explored.arrays`.
      source, target: ids of known configurations.
      limit: the best solution's cost (or a larger number while none is known).

    Returns:
      How many configurations the update wrote to ``settled`` (i64[capacity]): those whose cost
      fell and whose cost plus bound is now below ``limit``, cheapest first, the ones to search
      again.
    """
    (_, _, cost, bound, parent, first, settled, _, edge_next, edge_head, edge_cost, links,
     _) = explored
    key = (source << 32) | target
    if source == target or links[_link_slot(links, key)] == key:
        return 0
    _link(explored, source, target, key)
    return _update(cost, bound, parent, first, edge_next, edge_head, edge_cost, source, limit,
                   settled)


@jit
def _update(cost, bound, parent, first, edge_next, edge_head, edge_cost, source, limit, settled):
    """Dijkstra from ``source`` over the known edges, lowering costs and moving parents; writes
    the configurations whose cost fell with cost plus bound below ``limit`` to ``settled``, in
    the order they are settled, and returns their number."""
    queue = [(cost[source], source)]
    count = 0
    while queue:
        here_cost, here = heapq.heappop(queue)
        if here_cost != cost[here]:
            continue  # a stale entry: lowered again since
        if here != source and here_cost + bound[here] < limit:
            settled[count] = here
            count += 1
        edge = first[here]
        while edge != -1:
            there = edge_head[edge]
            through = here_cost + edge_cost[edge]
            if through < cost[there]:
                cost[there] = through
                parent[there] = here
                heapq.heappush(queue, (through, there))
            edge = edge_next[edge]
    return count
