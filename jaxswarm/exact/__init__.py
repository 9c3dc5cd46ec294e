"""Exact planners: Dijkstra, A*, bidirectional A* (host, instrumented) and the batched JAX
distance field used as the optimum inside vmapped sweeps."""
from jaxswarm.exact.astar import astar, bidirectional_astar
from jaxswarm.exact.dijkstra import dijkstra
from jaxswarm.exact.field import distance_field, optimum
from jaxswarm.exact.stats import SearchStats

__all__ = ["astar", "bidirectional_astar", "dijkstra", "distance_field", "optimum", "SearchStats"]
