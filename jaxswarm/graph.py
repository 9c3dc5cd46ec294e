"""Deprecated: the graph moved to :mod:`jaxswarm.world.graph` in 0.5.0 (this module goes in
0.6.0)."""
from jaxswarm.runtime.moved import forwarder, warn_module

warn_module(__name__, "jaxswarm.world.graph")
__getattr__ = forwarder(__name__, "jaxswarm.world.graph")
