"""Search statistics of the exact planners, and the Solution they return."""
from __future__ import annotations

import dataclasses

import jax
import numpy as np

from jaxswarm.world.paths import Solution, pad


@dataclasses.dataclass(frozen=True)
class SearchStats:
    """What one exact search did.

    Attributes:
      iterations: main-loop iterations (priority-queue pops; the compiled planners re-key a
        queued node in place, so they pop no stale entries, the heapq reference planners do).
      expanded: nodes expanded (successors generated); counts both directions for bidirectional A*.
      generated: nodes pushed onto a priority queue (successful relaxations plus the roots).
      wall_time: seconds spent in the search (adjacency caching excluded).
      touched: D* Lite only (else None): nodes whose labels the call set or changed; after an
        edit, how far the repair reached.
    """

    iterations: int
    expanded: int
    generated: int
    wall_time: float
    touched: int | None = None


jax.tree_util.register_dataclass(
    SearchStats, data_fields=["iterations", "expanded", "generated", "wall_time", "touched"],
    meta_fields=[])


def make_solution(nodes: list[int] | None, cost: float, stats: SearchStats,
                  length: int) -> Solution:
    """Solution from a host node list (None = not found), padded to ``length``."""
    if nodes is None:
        return Solution(path=np.full(length, -1, np.int32), cost=np.float64(np.inf),
                        found=np.bool_(False), stats=stats)
    return Solution(path=pad(nodes, length), cost=np.float64(cost), found=np.bool_(True),
                    stats=stats)
