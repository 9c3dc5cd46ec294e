"""Maps named by a word: what a ``--map`` option or a study's ``--maps`` list may name, as the map
entry (:mod:`jaxswarm.maps.entry`) that builds it.

Three kinds of name:

* a paper map (:data:`~jaxswarm.maps.paper.PAPER_MAPS`, e.g. ``maze20``), with the paper's start
  and goal;
* ``pathmapWxH`` (e.g. ``pathmap20x20``): a random thin-wall path map of W x H cells
  (:func:`~jaxswarm.maps.random.random_path_map`, seeded), from the top-left cell to the
  bottom-right one;
* a Moving AI ``.map`` file (:func:`~jaxswarm.maps.movingai.load_map`), whose start and goal must
  be given.

The error messages name the command-line options the names usually come from (``--map``,
``--start``, ``--goal``).
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import NamedTuple

from jaxswarm.maps.entry import PATH_MAP_SIZE, resolve
from jaxswarm.maps.paper import PAPER_MAPS
from jaxswarm.world.graph import Graph

PAPER = "paper map"
"""The kind of a paper map's name."""
PATH_MAP = "path map"
"""The kind of a ``pathmapWxH`` name."""
MAP_FILE = "map file"
"""The kind of a Moving AI ``.map`` file's name."""
PATH_MAP_NAME = re.compile("pathmap" + PATH_MAP_SIZE.pattern)
"""A path map's name; its groups are the width and the height in cells."""


class NamedMap(NamedTuple):
    """A named map resolved: its label, graph and query.

    Attributes:
      label: the name shown in tables (the name itself; a ``.map`` file's stem).
      graph: the map's Graph.
      start, goal: (x, y) cells.
    """

    label: str
    graph: Graph
    start: tuple[int, int]
    goal: tuple[int, int]


def map_kind(name: str) -> str | None:
    """The kind of map ``name`` names: :data:`PAPER`, :data:`PATH_MAP` or :data:`MAP_FILE`;
    None when it names none (files are not looked up here)."""
    if name in PAPER_MAPS:
        return PAPER
    if PATH_MAP_NAME.fullmatch(name):
        return PATH_MAP
    if name.endswith(".map"):
        return MAP_FILE
    return None


def named_entry(name: str, *, seed: int = 0, start: tuple[int, int] | None = None,
                goal: tuple[int, int] | None = None) -> str | dict:
    """The map entry (:mod:`jaxswarm.maps.entry`) of the map ``name`` names.

    Args:
      name: a paper map, ``pathmapWxH`` or the path of a Moving AI ``.map`` file.
      seed: the seed of a path map's random walls (unused by the other kinds).
      start, goal: (x, y) cells; required with a ``.map`` file (they go into its entry).

    Raises:
      ValueError: an unknown name, a missing ``.map`` file, or a ``.map`` file without a start
        and a goal.
    """
    kind = map_kind(name)
    if kind == PAPER:
        return name
    if kind == PATH_MAP:
        return dict(pathmap=name.removeprefix("pathmap"), seed=seed)
    if kind == MAP_FILE:
        if start is None or goal is None:
            raise ValueError("--start and --goal are required with a .map file")
        if not Path(name).is_file():
            raise ValueError(f"--map {name}: no such file")
        return dict(movingai=str(Path(name).absolute()), start=list(start), goal=list(goal))
    raise ValueError(f"--map must be one of {', '.join(PAPER_MAPS)}, pathmapWxH or a .map "
                     f"file, got {name!r}")


def named_map(name: str, *, seed: int = 0, start: tuple[int, int] | None = None,
              goal: tuple[int, int] | None = None) -> NamedMap:
    """The map ``name`` names (see the module docstring), built afresh by
    :func:`jaxswarm.maps.entry.resolve` from its :func:`named_entry`.

    Args:
      name: a paper map, ``pathmapWxH`` or the path of a Moving AI ``.map`` file.
      seed: the seed of a path map's random walls (unused by the other kinds).
      start, goal: (x, y) cells replacing the map's own; required with a ``.map`` file.

    Raises:
      ValueError: an unknown name, a missing ``.map`` file, a ``.map`` file without a start
        and a goal, or a start or goal off the map or blocked.
    """
    resolved = resolve(named_entry(name, seed=seed, start=start, goal=goal), start=start,
                       goal=goal)
    return NamedMap(named_label(name), resolved.world, resolved.start, resolved.goal)


def named_label(name: str) -> str:
    """The label tables and figures show for the map ``name``: the name, a ``.map`` file's
    stem."""
    return Path(name).stem if map_kind(name) == MAP_FILE else name
