"""Exact planners: Dijkstra, A*, bidirectional A* (host, instrumented), the optimum measured as
the swarms measure their paths (``optimal_length``) and the batched JAX distance field."""
from jaxswarm.exact.astar import astar, bidirectional_astar
from jaxswarm.exact.dijkstra import dijkstra, optimal_length
from jaxswarm.exact.field import distance_field, optimum
from jaxswarm.exact.stats import SearchStats

__all__ = ["astar", "bidirectional_astar", "dijkstra", "distance_field", "optimal_length",
           "optimum", "SearchStats"]
