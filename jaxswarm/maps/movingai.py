"""Moving AI benchmark files: ``.map`` grids and ``.scen`` scenario lists.

Format (see ``shared/benchdata/movingai/SOURCES.md``): a map is the header ``type octile``,
``height H``, ``width W``, ``map``, then H rows of W characters, where only ``.``, ``G`` and ``S``
are passable. A scenario file is ``version 1`` then tab-separated rows
``bucket map width height start_x start_y goal_x goal_y optimal_length``, with octile lengths
(8-connected, diagonal sqrt 2, no corner cutting). A length of 0 between distinct cells means
"no path" (the GPPC convention). Malformed input raises :class:`MovingAIFormatError` naming the
file and line.
"""
from __future__ import annotations

import dataclasses
import math
import os

import numpy as np

from jaxswarm.world.graph import Graph, grid_graph

PASSABLE = frozenset(".GS")
BLOCKED = frozenset("@OTW")


class MovingAIFormatError(ValueError):
    """A malformed ``.map`` or ``.scen`` file; the message names the file and line."""

    def __init__(self, path, line: int, problem: str):
        super().__init__(f"{os.fspath(path)}, line {line}: {problem}")
        self.path, self.line = os.fspath(path), line


@dataclasses.dataclass(frozen=True)
class Scenario:
    """One start-goal query of a ``.scen`` file.

    Attributes:
      bucket: the file's bucket column.
      map_name: the map file the row refers to.
      width, height: the map size the row declares.
      start, goal: (x, y) cells, x = column, y = row.
      optimal_length: the published octile optimum; inf where the file says "no path".
      line: the line number in the file.
    """

    bucket: int
    map_name: str
    width: int
    height: int
    start: tuple[int, int]
    goal: tuple[int, int]
    optimal_length: float
    line: int

    @property
    def reachable(self) -> bool:
        """Whether the file says a path exists."""
        return math.isfinite(self.optimal_length)


def read_map(path) -> np.ndarray:
    """bool[H, W] obstacles (True = blocked) of a ``.map`` file, indexed ``[y, x]``.

    Raises:
      MovingAIFormatError: a malformed file (a byte that is not ASCII, a bad header, a row of
        the wrong length, an unknown terrain); the message names the file and line.
    """
    lines = _ascii_lines(path)
    header = {}
    for number, expected in enumerate(("type", "height", "width", "map"), start=1):
        if len(lines) < number:
            raise MovingAIFormatError(path, number, f"missing '{expected}' header line")
        words = lines[number - 1].split()
        if not words or words[0] != expected or len(words) != (1 if expected == "map" else 2):
            raise MovingAIFormatError(path, number,
                                      f"expected '{expected} ...', got {lines[number - 1]!r}")
        header[expected] = words[1:] and words[1]
    if header["type"] != "octile":
        raise MovingAIFormatError(path, 1,
                                  f"only 'type octile' maps are supported, got {header['type']!r}")
    height = _positive_int(header["height"], path, 2, "height")
    width = _positive_int(header["width"], path, 3, "width")
    rows = lines[4:]
    while rows and not rows[-1].strip():
        rows.pop()
    if len(rows) != height:
        raise MovingAIFormatError(path, 5 + len(rows),
                                  f"expected {height} map rows, found {len(rows)}")
    obstacles = np.zeros((height, width), dtype=bool)
    for y, row in enumerate(rows):
        number = 5 + y
        if len(row) != width:
            raise MovingAIFormatError(path, number, f"row has {len(row)} cells, expected {width}")
        unknown = set(row) - PASSABLE - BLOCKED
        if unknown:
            raise MovingAIFormatError(path, number, f"unknown terrain {''.join(sorted(unknown))!r}")
        obstacles[y] = [c not in PASSABLE for c in row]
    return obstacles


def load_map(path, **grid_options) -> Graph:
    """Graph of a ``.map`` file (8-connected, no corner cutting unless ``grid_options`` say so).

    Args:
      path: the ``.map`` file.
      **grid_options: passed to :func:`jaxswarm.world.graph.grid_graph` (connectivity, corner_cutting).
    """
    return grid_graph(read_map(path), **grid_options)


def load_scenarios(path, obstacles: np.ndarray | None = None) -> list[Scenario]:
    """All rows of a ``.scen`` file, in file order.

    Args:
      path: the ``.scen`` file.
      obstacles: optional bool[H, W] of the map the rows refer to (:func:`read_map`): each row
        is then checked against it.

    Raises:
      MovingAIFormatError: a malformed row, or (with ``obstacles``) a row whose size differs
        from the map's, whose start or goal lies outside its own size, or on an obstacle; the
        message names the file and line.
    """
    lines = _ascii_lines(path)
    if not lines or not lines[0].startswith("version"):
        raise MovingAIFormatError(path, 1, "expected a 'version ...' first line")
    scenarios = []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = line.split("\t") if "\t" in line else line.split()
        if len(fields) != 9:
            raise MovingAIFormatError(path, number, f"expected 9 fields, found {len(fields)}")
        try:
            bucket, width, height, sx, sy, gx, gy = (int(fields[i]) for i in (0, 2, 3, 4, 5, 6, 7))
            length = float(fields[8])
        except ValueError as error:
            raise MovingAIFormatError(path, number, f"bad number: {error}") from None
        if length < 0 or not math.isfinite(length):
            raise MovingAIFormatError(path, number, f"bad optimal length {fields[8]!r}")
        if length == 0 and (sx, sy) != (gx, gy):
            length = math.inf
        scenario = Scenario(bucket, fields[1], width, height, (sx, sy), (gx, gy), length, number)
        if obstacles is not None:
            check_scenario(scenario, obstacles, path)
        scenarios.append(scenario)
    return scenarios


def check_scenario(scenario: Scenario, obstacles: np.ndarray, path) -> None:
    """Check one row of the ``.scen`` file ``path`` against its map's bool[H, W] obstacles.

    Raises:
      MovingAIFormatError: the row's size differs from the map's, or its start or goal lies
        outside it or on an obstacle; the message names the file and line.
    """
    height, width = obstacles.shape
    if (scenario.width, scenario.height) != (width, height):
        raise MovingAIFormatError(path, scenario.line, f"the row is for a {scenario.width}x"
                                  f"{scenario.height} map, the map is {width}x{height}")
    for name, (x, y) in (("start", scenario.start), ("goal", scenario.goal)):
        if not (0 <= x < width and 0 <= y < height):
            raise MovingAIFormatError(path, scenario.line, f"{name} ({x}, {y}) is outside the "
                                      f"row's {width}x{height} map")
        if obstacles[y, x]:
            raise MovingAIFormatError(path, scenario.line, f"{name} ({x}, {y}) is an obstacle")


def _ascii_lines(path) -> list[str]:
    """The lines of the Moving AI file ``path``, which is plain ASCII.

    Raises:
      MovingAIFormatError: the first byte that is not ASCII, with its line and column.
    """
    with open(path, "rb") as f:
        data = f.read()
    try:
        return data.decode("ascii").splitlines()
    except UnicodeDecodeError as error:
        at = error.start
        line_start = data.rfind(b"\n", 0, at) + 1
        raise MovingAIFormatError(path, data.count(b"\n", 0, at) + 1,
                                  f"byte 0x{data[at]:02x} at column {at - line_start + 1} is not "
                                  "ASCII (Moving AI files are plain ASCII)") from None


def _positive_int(text: str, path, line: int, name: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise MovingAIFormatError(path, line, f"{name} must be an integer, got {text!r}") from None
    if value <= 0:
        raise MovingAIFormatError(path, line, f"{name} must be positive, got {value}")
    return value
