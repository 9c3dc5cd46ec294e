"""The IWD_PG experiments' maps: their optima against networkx on a graph built here from the
obstacle array, independently of the library's grids."""
import math

import numpy as np
import pytest

from jaxswarm.exact import dijkstra
from jaxswarm.maps.iwd_pg import OPTIMA, iwd_pg_map
from jaxswarm.swarm import make_task

nx = pytest.importorskip("networkx")


def networkx_length(obstacles: np.ndarray, start, goal) -> float:
    """8-connected moves between free cells, a diagonal only when both cells beside it are free."""
    height, width = obstacles.shape
    graph = nx.Graph()
    for y in range(height):
        for x in range(width):
            if obstacles[y, x]:
                continue
            for dx, dy in ((1, 0), (0, 1), (1, 1), (-1, 1)):
                u, v = x + dx, y + dy
                if not (0 <= u < width and 0 <= v < height) or obstacles[v, u]:
                    continue
                if dx and dy and (obstacles[y, u] or obstacles[v, x]):
                    continue
                graph.add_edge((x, y), (u, v), weight=math.hypot(dx, dy))
    return nx.dijkstra_path_length(graph, start, goal)


@pytest.mark.parametrize("name", ["field", "complex"])
def test_the_maps_optima_agree_with_networkx(name):
    chosen = iwd_pg_map(name)
    want = networkx_length(chosen.obstacles, chosen.start, chosen.goal)
    assert OPTIMA[name] == pytest.approx(want, rel=1e-12)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    assert float(dijkstra(graph, task.start, task.goal).cost) == pytest.approx(want, rel=1e-6)
    assert not chosen.obstacles.flags.writeable


def test_an_unknown_map_is_named():
    with pytest.raises(ValueError, match="unknown IWD_PG map 'spset07'"):
        iwd_pg_map("spset07")
