"""Deprecated: split in 0.5.0 into :mod:`jaxswarm.world.plane` (the Plane and its geometry),
:mod:`jaxswarm.maps.planes` (the paper's and random planes) and
:mod:`jaxswarm.exact.visibility` (the exact planner); this module goes in 0.6.0."""
from jaxswarm.runtime.moved import forwarder, warn_module

warn_module(__name__, "jaxswarm.world.plane, jaxswarm.maps.planes and jaxswarm.exact.visibility")
__getattr__ = forwarder(__name__, {
    **dict.fromkeys(["Plane", "make_plane", "violations", "crossings", "in_plane",
                     "trajectory_length", "check_point"], "jaxswarm.world.plane"),
    **dict.fromkeys(["PlaneMap", "PLANE_CAPACITY", "PAPER_PLANES", "paper_plane",
                     "RANDOM_RECTANGLES", "random_plane"], "jaxswarm.maps.planes"),
    "shortest_path": "jaxswarm.exact.visibility"})
