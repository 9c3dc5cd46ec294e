"""The worlds the conformance tests share (``test_conformance.py``, ``test_swarm.py``): the RFD
paper's maze of :data:`sizes.MAP` for the walkers, the 6 x 6 plane of :func:`sizes.plane` for the
bees, each as ``(world, task, optimum)``."""
import pytest
import sizes

from jaxswarm.exact import optimal_length
from jaxswarm.exact.visibility import shortest_path
from jaxswarm.swarm import make, make_task
from jaxswarm.world.plane import Plane


@pytest.fixture(scope="module")
def maze():
    graph, task = sizes.maze()
    return graph, task, optimal_length(graph, int(task.start), int(task.goal))


@pytest.fixture(scope="module")
def field():
    """The bees' shared plane (:func:`sizes.plane`), its task and its optimum."""
    plane, start, goal = sizes.plane()
    return plane, make_task(plane, start, goal), shortest_path(plane, start, goal)[0]


def world_of(name, maze, field):
    """The conformance world of a swarm: maze20 for the walkers, the 6 x 6 plane for the bees."""
    return field if make(name).world is Plane else maze
