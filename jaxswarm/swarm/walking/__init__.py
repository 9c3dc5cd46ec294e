"""The walker shared by every swarm: the loop of queued agents over busy lanes (:mod:`.loop`),
one lockstep step of the lanes (:mod:`.lanes`), its random streams (:mod:`.streams`), the masked
sampler (:mod:`.sampler`), packed visited sets (:mod:`.bits`), what algorithms hand it
(:mod:`.tables`: edge tables, safe neighbour gathers and values, the goal heuristic, the step
budget), the per-step hook for memory that changes while the agents walk (:mod:`.hooks`), the
journal the lanes write their moves to (:mod:`.journal`), a walk's moves as they were made
(:mod:`.log`), and work on them cut to the moves the batch made (:mod:`.moves`)."""
from jaxswarm.swarm.walking.hooks import EdgeGroups, Move, StepHook, edge_groups
from jaxswarm.swarm.walking.loop import (AGENTS_PER_LANE, COMPACT_SHARE, FEWEST_LANES, LANES,
                                         SMALLEST_COMPACTION, STEPS_PER_REFILL, Walk,
                                         lanes_for, visited_nodes, walk)
from jaxswarm.swarm.walking.log import MoveLog
from jaxswarm.swarm.walking.options import EVERY_MOVE, WalkerOptions
from jaxswarm.swarm.walking.moves import (fold_agents, fold_blocks_backwards, move_widths,
                                          on_moves, on_walk)
from jaxswarm.swarm.walking.sampler import FORCED, sample_masked
from jaxswarm.swarm.walking.streams import uniforms
from jaxswarm.swarm.walking.tables import (edge_table, goal_log_distance, heads,
                                           neighbour_slots, step_budget)

__all__ = ["AGENTS_PER_LANE", "COMPACT_SHARE", "EVERY_MOVE", "EdgeGroups", "FEWEST_LANES",
           "FORCED", "LANES", "Move", "MoveLog", "SMALLEST_COMPACTION", "STEPS_PER_REFILL",
           "StepHook", "Walk", "WalkerOptions", "edge_groups", "edge_table", "fold_agents",
           "fold_blocks_backwards", "goal_log_distance", "heads", "lanes_for", "move_widths",
           "neighbour_slots", "on_moves", "on_walk", "sample_masked", "step_budget", "uniforms",
           "visited_nodes", "walk"]
