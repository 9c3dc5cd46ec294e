"""What each swarm's memory does when its world changes: the change rules, keyed by swarm name.

A rule is ``(state, before, after, old_task, new_task, params) -> State``: the memory of a run
on ``before`` for ``old_task`` adapted to ``after`` and ``new_task`` (jittable, shapes
unchanged). :func:`jaxswarm.dynamic.events.change` applies it; each family documents its own.
"""
from __future__ import annotations

import functools
from typing import Callable

from jaxswarm.swarm.aco import colony, improved
from jaxswarm.swarm.bees import cabc
from jaxswarm.swarm.core import Swarm
from jaxswarm.swarm.iwd import iwd, iwd_pg
from jaxswarm.swarm.rfd import graded, river

Rule = Callable
"""``(state, before, after, old_task, new_task, params) -> State``."""

CHANGE_RULES: dict[str, Callable[[object], Rule]] = {
    "rfd": lambda config: river.paper_altitude_rule,
    "rfd_star": lambda config: river.paper_altitude_rule,
    "rfd_graded": lambda config: graded.regrade,
    "ant_system": lambda config: colony.pheromone_rule,
    "aco_star": lambda config: colony.pheromone_rule,
    "max_min_aco": lambda config: colony.pheromone_rule,
    "improved_max_min_aco": improved.change_rule,
    "iwd": lambda config: iwd.soil_rule,
    "iwd_pg": lambda config: iwd_pg.change_rule,
    "cabc": lambda config: functools.partial(cabc.change_rule, config),
}
"""Swarm name -> ``(config) -> Rule``: its rule for the swarm built with ``config``. Add an entry
for a new swarm whose runs must go on after a change."""


def change_rule(swarm: Swarm) -> Rule:
    """``swarm``'s change rule (:data:`CHANGE_RULES`).

    Raises:
      ValueError: the swarm declares none; the message says where to add it.
    """
    if swarm.name not in CHANGE_RULES:
        raise ValueError(f"swarm {swarm.name!r} has no rule for a change of its world: add one "
                         "to jaxswarm.dynamic.rules.CHANGE_RULES")
    return CHANGE_RULES[swarm.name](swarm.config)
