"""Figures and animations, one module per world or subject: :mod:`~jaxswarm.plot.graph`
(maps, paths, memory fields, convergence; the PNG and GIF writers),
:mod:`~jaxswarm.plot.memory` (how each swarm's memory is drawn, and its frames over iterations),
:mod:`~jaxswarm.plot.plane` (planes and trajectories), :mod:`~jaxswarm.plot.robot` (a robot's
walk), :mod:`~jaxswarm.plot.agents` (multi-agent plans) and :mod:`~jaxswarm.plot.sweep`
(a sweep's results).
"""
