"""LaCAM's constraint trees (Okumura, AAAI 2023), stored as arrays.

Each configuration the search expands gets a tree: its agents in priority order, and a queue of
constraints not taken yet, breadth first. A constraint at depth d fixes the next nodes of the
first d agents of the order; it is stored as its parent constraint, the agent it adds (the
order's d-th) and that agent's node, so that a constraint is a few numbers whatever its depth and
its fixed moves are gathered by walking up to the tree's root (depth 0, fixing nothing). Taking a
constraint from the queue appends its children: the next agent's candidate nodes (its neighbours
and its own node) in a random order drawn from a NumPy ``Generator``, so that every combination
of moves is enumerated once, in the end.

The search's compiled loop (:mod:`jaxswarm.multiagent.lacam`) calls the ``@inline`` functions
below on the tuple :attr:`ConstraintTrees.arrays`; the class owns the arrays and grows them
between the loop's calls.
"""
from __future__ import annotations

import numpy as np

from jaxswarm.exact.kernels import inline
from jaxswarm.multiagent.explored import grown
from jaxswarm.multiagent.pibt import by_priority

NONE = -1
"""No constraint (a root's parent, a queue's end, an empty queue)."""


class ConstraintTrees:
    """The constraint trees of one search.

    Attributes:
      order: i32[T, A] each tree's agents, highest priority first (rows below the count).
      head: i64[T] each tree's next constraint to take (NONE: none left).
      tail: i64[T] its last constraint queued.
      parent: i64[C] each constraint's parent (NONE: a root).
      agent: i32[C] the agent it fixes (a root: NONE).
      node: i32[C] that agent's next node.
      depth: i32[C] how many agents it fixes (its own and its ancestors').
      queued: i64[C] the constraint after it in its tree's queue (NONE: the last).
      counts: i64[2] the numbers of trees and of constraints.
    """

    def __init__(self, agents: int, capacity: int = 1024):
        self.order = np.empty((capacity, agents), np.int32)
        self.head, self.tail = np.empty(capacity, np.int64), np.empty(capacity, np.int64)
        self.parent, self.queued = np.empty(capacity, np.int64), np.empty(capacity, np.int64)
        self.agent, self.node, self.depth = (np.empty(capacity, np.int32) for _ in range(3))
        self.counts = np.zeros(2, np.int64)

    @property
    def arrays(self) -> tuple:
        """What the ``@inline`` functions of this module take as ``trees``."""
        return (self.order, self.head, self.tail, self.parent, self.agent, self.node,
                self.depth, self.queued, self.counts)

    def reserve(self, trees: int, constraints: int) -> None:
        """Grow the arrays (doubling) so that ``trees`` more trees and ``constraints`` more
        constraints fit."""
        planted, count = self.counts
        self.order, self.head, self.tail = (grown(a, planted + trees)
                                            for a in (self.order, self.head, self.tail))
        self.parent, self.agent, self.node, self.depth, self.queued = (
            grown(a, count + constraints) for a in (self.parent, self.agent, self.node,
                                                    self.depth, self.queued))


@inline
def _queue(trees, tree, parent, agent, node, depth):
    """Append a new constraint to ``tree``'s queue."""
    (_, head, tail, parent_of, agent_of, node_of, depth_of, queued, counts) = trees
    new = counts[1]
    counts[1] += 1
    parent_of[new], agent_of[new], node_of[new], depth_of[new] = parent, agent, node, depth
    queued[new] = NONE
    if head[tree] == NONE:
        head[tree] = new
    else:
        queued[tail[tree]] = new
    tail[tree] = new


@inline
def plant(trees, priorities):
    """A new tree for agents of ``priorities`` (f64[A]): its order, highest priority first and
    ties by agent number, and its root queued. Returns its id."""
    (order, head, _, _, _, _, _, _, counts) = trees
    tree = counts[0]
    counts[0] += 1
    order[tree] = by_priority(priorities)
    head[tree] = NONE
    _queue(trees, tree, NONE, NONE, NONE, 0)
    return tree


@inline
def take(trees, tree, indptr, heads, current, options, rng):
    """Take ``tree``'s next constraint and queue its children: the next agent's candidates
    (``heads[indptr[u]:indptr[u + 1]]`` and ``u``, its node in ``current``, i32[A]) shuffled
    by ``rng`` (a NumPy ``Generator``) in the scratch array ``options`` (i32[C]). Returns the
    constraint, or NONE when the tree has none left."""
    (order, head, _, _, _, _, depth, queued, _) = trees
    taken = head[tree]
    if taken == NONE:
        return NONE
    head[tree] = queued[taken]
    d = depth[taken]
    if d < order.shape[1]:
        who = order[tree, d]
        here = current[who]
        count = indptr[here + 1] - indptr[here]
        options[:count] = heads[indptr[here]:indptr[here + 1]]
        options[count] = here
        rng.shuffle(options[:count + 1])
        for k in range(count + 1):
            _queue(trees, tree, taken, who, options[k], d + 1)
    return taken


@inline
def gather(trees, constraint, who, where):
    """Write the agents ``constraint`` fixes to ``who`` and their next nodes to ``where`` (i32[A]
    each), the order's first agent first; returns how many."""
    (_, _, _, parent, agent, node, depth, _, _) = trees
    fixed = depth[constraint]
    k = fixed
    while k > 0:
        k -= 1
        who[k] = agent[constraint]
        where[k] = node[constraint]
        constraint = parent[constraint]
    return fixed
