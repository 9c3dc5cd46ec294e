"""Map entries of a sweep spec, resolved to a graph and a start-goal query.

An entry is a paper map name (``"mosaic50"``), a seeded random grid
(``{ random = 50, seed = 3, density = 0.3 }``, corner to corner) or one row of a Moving AI
scenario file (``{ movingai = "mapf/maze-32-32-2.map", scenario = 5 }``).
"""
from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from jaxswarm.graph import Graph, grid_graph
from jaxswarm.maps import movingai
from jaxswarm.maps.paper import PAPER_MAPS, paper_map
from jaxswarm.maps.random import random_grid

RANDOM_KEYS = {"random", "seed", "density"}
MOVINGAI_KEYS = {"movingai", "scenario"}


@dataclasses.dataclass(frozen=True, eq=False)
class SweepMap:
    """A resolved map entry.

    Attributes:
      label: the name written in every results row (e.g. ``mosaic50``, ``random50-s3``,
        ``maze-32-32-2#5``).
      graph: the map's Graph.
      start, goal: (x, y) cells.
    """

    label: str
    graph: Graph
    start: tuple[int, int]
    goal: tuple[int, int]


def check_map_entry(entry) -> str | None:
    """The problem with a spec's map entry, or None if it is well formed (files are looked up
    when the map is resolved)."""
    if isinstance(entry, str):
        if entry not in PAPER_MAPS:
            return (f"unknown map {entry!r}; paper maps: {', '.join(PAPER_MAPS)} (or a table "
                    "{ random = SIZE, seed = S } / { movingai = FILE, scenario = ROW })")
        return None
    if not isinstance(entry, dict):
        return f"a map is a paper map name or a table, got {entry!r}"
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
        return None
    return f"a map table needs a 'random' or a 'movingai' key, got {sorted(entry)}"


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
        chosen = paper_map(entry)
        return SweepMap(entry, chosen.graph(), tuple(chosen.start), tuple(chosen.goal))
    if "random" in entry:
        density = float(entry.get("density", 0.3))
        grid = random_grid(entry["random"], entry["seed"], density=density)
        label = f"random{entry['random']}-s{entry['seed']}"
        if "density" in entry:
            label += f"-d{density:g}"
        return SweepMap(label, grid_graph(grid.obstacles), grid.start, grid.goal)
    map_path = _find_movingai(entry["movingai"], base_dir)
    scenarios = movingai.load_scenarios(_scenario_file(map_path))
    row = entry["scenario"]
    if row >= len(scenarios):
        raise ValueError(f"{map_path}: scenario {row} out of range ({len(scenarios)} rows)")
    scenario = scenarios[row]
    return SweepMap(f"{map_path.stem}#{row}", movingai.load_map(map_path), scenario.start,
                    scenario.goal)


def _find_movingai(name: str, base_dir: Path | None) -> Path:
    shared = Path(os.environ.get("JAXSWARM_SHARED",
                                 Path(__file__).resolve().parents[3] / "shared"))
    candidates = [Path(name)] if Path(name).is_absolute() else [
        *([base_dir / name] if base_dir else []), shared / "benchdata" / "movingai" / name]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise ValueError(f"Moving AI map {name!r} not found (looked in "
                     f"{', '.join(str(c) for c in candidates)})")


def _scenario_file(map_path: Path) -> Path:
    """``<map>.scen``, else the first ``<stem>*.scen`` beside the map (the MAPF set names them
    ``<stem>-even-1.scen``)."""
    beside = Path(str(map_path) + ".scen")
    if beside.is_file():
        return beside
    found = sorted(map_path.parent.glob(f"{map_path.stem}*.scen"))
    if not found:
        raise ValueError(f"{map_path}: no scenario file beside it")
    return found[0]


def _int_at_least(value, low: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= low
