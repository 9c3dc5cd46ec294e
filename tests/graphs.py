"""Random test maps shared by the exact-planner tests."""
import numpy as np

from jaxswarm.graph import dense_graph


def geometric_graph(rng, n: int, *, radius: float, density: float, stretch: tuple[float, float]):
    """A directed graph of ``n`` random points in a 10 x 10 square: an edge between two points
    closer than ``radius`` with probability ``density``, its weight the distance times a factor
    drawn from ``stretch`` (at least 1, so the Euclidean heuristic is admissible)."""
    xy = rng.uniform(0, 10, (n, 2))
    span = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
    weights = np.where((span < radius) & (rng.random((n, n)) < density),
                       span * rng.uniform(*stretch, (n, n)), 0.0)
    return dense_graph(weights, xy=xy)
