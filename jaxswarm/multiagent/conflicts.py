"""Vertex and swap conflicts of all agents at all time steps, as one batched JAX computation.

Per time step the agents' nodes are hashed into occupancy tables indexed by node: a scatter-add
counts the agents on each node, and a scatter-min of ``agent * N + next node`` keeps, per node,
the lowest agent there and where it goes next. So a step costs two scatters and two gathers of A
entries (and the tables' N entries to fill) instead of O(A^2) pair tests. Time steps are
processed in chunks whose tables hold about ``TABLE_ENTRIES`` entries, so memory stays bounded
on large maps and long solutions.

* A **vertex conflict** puts agent ``a`` at time ``t`` on a node another agent also occupies.
* A **swap conflict** between ``t`` and ``t + 1``: ``a`` moves u -> v while the agent found on
  ``v`` at ``t`` (the lowest id there) moves v -> u. A swap with an agent that is itself in a
  vertex conflict at ``t`` can go unreported; that vertex conflict is reported.
"""
from __future__ import annotations

import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.exact.kernels import jit

TABLE_ENTRIES = 1 << 16
"""Occupancy-table entries per chunk of time steps (chunk = this // nodes, at least 1 step)."""


class Conflicts(NamedTuple):
    """Per time step and agent (host numpy arrays).

    Attributes:
      vertex: bool[T, A] the agent shares its node at step t with another agent.
      swap: i32[T, A] the agent it swaps with between steps t and t + 1, -1 if none (row T - 1
        is all -1).
    """

    vertex: np.ndarray
    swap: np.ndarray

    @property
    def any(self) -> bool:
        """Whether there is any conflict."""
        return bool(self.vertex.any() or (self.swap >= 0).any())


def find_conflicts(paths, num_nodes: int) -> Conflicts:
    """Every vertex and swap conflict of a padded solution.

    Args:
      paths: i32[A, T] node indices in ``0..num_nodes-1`` (see :mod:`jaxswarm.multiagent.plan`).
      num_nodes: N, the map's number of nodes.

    Returns:
      :class:`Conflicts` (bool[T, A] vertex flags, i32[T, A] swap partners).
    """
    paths = np.asarray(paths)
    if paths.ndim != 2 or paths.size == 0:
        raise ValueError(f"paths must be a non-empty [agents, steps] array, got {paths.shape}")
    if paths.min() < 0 or paths.max() >= num_nodes:
        raise ValueError(f"paths hold nodes outside 0..{num_nodes - 1}")
    if paths.shape[0] * num_nodes >= 2**31:
        raise ValueError(f"{paths.shape[0]} agents x {num_nodes} nodes do not fit the i32 keys")
    paths = paths.astype(np.int32)
    steps = paths.shape[1]
    # Solutions of any length up to a power of two share one compiled program: the extra
    # steps repeat the last one (no new conflicts) and are cut off.
    padded = 1 << (steps - 1).bit_length()
    nodes = np.concatenate([paths, np.repeat(paths[:, -1:], padded - steps, axis=1)], axis=1)
    chunk = int(min(padded, max(1, TABLE_ENTRIES // num_nodes)))
    vertex, swap = _conflicts(jnp.asarray(nodes.T), num_nodes=num_nodes, chunk=chunk)
    return Conflicts(np.asarray(vertex)[:steps], np.asarray(swap)[:steps])


@functools.partial(jax.jit, static_argnames=("num_nodes", "chunk"))
def _conflicts(nodes: jax.Array, *, num_nodes: int, chunk: int):
    """``nodes`` i32[T, A] -> (bool[T, A] vertex flags, i32[T, A] swap partners)."""
    steps, agents = nodes.shape
    blocks = -(-steps // chunk)
    # Each block reads its rows and the row after each (the last row is followed by itself,
    # which never swaps); rows past T repeat row T - 1 and are cut off at the end.
    following = jnp.concatenate([nodes[1:], nodes[-1:]])
    pad = blocks * chunk - steps
    rows = jnp.concatenate([nodes, jnp.repeat(nodes[-1:], pad, axis=0)])
    nexts = jnp.concatenate([following, jnp.repeat(nodes[-1:], pad, axis=0)])
    ids = jnp.arange(agents, dtype=jnp.int32)

    def block(here, there):
        step = jnp.broadcast_to(jnp.arange(chunk)[:, None], here.shape)
        count = jnp.zeros((chunk, num_nodes), jnp.int32).at[step, here].add(1)
        nobody = agents * num_nodes
        lowest = jnp.full((chunk, num_nodes), nobody, jnp.int32).at[step, here].min(
            ids * num_nodes + there)
        vertex = count[step, here] > 1
        found = lowest[step, there]  # the lowest agent on my next node, and its next node
        other, other_next = found // num_nodes, found % num_nodes
        swapped = (found < nobody) & (other != ids) & (other_next == here) & (here != there)
        return vertex, jnp.where(swapped, other, -1)

    vertex, swap = jax.lax.map(lambda xs: block(*xs), (rows.reshape(blocks, chunk, agents),
                                                       nexts.reshape(blocks, chunk, agents)))
    return vertex.reshape(-1, agents)[:steps], swap.reshape(-1, agents)[:steps]


def pair_collisions(paths, agents=None) -> np.ndarray:
    """i32[B, A]: the first step at which each of ``agents`` (default all, B = A) collides with
    each agent, -1 if never.

    A collision at step t is a vertex conflict at t or a swap arriving at t. A compiled loop
    over the pairs (O(B A T) time, stopping at each pair's first collision): for the planners'
    decisions on few agents, not for validation.

    Args:
      paths: i32[A, T] padded paths.
      agents: optional i32[B] rows to compute.
    """
    paths = np.ascontiguousarray(paths, np.int32)
    rows = (np.arange(len(paths), dtype=np.int32) if agents is None
            else np.asarray(agents, np.int32).reshape(-1))
    return _first_collisions(paths, rows)


def pair_collision_steps(paths: np.ndarray, a: int, b: int) -> list[int]:
    """Every step at which agents ``a`` and ``b`` of ``paths`` (i32[A, T], padded) collide,
    ascending: a vertex conflict at the step or a swap arriving at it (as
    :func:`pair_collisions` counts them)."""
    here, there = paths[a], paths[b]
    swaps = (here[1:] == there[:-1]) & (here[:-1] == there[1:]) & (here[1:] != here[:-1])
    return sorted(np.flatnonzero(here == there).tolist() + (np.flatnonzero(swaps) + 1).tolist())


@jit
def _first_collisions(paths, rows):
    agents, steps = paths.shape
    first = np.full((len(rows), agents), -1, np.int32)
    for i in range(len(rows)):
        a = rows[i]
        for b in range(agents):
            if b == a:
                continue
            for t in range(steps):
                here, there = paths[a, t], paths[b, t]
                if here == there or (t > 0 and paths[a, t - 1] == there
                                     and here == paths[b, t - 1] and here != paths[a, t - 1]):
                    first[i, b] = t
                    break
    return first
