"""The lockstep walker shared by every swarm: the loop (:mod:`.loop`), the masked sampler
(:mod:`.sampler`), packed visited sets (:mod:`.bits`) and what algorithms hand it (:mod:`.tables`:
edge tables, safe neighbour gathers, the goal heuristic, the step budget)."""
from jaxswarm.swarm.walking.loop import (AGENT_AXIS, COMPACT_SHARE, STEPS_PER_CHECK, Walk,
                                         check_devices, visited_nodes, walk)
from jaxswarm.swarm.walking.sampler import FORCED, sample_masked
from jaxswarm.swarm.walking.tables import edge_table, goal_log_distance, heads, step_budget

__all__ = ["AGENT_AXIS", "COMPACT_SHARE", "FORCED", "STEPS_PER_CHECK", "Walk", "check_devices",
           "edge_table", "goal_log_distance", "heads", "sample_masked", "step_budget",
           "visited_nodes", "walk"]
