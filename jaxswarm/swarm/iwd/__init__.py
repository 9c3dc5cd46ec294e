"""Intelligent Water Drops on the shared walker: the equations and the walker hook through which
the drops change the soil as they walk (:mod:`.soil`), and the swarm (:mod:`.iwd`)."""
from jaxswarm.swarm.iwd.iwd import DEFAULT_IWD, IWDConfig, IWDParams, IWDState, build_iwd
from jaxswarm.swarm.iwd.soil import SOIL, global_update, soil_taken, velocity_after

__all__ = ["DEFAULT_IWD", "IWDConfig", "IWDParams", "IWDState", "SOIL", "build_iwd",
           "global_update", "soil_taken", "velocity_after"]
