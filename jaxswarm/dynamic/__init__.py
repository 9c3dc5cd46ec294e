"""Worlds that change during a run: events and what a swarm's memory does about them
(:mod:`~jaxswarm.dynamic.events`), the RFD paper's dynamic scenarios, Tables 2-5
(:mod:`~jaxswarm.dynamic.scenarios`), and a robot that re-plans where it finds a blocked path
(:mod:`~jaxswarm.dynamic.robot`).
"""
