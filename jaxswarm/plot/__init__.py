"""Figures and animations, one module per world or subject: :mod:`~jaxswarm.plot.graph`
(maps, paths, memory fields, convergence; the PNG and GIF writers),
:mod:`~jaxswarm.plot.plane` (planes and trajectories), :mod:`~jaxswarm.plot.robot` (a robot's
walk), :mod:`~jaxswarm.plot.agents` (multi-agent plans) and :mod:`~jaxswarm.plot.sweep`
(a sweep's results).

Until 0.6.0 the names of 0.4.0's ``jaxswarm.plot`` module are found here too, with a
``DeprecationWarning``: import them from :mod:`jaxswarm.plot.graph`.
"""
from jaxswarm.runtime.moved import forwarder

__getattr__ = forwarder(__name__, "jaxswarm.plot.graph")
