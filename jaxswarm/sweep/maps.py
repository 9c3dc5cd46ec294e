"""Map entries of a sweep spec, resolved to a world (a graph or a plane) and a start-goal query.

An entry is a paper map name (``"mosaic50"``), a seeded random grid
(``{ random = 50, seed = 3, density = 0.3 }``, corner to corner), a plane of rectangles for the
bees (``{ plane = "map1" }``, the bees paper's map #1 or #2, or
``{ plane = "random", seed = 3, rectangles = 40 }``, see
:func:`jaxswarm.maps.planes.random_plane`) or one row of a Moving AI
scenario file (``{ movingai = "mapf/maze-32-32-2.map", scenario = 5 }``, row 5 counted from 0;
``scenario_file = "random"`` takes the MAPF set's ``<map>-random-1.scen`` instead of the default
``<map>.map.scen`` or ``<map>-even-1.scen``, and any other value names a file beside the map), or
a seeded thin-wall path map (``{ pathmap = "20x20", seed = 3 }``, see
:func:`jaxswarm.maps.random.random_path_map`), top-left to bottom-right.
A relative ``.map`` path is looked up beside the spec, then in the folder that the environment
variable ``JAXSWARM_MOVINGAI`` names (e.g. ``shared/benchdata/movingai``). A resolved map keeps
the SHA-256 of each file it was read from (:func:`file_digests`), so that a store can tell an
edited file from the one its rows were computed on.
"""
from __future__ import annotations

import dataclasses
import hashlib
import os
from pathlib import Path

import jax

from jaxswarm.exact import optimal_length
from jaxswarm.exact.visibility import shortest_path
from jaxswarm.maps import movingai
from jaxswarm.maps.named import PAPER, PATH_MAP, map_kind, named_map
from jaxswarm.maps.paper import PAPER_MAPS
from jaxswarm.maps.planes import PAPER_PLANES, RANDOM_RECTANGLES, paper_plane, random_plane
from jaxswarm.maps.random import random_grid
from jaxswarm.swarm import make_task
from jaxswarm.world.graph import Graph, grid_graph
from jaxswarm.world.plane import Plane

RANDOM_KEYS = {"random", "seed", "density"}
PLANE_KEYS = {"plane", "seed", "rectangles"}
MOVINGAI_KEYS = {"movingai", "scenario", "scenario_file"}
PATH_MAP_KEYS = {"pathmap", "seed"}
MOVINGAI_DATA = "JAXSWARM_MOVINGAI"
"""The environment variable naming the folder of Moving AI maps (relative entries are looked up
there after the spec's own folder)."""


@dataclasses.dataclass(frozen=True, eq=False)
class SweepMap:
    """A resolved map entry.

    Attributes:
      label: the name written in every results row (e.g. ``mosaic50``, ``random50-s3``,
        ``maze-32-32-2#5``, ``map1``, ``plane-s3-r40``).
      world: the map's Graph, or a Plane.
      start, goal: (x, y) cells of a graph, (x, y) points of a plane.
      files: the files the map was read from, role (``map``, ``scenario``) -> ``(path,
        SHA-256 hex digest of the bytes read)``; empty for a map made from its entry alone.
    """

    label: str
    world: Graph | Plane
    start: tuple
    goal: tuple
    files: dict = dataclasses.field(default_factory=dict)

    @property
    def size(self) -> str:
        """``WIDTHxHEIGHT`` of a grid or a plane ("" for a general graph)."""
        if isinstance(self.world, Plane):
            return "x".join(f"{float(v):g}" for v in jax.device_get(self.world.extent))
        return f"{self.world.shape[1]}x{self.world.shape[0]}" if self.world.shape else ""

    def optimum(self) -> float:
        """The optimal path length, measured as the swarms measure theirs: Dijkstra's path on a
        graph (:func:`jaxswarm.exact.optimal_length`), the visibility-graph shortest path on a
        plane (:func:`jaxswarm.exact.visibility.shortest_path`); inf when the goal is
        unreachable."""
        if isinstance(self.world, Plane):
            return shortest_path(self.world, self.start, self.goal)[0]
        return optimal_length(self.world, self.start, self.goal)


def check_map_entry(entry) -> str | None:
    """The problem with a spec's map entry, or None if it is well formed (files are looked up
    when the map is resolved)."""
    if isinstance(entry, str):
        # A string names a paper map; seeded and Moving AI maps are tables, whose keys give the
        # seed or the scenario row that a bare name cannot.
        if map_kind(entry) != PAPER:
            return (f"unknown map {entry!r}; paper maps: {', '.join(PAPER_MAPS)} (or a table "
                    "{ random = SIZE, seed = S } / { movingai = FILE, scenario = ROW } / "
                    "{ plane = NAME } / { pathmap = WxH, seed = S })")
        return None
    if not isinstance(entry, dict):
        return f"a map is a paper map name or a table, got {entry!r}"
    if "plane" in entry:
        unknown = set(entry) - PLANE_KEYS
        if unknown:
            return f"unknown keys {sorted(unknown)} for a plane ({', '.join(sorted(PLANE_KEYS))})"
        name = entry["plane"]
        if name == "random":
            if not _int_at_least(entry.get("seed"), 0):
                return (f"seed = {entry.get('seed')!r}: a random plane needs a non-negative "
                        "integer seed")
            if not _int_at_least(entry.get("rectangles", RANDOM_RECTANGLES), 0):
                return (f"rectangles = {entry['rectangles']!r}: must be a non-negative "
                        "integer")
            return None
        if name not in PAPER_PLANES or set(entry) != {"plane"}:
            return (f"plane = {name!r}: one of {', '.join(PAPER_PLANES)} (alone) or "
                    "'random' (with seed and rectangles)")
        return None
    if "random" in entry:
        unknown = set(entry) - RANDOM_KEYS
        if unknown:
            return (f"unknown keys {sorted(unknown)} for a random map "
                    f"({', '.join(sorted(RANDOM_KEYS))})")
        size, seed = entry["random"], entry.get("seed")
        if not _int_at_least(size, 2):
            return f"random = {size!r}: the size must be an integer >= 2"
        if not _int_at_least(seed, 0):
            return f"seed = {seed!r}: a random map needs a non-negative integer seed"
        density = entry.get("density", 0.3)
        if not isinstance(density, (int, float)) or not 0 <= density < 1:
            return f"density = {density!r}: must be in [0, 1)"
        return None
    if "movingai" in entry:
        unknown = set(entry) - MOVINGAI_KEYS
        if unknown:
            return f"unknown keys {sorted(unknown)} for a Moving AI map (movingai, scenario)"
        if not isinstance(entry["movingai"], str) or not entry["movingai"].endswith(".map"):
            return f"movingai = {entry['movingai']!r}: must name a .map file"
        if not _int_at_least(entry.get("scenario"), 0):
            return "a Moving AI map needs scenario = ROW (a non-negative row of its .scen file)"
        if not isinstance(entry.get("scenario_file", ""), str):
            return (f"scenario_file = {entry['scenario_file']!r}: 'even', 'random' or a .scen "
                    "file beside the map")
        return None
    if "pathmap" in entry:
        return _check_path_map(entry)
    return (f"a map table needs a 'random', 'movingai', 'plane' or 'pathmap' key, got "
            f"{sorted(entry)}")


def _check_path_map(entry: dict) -> str | None:
    """The problem with a ``{ pathmap = "WxH", seed = S }`` entry, or None."""
    unknown = set(entry) - PATH_MAP_KEYS
    if unknown:
        return f"unknown keys {sorted(unknown)} for a path map (pathmap, seed)"
    size = entry["pathmap"]
    if not isinstance(size, str) or map_kind(f"pathmap{size}") != PATH_MAP:
        return f"pathmap = {size!r}: the size must be 'WxH' (e.g. '20x20')"
    if not _int_at_least(entry.get("seed"), 0):
        return f"seed = {entry.get('seed')!r}: a path map needs a non-negative integer seed"
    return None


def entry_world(entry) -> type:
    """The kind of world a well-formed map entry resolves to: Plane or Graph."""
    return Plane if isinstance(entry, dict) and "plane" in entry else Graph


def resolve_map(entry, base_dir: Path | None = None) -> SweepMap:
    """Build the graph and query of a checked map entry.

    Args:
      entry: as accepted by :func:`check_map_entry`.
      base_dir: where a relative Moving AI path is looked up first (the spec's directory).

    Raises:
      ValueError: a malformed entry, a missing Moving AI file or scenario row.
    """
    problem = check_map_entry(entry)
    if problem:
        raise ValueError(problem)
    if isinstance(entry, str):
        named = named_map(entry)
        return SweepMap(named.label, named.graph, tuple(named.start), tuple(named.goal))
    if "plane" in entry:
        if entry["plane"] == "random":
            count = entry.get("rectangles", RANDOM_RECTANGLES)
            chosen = random_plane(jax.random.key(entry["seed"]), num_rectangles=count)
            label = f"plane-s{entry['seed']}-r{count}"
        else:
            chosen = paper_plane(entry["plane"])
            label = chosen.label
        return SweepMap(label, chosen.plane, chosen.start, chosen.goal)
    if "pathmap" in entry:
        named = named_map(f"pathmap{entry['pathmap']}", seed=entry["seed"])
        return SweepMap(f"{named.label}-s{entry['seed']}", named.graph, tuple(named.start),
                        tuple(named.goal))
    if "random" in entry:
        density = float(entry.get("density", 0.3))
        grid = random_grid(entry["random"], entry["seed"], density=density)
        label = f"random{entry['random']}-s{entry['seed']}"
        if "density" in entry:
            label += f"-d{density:g}"
        return SweepMap(label, grid_graph(grid.obstacles), grid.start, grid.goal)
    map_path = _find_movingai(entry["movingai"], base_dir)
    scenario_path = _scenario_file(map_path, entry.get("scenario_file"))
    paths = {"map": map_path, "scenario": scenario_path}
    digests = {role: _sha256(path) for role, path in paths.items()}
    obstacles = movingai.read_map(map_path)
    scenarios = movingai.load_scenarios(scenario_path)
    # The digests vouch for the maps only if the files did not change while they were parsed.
    if {role: _sha256(path) for role, path in paths.items()} != digests:
        raise ValueError(f"{map_path} or {scenario_path} changed while it was read; try again")
    files = {role: (str(path), digests[role]) for role, path in paths.items()}
    row = entry["scenario"]
    if row >= len(scenarios):
        raise ValueError(f"{scenario_path}: scenario {row} out of range ({len(scenarios)} rows)")
    scenario = scenarios[row]
    movingai.check_scenario(scenario, obstacles, scenario_path)
    return SweepMap(f"{map_path.stem}#{row}", grid_graph(obstacles), scenario.start,
                    scenario.goal, files)


def file_digests(maps: list[SweepMap], key: str) -> dict:
    """What the rows of ``maps`` (a spec's list at ``key``) depend on outside the spec: the
    content of every file they were read from, ``"key[i].role"`` -> ``{"file": PATH, "sha256":
    HEX}``, for a store to record and compare
    (:class:`~jaxswarm.sweep.store.ResultsStore`'s ``depends_on``)."""
    return {f"{key}[{i}].{role}": dict(file=path, sha256=digest)
            for i, sweep_map in enumerate(maps) for role, (path, digest) in sweep_map.files.items()}


def _sha256(path: Path) -> str:
    """The SHA-256 hex digest of a file's bytes."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def resolve_maps(entries, key: str, source: str, base_dir: Path | None = None) -> list[SweepMap]:
    """Every map entry of ``entries`` (a spec's list at ``key``), resolved and its start and goal
    checked (:func:`resolve_map`, :func:`check_query`).

    Raises:
      ValueError: naming the spec file ``source``, the entry (``key[i]``) and the problem.
    """
    maps = []
    for i, entry in enumerate(entries):
        try:
            sweep_map = resolve_map(entry, base_dir)
            check_query(sweep_map)
        except ValueError as error:
            raise ValueError(f"{source}: {key}[{i}] = {entry!r}: {error}") from None
        maps.append(sweep_map)
    return maps


def check_query(sweep_map: SweepMap) -> None:
    """Check that a resolved map's start and goal are on the map and free.

    Raises:
      ValueError: naming the endpoint (see :func:`jaxswarm.swarm.make_task`).
    """
    make_task(sweep_map.world, sweep_map.start, sweep_map.goal)


def _find_movingai(name: str, base_dir: Path | None) -> Path:
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


def _int_at_least(value, low: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= low
