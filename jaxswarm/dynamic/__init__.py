"""Worlds that change during a run: events and what a swarm's memory does about them
(:mod:`~jaxswarm.dynamic.events`) and a robot that re-plans where it finds a blocked path
(:mod:`~jaxswarm.dynamic.robot`). The RFD paper's dynamic scenarios are
:mod:`jaxswarm.studies.rfd_dynamic` (:mod:`~jaxswarm.dynamic.scenarios`, their old path, is
deprecated).
"""
