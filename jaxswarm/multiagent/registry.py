"""The registry of multi-agent planners: each name, its Config, the function that plans, and what
tables and figures say of it.

A registered name is a paper's algorithm; a variant (``icbs``, ``lacam_star``) is an entry whose
``fixed`` options switch on the paper's improvements, options its user cannot pass.
``make_planner(name, **options)`` checks the option names (an unknown one: the message lists the
planner's), their types against the Config's annotations and their ranges by building the Config
(whose defaults are the only ones), all before any search. ``register(name, entry)`` adds a
planner; the ``jaxswarm mapf`` command, the MAPF study and the notebook read this registry.
"""
from __future__ import annotations

import dataclasses
import functools
import types
import typing
from collections.abc import Callable, Mapping
from typing import NamedTuple

from jaxswarm.multiagent.cbs import CBSConfig, cbs
from jaxswarm.multiagent.ecbs import ECBSConfig, ecbs, eecbs
from jaxswarm.multiagent.lacam import LaCAMConfig, lacam
from jaxswarm.multiagent.limits import OptionError
from jaxswarm.multiagent.pibt import PIBTConfig, pibt
from jaxswarm.multiagent.plan import Plan
from jaxswarm.multiagent.prioritized import PrioritizedConfig, prioritized
from jaxswarm.multiagent.report import ReportConfig, report_scheme
from jaxswarm.runtime.options import check_new_entry, typed_option
from jaxswarm.world.graph import Graph


class Style(NamedTuple):
    """How a planner's line is drawn in figures: a matplotlib ``marker`` and ``linestyle``."""

    marker: str
    linestyle: str


class Entry(NamedTuple):
    """One registered planner.

    Attributes:
      config: its Config class, a frozen dataclass whose fields are the planner's options with
        their defaults and whose construction checks them (TypeError or ValueError naming the
        option).
      plan: ``(graph, starts, goals, **options) -> Plan``, the options those of ``config``.
      label: its name in tables and figures.
      source: the paper it implements, and where it departs from it.
      faithful: the paper's algorithm as written (False: with departures of this project).
      style: its line in figures.
      fixed: options the entry sets and its user cannot (the switches of a variant).
      guarantee: ``"optimal"`` (least sum of costs when solved), ``"bounded"`` (within the
        option ``w`` of it) or ``""`` (none).
    """

    config: type
    plan: Callable[..., Plan]
    label: str
    source: str
    faithful: bool
    style: Style
    fixed: Mapping[str, object] = types.MappingProxyType({})
    guarantee: str = ""


_ICBS = dict(prioritize=True, bypass=True, avoid=True)
_CBSH = dict(_ICBS, wdg=True)
_CBS_OFF = dict.fromkeys(("prioritize", "bypass", "avoid", "wdg", "target", "corridor",
                          "rectangle"), False)


def _cbs_entry(label: str, source: str, faithful: bool, style: Style, **switches) -> Entry:
    """An entry of :func:`cbs` with ``switches`` on and the others off, all fixed."""
    return Entry(CBSConfig, cbs, label, source, faithful, style,
                 types.MappingProxyType(dict(_CBS_OFF, **switches)), "optimal")


REGISTRY: dict[str, Entry] = {
    "report": Entry(ReportConfig, report_scheme, "report's scheme",
                    "the A* report, section 5 (two robots; pairwise for more: jaxswarm's)",
                    True, Style("o", "-")),
    "prioritized": Entry(PrioritizedConfig, prioritized, "prioritized",
                         "Silver, AIIDE 2005: space-time A* around a reservation table", True,
                         Style("s", "-")),
    "cbs": _cbs_entry("CBS", "Sharon et al., AIJ 2015", True, Style("v", "-")),
    "icbs": _cbs_entry("ICBS", "Boyarski et al., IJCAI 2015: prioritised conflicts and "
                       "bypassing, without meta-agents; a conflict avoidance table", False,
                       Style("P", "-"), **_ICBS),
    "cbsh": _cbs_entry("CBSH", "Li et al., IJCAI 2019: ICBS with the WDG heuristic "
                       "(jaxswarm's tie-break by its weights)", False, Style("x", "--"),
                       **_CBSH),
    "cbsh_tc": _cbs_entry("CBSH-TC", "Li et al., ICAPS 2020: CBSH with target and corridor "
                          "reasoning (jaxswarm's tie-break)", False, Style("*", "--"),
                          **_CBSH, target=True, corridor=True),
    "cbsh_rtc": _cbs_entry("CBSH-RTC", "Li et al., AIJ 2021: CBSH-TC with rectangle "
                           "reasoning (barriers timed by static distances)", False,
                           Style("X", ":"), **_CBSH, target=True, corridor=True,
                           rectangle=True),
    "ecbs": Entry(ECBSConfig, ecbs, "ECBS", "Barer et al., SoCS 2014", True, Style("h", "-"),
                  guarantee="bounded"),
    "eecbs": Entry(ECBSConfig, eecbs, "EECBS", "Li et al., AAAI 2021, without its CBS "
                   "improvements", False, Style("d", "-"), guarantee="bounded"),
    "pibt": Entry(PIBTConfig, pibt, "PIBT", "Okumura et al., AIJ 2022", True, Style("<", "--")),
    "lacam": Entry(LaCAMConfig, lacam, "LaCAM", "Okumura, AAAI 2023", True, Style(">", ":"),
                   types.MappingProxyType({"swap": False})),
    "lacam_star": Entry(LaCAMConfig, lacam, "LaCAM* (swap)",
                        "Okumura, IJCAI 2023: LaCAM with PIBT's swap (refine: its anytime "
                        "refinement)", True, Style("p", "-"),
                        types.MappingProxyType({"swap": True})),
}
"""Registered name -> :class:`Entry`, in the order tables list them."""


def register(name: str, entry: Entry) -> None:
    """Add the planner ``entry`` as ``name``: the ``jaxswarm mapf`` command, the MAPF study and
    :func:`make_planner` offer it from then on.

    Raises:
      TypeError: ``entry`` is not an :class:`Entry`, or its config is not a dataclass.
      ValueError: ``name`` is taken, or ``fixed`` names an option the config does not have.
    """
    check_new_entry(REGISTRY, name, entry, Entry, "planner")
    fields = {field.name for field in dataclasses.fields(entry.config)}
    if set(entry.fixed) - fields:
        raise ValueError(f"fixed options {sorted(set(entry.fixed) - fields)} of {name!r} are "
                         f"not fields of {entry.config.__name__}")
    REGISTRY[name] = entry


def registered() -> tuple[str, ...]:
    """The registered planners' names, in the order tables list them."""
    return tuple(REGISTRY)


def entry(name: str) -> Entry:
    """The registry entry of ``name``.

    Raises:
      ValueError: unknown name (the message lists the registered ones).
    """
    if name not in REGISTRY:
        raise ValueError(f"unknown planner {name!r}; registered: {', '.join(REGISTRY)}")
    return REGISTRY[name]


def options(name: str) -> tuple[str, ...]:
    """The options a user may give the planner ``name``: its Config's fields less those the
    entry fixes."""
    found = entry(name)
    return tuple(field.name for field in dataclasses.fields(found.config)
                 if field.name not in found.fixed)


def config(name: str, **given):
    """The Config of the planner ``name`` with the options ``given`` (and the entry's fixed
    ones), checked.

    Raises:
      ValueError: unknown name, unknown or fixed option (listing the planner's options), or a
        value out of range (:class:`~jaxswarm.multiagent.limits.OptionError` where the Config
        raises one), naming the planner and the option.
      TypeError: a value of the wrong type, naming the planner and the option.
    """
    known = options(name)
    fixed = entry(name).fixed
    for option in given:
        if option in fixed:
            raise ValueError(f"{option} of {name} is fixed ({fixed[option]!r}); its options: "
                             f"{', '.join(known)}")
        if option not in known:
            raise ValueError(f"unknown option {option!r} of {name}; its options: "
                             f"{', '.join(known) or 'none'}")
    kinds = typing.get_type_hints(entry(name).config)
    checked = {option: typed_option(name, option, kinds[option], value)
               for option, value in given.items()}
    try:
        return entry(name).config(**checked, **fixed)
    except OptionError as error:
        raise OptionError(error.option, f"{error.problem} (an option of {name})") from None
    except (TypeError, ValueError) as error:
        raise type(error)(f"{error} (an option of {name})") from None


def make_planner(name: str, **given) -> Callable[[Graph, object, object], Plan]:
    """The planner ``name`` with the options ``given``: ``(graph, starts, goals) -> Plan``.

    The options are checked now, before any instance (see
    :func:`~jaxswarm.multiagent.registry.config`, which raises).
    """
    checked = config(name, **given)
    return functools.partial(entry(name).plan, **{field.name: getattr(checked, field.name)
                                                  for field in dataclasses.fields(checked)})


def plan(name: str, graph: Graph, starts, goals, **given) -> Plan:
    """The :class:`~jaxswarm.multiagent.plan.Plan` of the planner ``name`` with the options
    ``given`` for the agents' ``starts`` and ``goals`` ((x, y) cells or node indices, one per
    agent) on ``graph``; its options are checked before any search (see :func:`config`)."""
    return make_planner(name, **given)(graph, starts, goals)


def planner_functions() -> dict[str, Callable[..., Plan]]:
    """Name -> ``(graph, starts, goals, **options) -> Plan`` with the entry's fixed options
    set (the deprecated ``jaxswarm.multiagent.PLANNERS``)."""
    return {name: functools.partial(found.plan, **found.fixed) if found.fixed else found.plan
            for name, found in REGISTRY.items()}
