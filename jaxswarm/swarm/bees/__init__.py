"""Bees: the constrained ABC local planner of the bees paper (``cabc``): a vehicle in a plane of
rectangles (:mod:`jaxswarm.world.plane`) steered, step by step, by a bee colony (:mod:`.colony`)
that minimises the guided function (:mod:`.guided`) inside its sensor window (:mod:`.cabc`)."""
from jaxswarm.swarm.bees.cabc import CABCConfig, CABCParams, CABCState, build_cabc

__all__ = ["CABCConfig", "CABCParams", "CABCState", "build_cabc"]
