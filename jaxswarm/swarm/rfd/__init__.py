"""River Formation Dynamics: the RFD paper's ``rfd`` and ``rfd_star`` (:mod:`.paper`), and this
project's ``rfd_graded`` (:mod:`.graded`), over a shared altitude memory (:mod:`.river`)."""
from jaxswarm.swarm.rfd.alleys import blind_alleys
from jaxswarm.swarm.rfd.graded import (DEFAULT_GRADED, GradedConfig, GradedParams, carve,
                                       erode_banks, graded_transition, settle)
from jaxswarm.swarm.rfd.paper import (DEFAULT_RFD, DEFAULT_RFD_STAR, EROSION_LAWS, EROSION_PATHS,
                                      RFDConfig, RFDParams, RFDStarConfig, RFDStarParams,
                                      erosion_change, rfd_star_transition, rfd_transition)
from jaxswarm.swarm.rfd.river import RFDState, add_compensated

__all__ = ["DEFAULT_GRADED", "DEFAULT_RFD", "DEFAULT_RFD_STAR", "EROSION_LAWS", "EROSION_PATHS",
           "GradedConfig", "GradedParams", "RFDConfig", "RFDParams", "RFDStarConfig",
           "RFDStarParams", "RFDState", "add_compensated", "blind_alleys", "carve", "erode_banks",
           "erosion_change", "graded_transition", "rfd_star_transition", "rfd_transition",
           "settle"]
