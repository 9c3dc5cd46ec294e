"""What a swarm's memory looks like in a figure, keyed by swarm name: the array drawn and its
label (:data:`MEMORY`), and frames of it re-forming over iterations (:func:`memory_frames`, for
a GIF with :func:`jaxswarm.plot.graph.animate_field`)."""
from __future__ import annotations

from typing import Callable, NamedTuple

import jax

from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.swarm.bees.cabc import WAYPOINTS_LABEL
from jaxswarm.swarm.core import Swarm, Task, World
from jaxswarm.swarm.executor import steps
from jaxswarm.swarm.iwd.iwd import SOIL_LABEL, soil_per_node


class MemoryView(NamedTuple):
    """How a swarm's memory is drawn.

    Attributes:
      of: ``(state) -> array``: the memory per node (f32[N]: altitude, pheromone, soil) of a
        graph swarm, the trajectory so far (f32[L, 2]) of the bees' vehicle.
      label: what ``of`` shows, for colorbars.
    """

    of: Callable
    label: str


def _altitude(state) -> jax.Array:
    return state.altitude


def _pheromone(state) -> jax.Array:
    return ordered_sum(state.pheromone)


_RIVER = MemoryView(_altitude, "altitude")
_COLONY = MemoryView(_pheromone, "pheromone on a node's edges")
_SOIL = MemoryView(soil_per_node, SOIL_LABEL)

MEMORY: dict[str, MemoryView] = {
    "rfd": _RIVER, "rfd_star": _RIVER, "rfd_graded": _RIVER,
    "ant_system": _COLONY, "aco_star": _COLONY, "max_min_aco": _COLONY,
    "improved_max_min_aco": _COLONY,
    "iwd": _SOIL, "iwd_pg": _SOIL,
    "cabc": MemoryView(lambda state: state.waypoints, WAYPOINTS_LABEL),
}
"""Swarm name -> :class:`MemoryView`. Add an entry for a new swarm whose memory is drawn."""


def memory_view(swarm: Swarm) -> MemoryView:
    """How ``swarm``'s memory is drawn (:data:`MEMORY`).

    Raises:
      ValueError: the swarm declares no view; the message says where to add one.
    """
    if swarm.name not in MEMORY:
        raise ValueError(f"swarm {swarm.name!r} has no drawing of its memory: add one to "
                         "jaxswarm.plot.memory.MEMORY")
    return MEMORY[swarm.name]


def memory_frames(swarm: Swarm, state, world: World, task: Task, params, iterations: int):
    """Step a swarm ``iterations`` times from ``state`` (static count, no stop rule) and keep its
    memory (:func:`memory_view`) after each step: ``(state, frames)``, ``frames`` f32[iterations
    + 1, N] on a graph, the first row the memory given (for a figure or a GIF of it re-forming
    after a change, see :func:`jaxswarm.plot.graph.animate_field`). Jittable (``swarm`` and
    ``iterations`` static); see :func:`jaxswarm.swarm.executor.steps`.

    Raises:
      ValueError: the swarm declares no view of its memory.
    """
    return steps(swarm, state, world, task, params, iterations=iterations,
                 record=memory_view(swarm).of)
