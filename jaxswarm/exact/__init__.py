"""Exact planners: Dijkstra, A*, bidirectional A* and its balanced variant (compiled, with
search statistics), D* Lite (:func:`replanner`), batches of queries (:func:`shortest_lengths`),
the optimum measured as the swarms measure their paths (:func:`optimal_length`) and the batched
JAX distance field. The readable heapq versions of the one-shot planners are
:mod:`jaxswarm.exact.reference`."""
from jaxswarm.exact import reference
from jaxswarm.exact.astar import astar, balanced_bidirectional_astar, bidirectional_astar
from jaxswarm.exact.batch import Lengths, shortest_lengths
from jaxswarm.exact.dijkstra import dijkstra, optimal_length
from jaxswarm.exact.dstar_lite import DStarLite, replanner
from jaxswarm.exact.field import distance_field, optimum
from jaxswarm.exact.stats import SearchStats
from jaxswarm.exact.warm import warm_up

__all__ = ["DStarLite", "Lengths", "SearchStats", "astar", "balanced_bidirectional_astar",
           "bidirectional_astar", "dijkstra", "distance_field", "optimal_length", "optimum",
           "reference", "replanner", "shortest_lengths", "warm_up"]
