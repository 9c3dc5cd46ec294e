"""Many agents on one map, with one solution format (:class:`Plan`) and one validator.

* :func:`report_scheme`: the A* report's two-robot scheme (its section 5).
* :func:`prioritized`: space-time A* per agent around a reservation table, in a given, distance
  or seeded random order.
* :func:`cbs` (:mod:`~jaxswarm.multiagent.cbs`): Conflict-Based Search, optimal sum of costs,
  with its papers' improvements as switches; :func:`ecbs` and :func:`eecbs`
  (:mod:`~jaxswarm.multiagent.ecbs`): within a factor ``w`` of the optimum.
* :func:`pibt`: one step for all agents at a time, fast and incomplete; :func:`lacam`
  (:mod:`~jaxswarm.multiagent.lacam`): complete, with LaCAM*'s ``swap`` and ``refine``.
* :mod:`~jaxswarm.multiagent.registry`: the planners by name, each with its Config, label, paper
  and figure style (:func:`make_planner`), as the ``jaxswarm mapf`` command and the study read it.
* :func:`validate` checks any solution; :func:`find_conflicts` is its batched JAX conflict check.

Time is in steps: every agent moves along one edge or waits per step, and an agent's cost is the
step from which it stays at its goal; on the MAPF benchmark maps (:func:`load_instance`, loaded
4-connected) that is the benchmark's sum of costs.
"""
import warnings

from jaxswarm.multiagent.agents import (UNREACHABLE, Instance, agent_nodes, hop_fields,
                                        load_instance, lower_bound)
from jaxswarm.multiagent.cbs import cbs
from jaxswarm.multiagent.conflicts import Conflicts, find_conflicts
from jaxswarm.multiagent.ecbs import ecbs, eecbs
from jaxswarm.multiagent.lacam import lacam
from jaxswarm.multiagent.pibt import pibt
from jaxswarm.multiagent.plan import Plan, arrival_steps, pack
from jaxswarm.multiagent.prioritized import ORDERS, prioritized
from jaxswarm.multiagent.registry import make_planner
from jaxswarm.multiagent.report import report_scheme
from jaxswarm.multiagent.validate import Violation, validate


def __getattr__(name: str):
    """``PLANNERS``, deprecated: name -> planner function with its variant's switches set, as
    :func:`jaxswarm.multiagent.registry.planner_functions` gives it."""
    if name == "PLANNERS":
        warnings.warn("jaxswarm.multiagent.PLANNERS is deprecated since jaxswarm 0.11.0 and "
                      "goes in 0.12.0; use jaxswarm.multiagent.registry (make_planner, registered, "
                      "entry)", DeprecationWarning, stacklevel=2)
        from jaxswarm.multiagent.registry import planner_functions

        return planner_functions()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["Conflicts", "Instance", "ORDERS", "Plan", "UNREACHABLE", "Violation",
           "agent_nodes", "arrival_steps", "cbs", "ecbs", "eecbs", "find_conflicts", "hop_fields",
           "lacam", "load_instance", "lower_bound", "make_planner", "pack", "pibt",
           "prioritized", "report_scheme", "validate"]
