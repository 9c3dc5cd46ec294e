"""Ant colonies on the shared walker: the RFD paper's Ant System and ACO* (:mod:`.ant_system`),
the Max-Min ACO paper's Max-Min ACO (:mod:`.max_min`) and Improved Max-Min ACO (:mod:`.improved`,
with its first ant in :mod:`.bug2`), over the shared pheromone memory (:mod:`.colony`)."""
from jaxswarm.swarm.aco.ant_system import (DEFAULT_ACO_STAR, DEFAULT_ANT_SYSTEM, TAU_FLOOR,
                                           ACOStarParams, AntSystemParams)
from jaxswarm.swarm.aco.bug2 import bug2_path, direction_cosine, first_ant_path
from jaxswarm.swarm.aco.colony import (DIRECTION_FLOOR, ACOState, deposit, reinforce,
                                       transition_rule)
from jaxswarm.swarm.aco.improved import (DEFAULT_IMPROVED, FIRST_ANTS, ImprovedConfig,
                                         ImprovedParams)
from jaxswarm.swarm.aco.max_min import DEFAULT_MAX_MIN, MaxMinConfig, MaxMinParams

__all__ = ["ACOStarParams", "ACOState", "AntSystemParams", "DEFAULT_ACO_STAR",
           "DEFAULT_ANT_SYSTEM", "DEFAULT_IMPROVED", "DEFAULT_MAX_MIN", "DIRECTION_FLOOR",
           "FIRST_ANTS", "ImprovedConfig", "ImprovedParams", "MaxMinConfig", "MaxMinParams",
           "TAU_FLOOR", "bug2_path", "deposit", "direction_cosine", "first_ant_path", "reinforce",
           "transition_rule"]
