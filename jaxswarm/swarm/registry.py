"""The registry of swarms: each name, its static Config and the function that builds it.

A registered name is a paper's algorithm as the paper writes it; an algorithm of this project is
registered under its own name (``rfd_graded``). ``make(name, **config)`` checks each option's
type against its Config field's annotation, then its range by building the Config (whose
defaults are the only ones), and equal Configs return the same Swarm, so they share compiled
code.
"""
from __future__ import annotations

import dataclasses
import functools
import typing
from typing import Callable, NamedTuple

import numpy as np

from jaxswarm.runtime.options import check_new_entry, typed_option
from jaxswarm.swarm.aco import ant_system, improved, max_min
from jaxswarm.swarm.bees import cabc
from jaxswarm.swarm.core import Swarm, SwarmConfig, WalkingConfig
from jaxswarm.swarm.iwd import iwd, iwd_pg
from jaxswarm.swarm.rfd import graded, paper


class Entry(NamedTuple):
    """One registered swarm.

    Attributes:
      config: its Config class (the options of ``make`` and their defaults).
      build: ``(config) -> Swarm``.
      label: its name in tables and figures.
      source: the paper and equations it implements, or ``"jaxswarm"`` for ours.
      faithful: the paper's algorithm as written (False: an algorithm of this project).
    """

    config: type
    build: Callable[..., Swarm]
    label: str
    source: str
    faithful: bool = True


REGISTRY: dict[str, Entry] = {
    "rfd": Entry(WalkingConfig, paper.build_rfd, "RFD", "RFD paper, eqs. 1-5"),
    "rfd_star": Entry(paper.RFDStarConfig, paper.build_rfd_star, "RFD*",
                      "RFD paper, eq. 6 with eqs. 4-5"),
    "rfd_graded": Entry(graded.GradedConfig, graded.build_rfd_graded, "RFD graded",
                        "jaxswarm: RFD*'s eq. 6 over a graded river bed", faithful=False),
    "ant_system": Entry(WalkingConfig, ant_system.build_ant_system, "Ant System",
                        "RFD paper, eqs. 7-9"),
    "aco_star": Entry(WalkingConfig, ant_system.build_aco_star, "ACO*",
                      "RFD paper, ACO*: eq. 7 over the goal distance"),
    "max_min_aco": Entry(max_min.MaxMinConfig, max_min.build_max_min_aco, "Max-Min ACO",
                         "Max-Min ACO paper, section 4"),
    "improved_max_min_aco": Entry(improved.ImprovedConfig, improved.build_improved_max_min_aco,
                                  "Improved Max-Min ACO", "Max-Min ACO paper, Algorithm 1"),
    "iwd": Entry(iwd.IWDConfig, iwd.build_iwd, "IWD",
                 "IWD_PG paper, eqs. 1-6 (Shah-Hosseini's IWD)"),
    "iwd_pg": Entry(iwd_pg.IWDPGConfig, iwd_pg.build_iwd_pg, "IWD_PG",
                    "IWD_PG paper: IWD with smoothing, memory, intersections, fuzzy local search"),
    "cabc": Entry(cabc.CABCConfig, cabc.build_cabc, "cABC",
                  "bees paper, eqs. 1-10: constrained ABC in the sensor window, on a plane"),
}
"""Registered name -> :class:`Entry`."""


def make(name: str, **config) -> Swarm:
    """The registered swarm ``name`` built with ``config`` (see its Config class for options).

    Raises:
      TypeError: an option of the wrong type (an integer option given 8.5 or "8"); the message
        names the swarm and the option.
      ValueError: unknown name (the message lists the registered ones), unknown option (the
        message lists the known ones) or a value out of range (naming the swarm and the
        option).
    """
    options = config_options(name)
    unknown = sorted(set(config) - set(options))
    if unknown:
        raise ValueError(f"unknown option {unknown[0]!r} of {name}; known: {', '.join(options)}")
    kinds = typing.get_type_hints(REGISTRY[name].config)
    checked = {option: typed_option(name, option, kinds[option], value)
               for option, value in config.items()}
    try:
        built = REGISTRY[name].config(**checked)
    except ValueError as error:
        raise ValueError(f"{error} (a config option of {name})") from None
    return _build(name, built)


@functools.lru_cache(maxsize=None)
def _build(name: str, config) -> Swarm:
    return REGISTRY[name].build(config)


def built_again(swarm: Swarm, config) -> Swarm:
    """The registered swarm ``swarm`` built with another ``config`` of its Config class (how
    the executor gives a swarm's walks more room).

    Raises:
      ValueError: ``swarm`` was not built by the registry.
    """
    if (swarm.name not in REGISTRY or type(swarm.config) is not REGISTRY[swarm.name].config
            or _build(swarm.name, swarm.config) is not swarm):
        raise ValueError(f"swarm {swarm.name!r} was not built by the registry, so it cannot be "
                         "built again with another config")
    return _build(swarm.name, config)


def register(name: str, entry: Entry) -> None:
    """Add the swarm ``entry`` as ``name``: :func:`make`, sweeps, tunes and the CLI offer it from
    then on. What else it offers is declared where it is used, under the same name (its memory's
    drawing, its change rule, its batch schedule; see :class:`~jaxswarm.swarm.core.Swarm`).

    Raises:
      TypeError: ``entry`` is not an :class:`Entry`, or its config is not a dataclass.
      ValueError: ``name`` is taken.
    """
    check_new_entry(REGISTRY, name, entry, Entry, "swarm")
    REGISTRY[name] = entry


def config_options(name: str) -> tuple[str, ...]:
    """The static options (Config fields) of the registered swarm ``name``."""
    return tuple(field.name for field in dataclasses.fields(entry(name).config))


def registered(world: type | None = None) -> tuple[str, ...]:
    """Names of the registered swarms, sorted; with ``world`` (:class:`~jaxswarm.world.graph.Graph` or
    :class:`~jaxswarm.world.plane.Plane`) only those that plan in that kind of world."""
    return tuple(name for name in sorted(REGISTRY)
                 if world is None or make(name).world is world)


def definition(swarm: Swarm) -> dict:
    """JSON-ready record of what a swarm is: its name, its Config
    (:func:`~jaxswarm.swarm.registry.config_record`) and every default param (what a results
    store compares before it resumes)."""
    return dict(name=swarm.name, config=config_record(swarm.config),
                default_params={k: float(np.asarray(v))
                                for k, v in swarm.default_params._asdict().items()})


def config_record(config: SwarmConfig) -> dict:
    """JSON-ready record of a swarm's Config: every field but a walking swarm's ``walker``
    options, which change no result."""
    record = dataclasses.asdict(config)
    record.pop("walker", None)
    return record


def entry(name: str) -> Entry:
    """The registry entry of ``name``.

    Raises:
      ValueError: unknown name (the message lists the registered ones).
    """
    if name not in REGISTRY:
        raise ValueError(f"unknown swarm {name!r}; registered: {', '.join(sorted(REGISTRY))}")
    return REGISTRY[name]
