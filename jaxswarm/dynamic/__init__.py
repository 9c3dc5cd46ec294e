"""Worlds that change during a run: events and what a swarm's memory does about them
(:mod:`~jaxswarm.dynamic.events`), the RFD paper's dynamic scenarios, Tables 2-5
(:mod:`~jaxswarm.dynamic.scenarios`), and a robot that re-plans where it finds a blocked path
(:mod:`~jaxswarm.dynamic.robot`).

Until 0.6.0 the names of 0.4.0's ``jaxswarm.dynamic`` module are found here too, with a
``DeprecationWarning``: import them from :mod:`jaxswarm.dynamic.events`.
"""
from jaxswarm.runtime.moved import forwarder

__getattr__ = forwarder(__name__, "jaxswarm.dynamic.events")
