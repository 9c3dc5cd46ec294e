"""A map entry resolved in one place: what a sweep or tune spec, a study or the CLI names becomes
a world, a task and its optimum.

The entries (as a TOML spec writes them):

* a paper map's name, ``"mosaic50"``, with the paper's start and goal;
* a seeded random grid, ``{ random = 50, seed = 3, density = 0.3 }``, corner to corner;
* a seeded thin-wall path map, ``{ pathmap = "20x20", seed = 3 }``, top-left to bottom-right;
* a plane of the bees, ``{ plane = "map1" }`` (``map1``, ``map2``) or
  ``{ plane = "random", seed = 3, rectangles = 40 }``;
* a row of a Moving AI scenario file, ``{ movingai = "mapf/maze-32-32-2.map", scenario = 5 }``
  (row 5 counted from 0; ``scenario_file`` = ``"even"``, ``"random"`` or a file beside the map
  picks the file, else ``<map>.map.scen`` or ``<map>-even-1.scen``);
* a Moving AI map with a query of its own, ``{ movingai = "FILE.map", start = [x, y],
  goal = [x, y] }``.

A relative ``.map`` path is looked up in ``base_dir`` (a spec's folder), then in the folder that
``$JAXSWARM_MOVINGAI`` names.
"""
from __future__ import annotations

import dataclasses
import functools
import hashlib
import os
import re
from pathlib import Path

import jax

from jaxswarm.exact import optimal_length
from jaxswarm.exact.visibility import shortest_path
from jaxswarm.maps import movingai
from jaxswarm.maps.paper import PAPER_MAPS, paper_map
from jaxswarm.maps.planes import PAPER_PLANES, RANDOM_RECTANGLES, paper_plane, random_plane
from jaxswarm.maps.random import random_grid, random_path_map
from jaxswarm.swarm import Task, make_task
from jaxswarm.world.graph import Graph, grid_graph, path_map_graph
from jaxswarm.world.plane import Plane

KEYS = {"plane": {"plane", "seed", "rectangles"}, "random": {"random", "seed", "density"},
        "movingai": {"movingai", "scenario", "scenario_file", "start", "goal"},
        "pathmap": {"pathmap", "seed"}}
"""The keys of each kind of map table, by the key that names the kind (the first of them in a
table decides its kind)."""
DEFAULT_DENSITY = 0.3
"""A random grid's share of obstacles when its entry names none."""
PATH_MAP_SIZE = re.compile(r"(\d+)x(\d+)")
"""A path map's size, ``WxH``; its groups are the width and the height in cells."""
MOVINGAI_DATA = "JAXSWARM_MOVINGAI"
"""The environment variable naming the folder of Moving AI maps (relative entries are looked up
there after ``base_dir``)."""


@dataclasses.dataclass(frozen=True, eq=False)
class ResolvedMap:
    """A map entry resolved.

    Attributes:
      label: the name written in every results row (``mosaic50``, ``random50-s3``,
        ``pathmap20x20-s3``, ``map1``, ``plane-s3-r40``, ``maze-32-32-2#5``, ``maze-32-32-2``).
      world: the map's Graph, or a Plane.
      start, goal: (x, y) cells of a graph, (x, y) points of a plane.
      files: role (``map``, ``scenario``) -> ``(path, SHA-256 hex digest of the bytes read)``
        of each file the map was read from; empty for a map made from its entry alone.
    """

    label: str
    world: Graph | Plane
    start: tuple
    goal: tuple
    files: dict = dataclasses.field(default_factory=dict)

    @functools.cached_property
    def task(self) -> Task:
        """The swarms' Task (:func:`jaxswarm.swarm.make_task`): node indices i32[] of a graph,
        points f32[2] of a plane."""
        return make_task(self.world, self.start, self.goal)

    def optimum(self) -> float:
        """The optimal path length, measured as the swarms measure theirs: Dijkstra's path on a
        graph (:func:`jaxswarm.exact.optimal_length`), the visibility graph's shortest path on
        a plane (:func:`jaxswarm.exact.visibility.shortest_path`); inf when the goal cannot be
        reached."""
        if isinstance(self.world, Plane):
            return shortest_path(self.world, self.start, self.goal)[0]
        return optimal_length(self.world, self.start, self.goal)

    @property
    def size(self) -> str:
        """``WIDTHxHEIGHT`` of a grid or a plane ("" for a general graph)."""
        if isinstance(self.world, Plane):
            return "x".join(f"{float(v):g}" for v in jax.device_get(self.world.extent))
        return f"{self.world.shape[1]}x{self.world.shape[0]}" if self.world.shape else ""


def check(entry) -> str | None:
    """The problem with a map entry (naming the key at fault), or None if it is well formed.
    Files are looked up, and start and goal placed, by :func:`resolve`."""
    if isinstance(entry, str):
        # A bare name is a paper map: the other kinds need a seed, a row or a query.
        if entry not in PAPER_MAPS:
            return (f"unknown map {entry!r}; paper maps: {', '.join(PAPER_MAPS)} (or a table "
                    "{ random = SIZE, seed = S } / { movingai = FILE, scenario = ROW } / "
                    "{ plane = NAME } / { pathmap = WxH, seed = S })")
        return None
    if not isinstance(entry, dict):
        return f"a map is a paper map name or a table, got {entry!r}"
    kind = next((kind for kind in KEYS if kind in entry), None)
    if kind is None:
        return (f"a map table needs a 'random', 'movingai', 'plane' or 'pathmap' key, got "
                f"{sorted(entry)}")
    unknown = set(entry) - KEYS[kind]
    if unknown:
        what = {"random": "a random map", "pathmap": "a path map", "plane": "a plane",
                "movingai": "a Moving AI map"}[kind]
        return f"unknown keys {sorted(unknown)} for {what} ({', '.join(sorted(KEYS[kind]))})"
    return {"random": _check_random, "pathmap": _check_path_map, "plane": _check_plane,
            "movingai": _check_movingai}[kind](entry)


def world_kind(entry) -> type:
    """The kind of world a well-formed entry resolves to: Plane or Graph."""
    return Plane if isinstance(entry, dict) and "plane" in entry else Graph


def resolve(entry, *, base_dir: Path | None = None, start: tuple | None = None,
            goal: tuple | None = None) -> ResolvedMap:
    """The world, query and files of a map entry.

    Args:
      entry: an entry :func:`check` accepts (see the module docstring).
      base_dir: where a relative Moving AI path is looked up first (a spec's folder).
      start, goal: (x, y) replacing the entry's own (the CLI's ``--start``, ``--goal``).

    Returns:
      ResolvedMap whose start and goal are on the map and free (its ``task`` is built).

    Raises:
      ValueError: a malformed entry, a missing or malformed Moving AI file or scenario row, a
        start or goal off the map or blocked (naming which).
    """
    problem = check(entry)
    if problem:
        raise ValueError(problem)
    if isinstance(entry, str):
        chosen = paper_map(entry)
        resolved = ResolvedMap(entry, chosen.graph(), chosen.start, chosen.goal)
    elif "movingai" in entry:
        resolved = _movingai(entry, base_dir)
    else:
        resolved = {"random": _random, "pathmap": _path_map, "plane": _plane}[
            next(kind for kind in KEYS if kind in entry)](entry)
    if start is not None or goal is not None:
        resolved = dataclasses.replace(resolved, start=start or resolved.start,
                                       goal=goal or resolved.goal)
    resolved.task  # noqa: B018 (builds the task: a start or goal off the map or blocked is refused)
    return resolved


def _random(entry: dict) -> ResolvedMap:
    density = float(entry.get("density", DEFAULT_DENSITY))
    grid = random_grid(entry["random"], entry["seed"], density=density)
    label = f"random{entry['random']}-s{entry['seed']}"
    if "density" in entry:
        label += f"-d{density:g}"
    return ResolvedMap(label, grid_graph(grid.obstacles), grid.start, grid.goal)


def _path_map(entry: dict) -> ResolvedMap:
    width, height = _path_map_size(entry["pathmap"])
    graph = path_map_graph(random_path_map(width, height, entry["seed"]))
    return ResolvedMap(f"pathmap{entry['pathmap']}-s{entry['seed']}", graph, (0, 0),
                       (width - 1, height - 1))


def _plane(entry: dict) -> ResolvedMap:
    if entry["plane"] == "random":
        count = entry.get("rectangles", RANDOM_RECTANGLES)
        chosen = random_plane(jax.random.key(entry["seed"]), num_rectangles=count)
        return ResolvedMap(f"plane-s{entry['seed']}-r{count}", chosen.plane, chosen.start,
                           chosen.goal)
    chosen = paper_plane(entry["plane"])
    return ResolvedMap(chosen.label, chosen.plane, chosen.start, chosen.goal)


def _movingai(entry: dict, base_dir: Path | None) -> ResolvedMap:
    """A Moving AI map with a row of its scenario file, or with the entry's start and goal; its
    files' digests taken before and after they are parsed."""
    map_path = _find_movingai(entry["movingai"], base_dir)
    paths = {"map": map_path}
    if "scenario" in entry:
        paths["scenario"] = _scenario_file(map_path, entry.get("scenario_file"))
    digests = {role: _sha256(path) for role, path in paths.items()}
    obstacles = movingai.read_map(map_path)
    scenarios = movingai.load_scenarios(paths["scenario"]) if "scenario" in entry else None
    # The digests vouch for the map only if the files did not change while they were parsed.
    if {role: _sha256(path) for role, path in paths.items()} != digests:
        raise ValueError(f"{' or '.join(map(str, paths.values()))} changed while it was read; "
                         "try again")
    files = {role: (str(path), digests[role]) for role, path in paths.items()}
    if scenarios is None:
        return ResolvedMap(map_path.stem, grid_graph(obstacles), tuple(entry["start"]),
                           tuple(entry["goal"]), files)
    row = entry["scenario"]
    if row >= len(scenarios):
        raise ValueError(f"{paths['scenario']}: scenario {row} out of range "
                         f"({len(scenarios)} rows)")
    movingai.check_scenario(scenarios[row], obstacles, paths["scenario"])
    return ResolvedMap(f"{map_path.stem}#{row}", grid_graph(obstacles), scenarios[row].start,
                       scenarios[row].goal, files)


def _find_movingai(name: str, base_dir: Path | None) -> Path:
    """The ``.map`` file ``name``: absolute, else in ``base_dir``, then in
    ``$JAXSWARM_MOVINGAI`` (then in the working folder when there is no ``base_dir``)."""
    folder = os.environ.get(MOVINGAI_DATA)
    candidates = [Path(name)] if Path(name).is_absolute() else [
        *([base_dir / name] if base_dir else []), *([Path(folder) / name] if folder else []),
        *([] if base_dir else [Path(name)])]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    hint = "" if folder else f"; set {MOVINGAI_DATA} to the folder of the Moving AI maps"
    raise ValueError(f"Moving AI map {name!r} not found (looked in "
                     f"{', '.join(str(c) for c in candidates)}){hint}")


def _scenario_file(map_path: Path, choice: str | None) -> Path:
    """The scenario file of a map: ``choice`` "even" or "random" (the MAPF set's
    ``<stem>-even-1.scen``, ``<stem>-random-1.scen``), a file name beside the map, or by default
    ``<map>.scen``, else ``<stem>-even-1.scen``."""
    if choice in (None, "even", "random"):
        names = ([f"{map_path.name}.scen"] if choice is None else []) + [
            f"{map_path.stem}-{choice or 'even'}-1.scen"]
    else:
        names = [choice]
    for name in names:
        if (map_path.parent / name).is_file():
            return map_path.parent / name
    raise ValueError(f"{map_path}: no scenario file {' or '.join(names)} beside it")


def _sha256(path: Path) -> str:
    """The SHA-256 hex digest of a file's bytes."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _check_random(entry: dict) -> str | None:
    size, seed = entry["random"], entry.get("seed")
    if not _int_at_least(size, 2):
        return f"random = {size!r}: the size must be an integer >= 2"
    if not _int_at_least(seed, 0):
        return f"seed = {seed!r}: a random map needs a non-negative integer seed"
    density = entry.get("density", DEFAULT_DENSITY)
    if not isinstance(density, (int, float)) or not 0 <= density < 1:
        return f"density = {density!r}: must be in [0, 1)"
    return None


def _check_path_map(entry: dict) -> str | None:
    if _path_map_size(entry["pathmap"]) is None:
        return f"pathmap = {entry['pathmap']!r}: the size must be 'WxH' (e.g. '20x20')"
    if not _int_at_least(entry.get("seed"), 0):
        return f"seed = {entry.get('seed')!r}: a path map needs a non-negative integer seed"
    return None


def _check_plane(entry: dict) -> str | None:
    name = entry["plane"]
    if name == "random":
        if not _int_at_least(entry.get("seed"), 0):
            return (f"seed = {entry.get('seed')!r}: a random plane needs a non-negative integer "
                    "seed")
        if not _int_at_least(entry.get("rectangles", RANDOM_RECTANGLES), 0):
            return f"rectangles = {entry['rectangles']!r}: must be a non-negative integer"
        return None
    if name not in PAPER_PLANES or set(entry) != {"plane"}:
        return (f"plane = {name!r}: one of {', '.join(PAPER_PLANES)} (alone) or 'random' (with "
                "seed and rectangles)")
    return None


def _check_movingai(entry: dict) -> str | None:
    if not isinstance(entry["movingai"], str) or not entry["movingai"].endswith(".map"):
        return f"movingai = {entry['movingai']!r}: must name a .map file"
    if "start" in entry or "goal" in entry:
        if "scenario" in entry or "scenario_file" in entry:
            return "a Moving AI map takes scenario = ROW or start and goal, not both"
        for key in ("start", "goal"):
            point = entry.get(key)
            if not (isinstance(point, (list, tuple)) and len(point) == 2
                    and all(_int_at_least(v, 0) for v in point)):
                return f"{key} = {point!r}: must be [x, y], two non-negative integers"
        return None
    if not _int_at_least(entry.get("scenario"), 0):
        return ("a Moving AI map needs scenario = ROW (a non-negative row of its .scen file), "
                "or start = [x, y] and goal = [x, y]")
    if not isinstance(entry.get("scenario_file", ""), str):
        return (f"scenario_file = {entry['scenario_file']!r}: 'even', 'random' or a .scen file "
                "beside the map")
    return None


def _path_map_size(size) -> tuple[int, int] | None:
    """``(width, height)`` of a path map's ``"WxH"``, or None when ``size`` is not of that
    form."""
    if not isinstance(size, str):
        return None
    match = PATH_MAP_SIZE.fullmatch(size)
    return (int(match[1]), int(match[2])) if match else None


def _int_at_least(value, low: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= low
