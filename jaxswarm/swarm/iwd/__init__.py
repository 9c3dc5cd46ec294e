"""Intelligent Water Drops on the shared walker: the equations and the walker hook through which
the drops change the soil as they walk (:mod:`.soil`), the swarm (:mod:`.iwd`), and IWD_PG
(:mod:`.iwd_pg`) with its stages: the smooth operator (:mod:`.smooth`), the memory and path
surgery (:mod:`.memory`), the intersection operators (:mod:`.intersect`), local search
(:mod:`.local`) and the fuzzy section scores (:mod:`.fuzzy`)."""
from jaxswarm.swarm.iwd.iwd import (DEFAULT_IWD, STANDARD_IWD, IWDConfig, IWDParams, IWDState,
                                    build_iwd)
from jaxswarm.swarm.iwd.soil import SOIL, global_update, soil_taken, velocity_after

__all__ = ["DEFAULT_IWD", "IWDConfig", "IWDParams", "IWDState", "SOIL", "STANDARD_IWD",
           "build_iwd", "global_update", "soil_taken", "velocity_after"]
