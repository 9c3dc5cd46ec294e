"""Many agents on one map: the A* report's two-robot scheme, prioritised space-time A*,
Conflict-Based Search, PIBT and LaCAM, with one solution format and one validator.

* :func:`report_scheme` (:mod:`~jaxswarm.multiagent.report`): A* per robot, then at a collision
  one robot side-steps while the other waits, or one moves first (the report's section 5).
* :func:`prioritized` (:mod:`~jaxswarm.multiagent.prioritized`): space-time A* per agent around a
  reservation table, in a given, distance or seeded random order.
* :func:`cbs` (:mod:`~jaxswarm.multiagent.cbs`): Conflict-Based Search, optimal sum of costs;
  ``prioritize`` and ``bypass`` switch on Boyarski et al.'s improvements, ``avoid`` the
  conflict avoidance table's tie-break (``"icbs"`` in ``PLANNERS``: all three), with MDDs from
  :mod:`~jaxswarm.multiagent.mdd`; ``wdg`` the weighted dependency graph heuristic
  (:mod:`~jaxswarm.multiagent.dependency`; ``"cbsh"``: all four), ``target``, ``corridor`` and
  ``rectangle`` the symmetry reasoning of :mod:`~jaxswarm.multiagent.constraints`,
  :mod:`~jaxswarm.multiagent.corridor` and :mod:`~jaxswarm.multiagent.rectangle`
  (``"cbsh_tc"``: the first six, ``"cbsh_rtc"``: all seven).
* :func:`ecbs` and :func:`eecbs` (:mod:`~jaxswarm.multiagent.ecbs`): Enhanced CBS and Explicit
  Estimation CBS, within a factor ``w`` of the optimum.
* :func:`pibt` (:mod:`~jaxswarm.multiagent.pibt`): priority inheritance with backtracking, one
  step for all agents at a time; fast, incomplete.
* :func:`lacam` (:mod:`~jaxswarm.multiagent.lacam`): LaCAM, a complete search over
  configurations with PIBT as its generator, and LaCAM*'s generator (``swap``; ``"lacam_star"``
  in ``PLANNERS``) and anytime refinement (``refine``).
* :func:`validate` (:mod:`~jaxswarm.multiagent.validate`) checks any solution;
  :func:`find_conflicts` (:mod:`~jaxswarm.multiagent.conflicts`) is its batched JAX conflict
  check; :class:`Plan` (:mod:`~jaxswarm.multiagent.plan`) is the one result format.

Time is in steps: every agent moves along one edge or waits per step, and an agent's cost is the
step from which it stays at its goal. On the MAPF benchmark maps (:func:`load_instance`, loaded
4-connected) that is the benchmark's sum of costs.
"""
import functools

from jaxswarm.multiagent.agents import (UNREACHABLE, Instance, agent_nodes, hop_fields,
                                        load_instance, lower_bound)
from jaxswarm.multiagent.cbs import cbs
from jaxswarm.multiagent.conflicts import Conflicts, find_conflicts
from jaxswarm.multiagent.ecbs import ecbs, eecbs
from jaxswarm.multiagent.lacam import lacam
from jaxswarm.multiagent.pibt import pibt
from jaxswarm.multiagent.plan import Plan, arrival_steps, pack
from jaxswarm.multiagent.prioritized import ORDERS, prioritized
from jaxswarm.multiagent.report import report_scheme
from jaxswarm.multiagent.validate import Violation, validate

PLANNERS = {"report": report_scheme, "prioritized": prioritized, "cbs": cbs,
            "icbs": functools.partial(cbs, prioritize=True, bypass=True, avoid=True),
            "cbsh": functools.partial(cbs, prioritize=True, bypass=True, avoid=True, wdg=True),
            "cbsh_tc": functools.partial(cbs, prioritize=True, bypass=True, avoid=True, wdg=True,
                                         target=True, corridor=True),
            "cbsh_rtc": functools.partial(cbs, prioritize=True, bypass=True, avoid=True, wdg=True,
                                          target=True, corridor=True, rectangle=True),
            "ecbs": ecbs, "eecbs": eecbs, "pibt": pibt, "lacam": lacam,
            "lacam_star": functools.partial(lacam, swap=True)}
"""The planners by name (as the ``jaxswarm mapf`` command and the study call them)."""

__all__ = ["Conflicts", "Instance", "ORDERS", "PLANNERS", "Plan", "UNREACHABLE", "Violation",
           "agent_nodes", "arrival_steps", "cbs", "ecbs", "eecbs", "find_conflicts", "hop_fields",
           "lacam", "load_instance", "lower_bound", "pack", "pibt", "prioritized",
           "report_scheme", "validate"]
