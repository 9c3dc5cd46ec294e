"""Deprecated: the re-planning robot moved to :mod:`jaxswarm.dynamic.robot` in 0.5.0 (this
module goes in 0.6.0)."""
from jaxswarm.runtime.moved import forwarder, warn_module

warn_module(__name__, "jaxswarm.dynamic.robot")
__getattr__ = forwarder(__name__, "jaxswarm.dynamic.robot")
