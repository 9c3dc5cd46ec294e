"""The walker shared by every swarm: the loop of queued agents over busy lanes (:mod:`.loop`),
its random streams (:mod:`.streams`), the masked sampler (:mod:`.sampler`), packed visited sets
(:mod:`.bits`) and what algorithms hand it (:mod:`.tables`: edge tables, safe neighbour gathers
and values, the goal heuristic, the step budget)."""
from jaxswarm.swarm.walking.loop import (COMPACT_SHARE, LANES, STEPS_PER_REFILL, Walk,
                                         visited_nodes, walk)
from jaxswarm.swarm.walking.sampler import FORCED, sample_masked
from jaxswarm.swarm.walking.streams import uniforms
from jaxswarm.swarm.walking.tables import (edge_table, goal_log_distance, heads,
                                           neighbour_slots, step_budget)

__all__ = ["COMPACT_SHARE", "FORCED", "LANES", "STEPS_PER_REFILL", "Walk", "edge_table",
           "goal_log_distance", "heads", "neighbour_slots", "sample_masked",
           "step_budget", "uniforms", "visited_nodes", "walk"]
