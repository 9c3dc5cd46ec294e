"""Changes of the map or the task during a run, and what a swarm's memory does about them.

An :class:`Event` is data (node indices, -1 for "none"), so the same compiled program applies any
event of the same size, and a batch of events vmaps::

    event = make_event(graph, goal=(19, 17), block=[(5, 5), (5, 6)])
    state, graph, task = change(swarm, state, event, graph, task, params)  # memory kept
    state, trace = run(swarm, key, graph, task, params, state=state)     # continue from it

:func:`replan` does both in one jittable call, and :func:`first_iteration_at` reads from its trace
when the new optimum was first reached.

:func:`change` applies the event to the map and the task (:func:`apply_event`), then the swarm's
change rule (:mod:`jaxswarm.dynamic.rules`, documented per swarm family: the RFD paper's
:func:`jaxswarm.swarm.rfd.river.paper_altitude_rule`, ``rfd_graded``'s
:func:`jaxswarm.swarm.rfd.graded.regrade` and the ant colonies'
:func:`jaxswarm.swarm.aco.colony.pheromone_rule`), then forgets a best path the event made
invalid (:func:`forget_invalid_best`). Continuing with ``run(..., state=...)``
restarts the patience count.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.dynamic.rules import change_rule
from jaxswarm.swarm.core import Swarm, Task
from jaxswarm.swarm.executor import run
from jaxswarm.world.edits import block_cells, close_edges, open_edges, unblock_cells
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import as_node, is_valid_path

NO_NODE = -1


class Event(NamedTuple):
    """One change (a pytree; stack events of equal sizes for a batch).

    Attributes:
      start: i32[] the new start (the robot moved), -1: unchanged.
      goal: i32[] the new goal, -1: unchanged.
      block: i32[M] nodes that become obstacles, -1 padded.
      unblock: i32[M'] nodes that become free, -1 padded.
      close: i32[E, 2] passages that get a thin wall, as (node, neighbour slot) pairs (both
        directions close), -1 padded.
      open: i32[E', 2] passages whose thin wall goes, likewise.
      num_nodes: i32[] the node count of the map the event was made for.
    """

    start: jax.Array
    goal: jax.Array
    block: jax.Array
    unblock: jax.Array
    close: jax.Array
    open: jax.Array
    num_nodes: jax.Array


def make_event(graph: Graph, *, start=None, goal=None, block=(), unblock=(), close=(),
               open=(), size: int | None = None) -> Event:
    """Host-side: an Event for ``graph``, points as (x, y) cells or node indices.

    Args:
      graph: the map the event is for.
      start, goal: the new start or goal (None: unchanged).
      block, unblock: cells that become obstacles, or free.
      close, open: passages that get, or lose, a thin wall: pairs of adjacent cells
        ``(a, b)``, each an (x, y) cell or a node index.
      size: pad each of ``block``, ``unblock``, ``close`` and ``open`` to this length (events
        of one batch must agree).

    Raises:
      ValueError: a point off the map; a pair of cells that are not neighbours; more entries
        than ``size``.
    """
    def padded(entries, name, blank):
        length = len(entries) if size is None else size
        if len(entries) > length:
            raise ValueError(f"{name}: {len(entries)} entries do not fit size={size}")
        rows = list(entries) + [blank] * (length - len(entries))
        return jnp.asarray(rows, jnp.int32).reshape((length,) + np.shape(blank))

    def node(point, name):
        return NO_NODE if point is None else as_node(graph, point, name=name,
                                                     require_free=False)

    def passage(pair, name):
        a, b = (node(p, name) for p in pair)
        slots = np.nonzero(np.asarray(graph.nbr[a]) == b)[0]
        if not slots.size:
            raise ValueError(f"{name}: cells {pair[0]} and {pair[1]} are not neighbours")
        return (a, int(slots[0]))

    return Event(start=jnp.int32(node(start, "start")), goal=jnp.int32(node(goal, "goal")),
                 block=padded([node(p, "block") for p in block], "block", NO_NODE),
                 unblock=padded([node(p, "unblock") for p in unblock], "unblock", NO_NODE),
                 close=padded([passage(p, "close") for p in close], "close", (NO_NODE,) * 2),
                 open=padded([passage(p, "open") for p in open], "open", (NO_NODE,) * 2),
                 num_nodes=jnp.int32(graph.num_nodes))


def check_events(graph: Graph, task: Task, events: Event) -> None:
    """Host-side: raise ValueError naming the first bad event (of a single Event or a stacked
    batch) before anything is applied: made for a map of another size, a node off the map, a
    start or goal moved onto an obstacle, or a start or goal blocked by the event."""
    leaves = jax.tree_util.tree_map(np.asarray, events)
    batched = leaves.start.ndim == 1
    count = leaves.start.shape[0] if batched else 1
    n = graph.num_nodes
    free = np.asarray(graph.free)
    for i in range(count):
        e = jax.tree_util.tree_map(lambda x, i=i: x[i], leaves) if batched else leaves
        name = f"event {i}" if batched else "event"
        if int(e.num_nodes) != n:
            raise ValueError(f"{name} was made for a map of {int(e.num_nodes)} nodes; this map "
                             f"has {n}")
        for field in ("start", "goal", "block", "unblock", "close", "open"):
            values = np.atleast_1d(getattr(e, field))
            values = values[:, 0] if values.ndim == 2 else values
            off = (values != NO_NODE) & ((values < 0) | (values >= n))
            if off.any():
                raise ValueError(f"{name}: {field} node {int(values[off][0])} is off the map "
                                 f"(nodes 0..{n - 1})")
        for field in ("close", "open"):
            pairs = getattr(e, field)
            pairs = pairs[pairs[:, 0] >= 0]
            slot_ok = (pairs[:, 1] >= 0) & (pairs[:, 1] < graph.max_degree)
            lattice = slot_ok & (np.asarray(graph.nbr)[pairs[:, 0],
                                                       np.where(slot_ok, pairs[:, 1], 0)] >= 0)
            if not lattice.all():
                a, k = pairs[~lattice][0]
                raise ValueError(f"{name}: {field} passage (node {a}, slot {k}) is not an edge "
                                 "of the map")
        after = free.copy()
        after[e.block[e.block >= 0]] = False
        after[e.unblock[e.unblock >= 0]] = True
        for field, old in (("start", int(task.start)), ("goal", int(task.goal))):
            moved = int(getattr(e, field))
            node = old if moved == NO_NODE else moved
            if not after[node]:
                what = "moves onto an obstacle" if moved != NO_NODE else "is blocked"
                raise ValueError(f"{name}: the {field} (node {node}) {what}")


def apply_event(event: Event, graph: Graph, task: Task) -> tuple[Graph, Task]:
    """The map and the task after ``event`` (jittable; shapes unchanged). Cells are blocked,
    then unblocked, then passages closed, then opened."""
    n = graph.num_nodes
    graph = block_cells(graph, jnp.where(event.block >= 0, event.block, n))
    graph = unblock_cells(graph, jnp.where(event.unblock >= 0, event.unblock, n))
    for edit, pairs in ((close_edges, event.close), (open_edges, event.open)):
        graph = edit(graph, pairs[:, 0], jnp.maximum(pairs[:, 1], 0))  # -1 rows: ignored
    task = Task(start=jnp.where(event.start >= 0, event.start, task.start),
                goal=jnp.where(event.goal >= 0, event.goal, task.goal))
    return graph, task


def change(swarm: Swarm, state, event: Event, graph: Graph, task: Task, params):
    """Apply ``event``: ``(state, graph, task)`` after it, the swarm's memory adapted by its rule
    and a best path the event made invalid forgotten (jittable, vmappable over events).

    Check events on the host first (:func:`check_events`); :func:`~jaxswarm.swarm.executor.run` does
    not."""
    after, new_task = apply_event(event, graph, task)
    state = change_rule(swarm)(state, graph, after, task, new_task, params)
    return forget_invalid_best(state, after, new_task), after, new_task


def replan(swarm: Swarm, key, state, event: Event, graph: Graph, task: Task, params, *,
           iterations: int, patience: int | None = None, budget=None):
    """Apply ``event`` (:func:`change`) and continue the run from the adapted memory: ``(state,
    trace)`` of the continuation (:func:`jaxswarm.swarm.run` with ``state``; jittable, so the
    change and the continuation are timed together)."""
    changed, edited, new_task = change(swarm, state, event, graph, task, params)
    return run(swarm, key, edited, new_task, params, iterations=iterations, patience=patience,
               state=changed, budget=budget)


def first_iteration_at(trace, cost: float, *, gap: float) -> int | None:
    """Host-side: the 1-based iteration at which a run's best cost first came within relative
    ``gap`` of ``cost`` (say the new optimum; the run itself never saw it), None if never."""
    best = np.asarray(trace.best_cost)[:int(trace.iterations)]
    hits = np.nonzero((best - cost) / cost < gap)[0]
    return int(hits[0]) + 1 if hits.size else None


def forget_invalid_best(state, graph: Graph, task: Task):
    """``state`` without its best path if that path is no longer a path from the start to the
    goal on ``graph`` (it crosses a blocked cell or edge, or ends at an old goal): its cost is
    forgotten too (inf), so the swarm's next arrived agent becomes the best."""
    valid = is_valid_path(graph, state.best_path, task.start, task.goal)
    return dataclasses.replace(
        state, best_path=jnp.where(valid, state.best_path, NO_NODE),
        best_cost=jnp.where(valid, state.best_cost, jnp.inf))


def __getattr__(name: str):
    if name == "memory_frames":
        import warnings

        from jaxswarm.plot.memory import memory_frames
        warnings.warn("jaxswarm.dynamic.events.memory_frames is jaxswarm.plot.memory.memory_frames "
                      "(this name goes in 0.12.0)", DeprecationWarning, stacklevel=2)
        return memory_frames
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
