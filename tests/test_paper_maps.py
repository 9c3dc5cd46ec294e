"""The RFD paper's maps (jaxswarm.maps.paper), checked against scipy's Dijkstra as an oracle, and
the names that pick a map (jaxswarm.maps.named)."""
import functools
import math
import re

import numpy as np
import pytest
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from jaxswarm.maps.named import MAP_FILE, PAPER, PATH_MAP, map_kind, named_map
from jaxswarm.maps.paper import (PAPER_MAPS, PAPER_OPTIMA, PAPER_TABLE1_LENGTH, PAPER_TABLE1_MS,
                                 PaperMap, paper_map, paper_map_names)

# The paper's start and goal cells, (x, y), written out again from its section 3.
PAPER_ENDPOINTS = {
    "maze20": ((0, 0), (19, 19)), "mosaic20": ((1, 9), (18, 9)), "alley20": ((3, 9), (16, 9)),
    "maze50": ((0, 0), (49, 49)), "mosaic50": ((2, 24), (46, 24)), "alley50": ((9, 24), (38, 24)),
    "maze100": ((0, 0), (99, 99)), "mosaic100": ((2, 54), (97, 54)),
    "alley100": ((23, 49), (75, 49)),
}


def octile_graph(obstacles):
    """Sparse graph over cells y * W + x: 8-connected moves between free cells, orthogonal cost 1,
    diagonal cost sqrt(2), no corner cutting (a diagonal needs both orthogonal neighbours free).
    Each undirected edge is stored once; use it with ``directed=False``."""
    height, width = obstacles.shape

    def free(x, y):
        return 0 <= x < width and 0 <= y < height and not obstacles[y, x]

    sources, targets, lengths = [], [], []
    for y in range(height):
        for x in range(width):
            if not free(x, y):
                continue
            for dx, dy in ((1, 0), (0, 1), (1, 1), (-1, 1)):
                if not free(x + dx, y + dy):
                    continue
                if dx and dy and not (free(x + dx, y) and free(x, y + dy)):
                    continue
                sources.append(y * width + x)
                targets.append((y + dy) * width + x + dx)
                lengths.append(math.sqrt(2.0) if dx and dy else 1.0)
    n = height * width
    return csr_matrix((lengths, (sources, targets)), shape=(n, n))


@functools.lru_cache(maxsize=None)
def optimum(name):
    """Shortest start-goal length on map ``name`` (inf if the goal is unreachable)."""
    m = paper_map(name)
    width = m.obstacles.shape[1]
    distances = dijkstra(octile_graph(m.obstacles), directed=False,
                         indices=m.start[1] * width + m.start[0])
    return float(distances[m.goal[1] * width + m.goal[0]])


def straight_line(m: PaperMap):
    return math.dist(m.start, m.goal)


def test_map_list_matches_optima():
    assert len(PAPER_MAPS) == 9
    assert set(PAPER_MAPS) == set(PAPER_OPTIMA) == set(PAPER_ENDPOINTS)
    assert PAPER_OPTIMA["maze100"] == 510.56


@pytest.mark.parametrize("name", PAPER_MAPS)
def test_shape_and_endpoints(name):
    m = paper_map(name)
    size = int(re.search(r"\d+$", name).group())
    assert m.name == name
    assert m.obstacles.shape == (size, size) and m.obstacles.dtype == bool
    assert (m.start, m.goal) == PAPER_ENDPOINTS[name]
    for x, y in (m.start, m.goal):
        assert 0 <= x < size and 0 <= y < size
        assert not m.obstacles[y, x]


@pytest.mark.parametrize("name", PAPER_MAPS)
def test_optimum_near_paper(name):
    length = optimum(name)
    assert math.isfinite(length), "goal unreachable"
    # Our maps are rebuilt from the paper's figures: every optimum is within 4.6 % of its
    # Table 1 value (maze50, 218 against 228.52, is the farthest).
    assert abs(length / PAPER_OPTIMA[name] - 1.0) <= 0.05, (length, PAPER_OPTIMA[name])


@pytest.mark.parametrize("name", PAPER_MAPS)
def test_paths_detour(name):
    straight = straight_line(paper_map(name))
    if name.startswith(("maze", "alley")):
        assert optimum(name) > 1.5 * straight
    else:  # mosaic: the straight line is blocked here and there
        assert optimum(name) > straight + 1.0


@pytest.mark.parametrize("name", PAPER_MAPS)
def test_many_obstacles(name):
    assert paper_map(name).obstacles.mean() >= 0.15


@pytest.mark.parametrize("name", PAPER_MAPS)
def test_deterministic_and_read_only(name):
    a, b = paper_map(name), paper_map(name)
    np.testing.assert_array_equal(a.obstacles, b.obstacles)
    assert (a.start, a.goal) == (b.start, b.goal)
    assert not a.obstacles.flags.writeable
    with pytest.raises(ValueError):
        a.obstacles[a.start[1], a.start[0]] = True


@pytest.mark.parametrize("name", ["maze30", "Maze20", "", "alley"])
def test_unknown_name(name):
    with pytest.raises(ValueError, match="maze20"):
        paper_map(name)


@pytest.mark.parametrize("text, names", [
    ("all", PAPER_MAPS),
    ("maze100,mosaic20", ("maze100", "mosaic20")),
    (" alley50 , alley50,", ("alley50",)),
])
def test_map_names_from_a_command_line_list(text, names):
    assert paper_map_names(text) == names


@pytest.mark.parametrize("text, message", [
    ("mosaic20,maze30,Alley20", r"unknown paper maps \['maze30', 'Alley20'\]; choose from all or"),
    (" , ", "no paper map named"),
])
def test_bad_map_lists_name_the_problem(text, message):
    with pytest.raises(ValueError, match=message):
        paper_map_names(text)


def test_table1_transcription():
    for table in (PAPER_TABLE1_LENGTH, PAPER_TABLE1_MS):
        assert list(table) == ["Dijkstra", "A*", "ACO", "ACO*", "RFD", "RFD*"]
        for algorithm, values in table.items():
            assert list(values) == list(PAPER_MAPS)
            missing = {m for m, v in values.items() if v is None}
            # The paper's ACO, ACO* and RFD found no path on any maze.
            expected = {"maze20", "maze50", "maze100"} if algorithm in ("ACO", "ACO*", "RFD") \
                else set()
            assert missing == expected, algorithm
    # Dijkstra, A* and RFD* share the optimal lengths; spot checks of the times.
    assert PAPER_TABLE1_LENGTH["A*"] == PAPER_TABLE1_LENGTH["RFD*"] == PAPER_OPTIMA
    assert PAPER_TABLE1_MS["RFD*"]["alley100"] == 5934.1
    assert PAPER_TABLE1_MS["ACO"]["mosaic100"] == 131071.05


@pytest.mark.parametrize("name, kind", [
    ("maze100", PAPER), ("pathmap40x25", PATH_MAP), ("maps/den312d.map", MAP_FILE),
    ("maze30", None), ("pathmap40", None), ("pathmap40x25.png", None)])
def test_a_name_says_which_kind_of_map_it_picks(name, kind):
    assert map_kind(name) == kind


def test_a_named_paper_map_is_the_paper_map_unless_its_endpoints_are_given():
    named, chosen = named_map("alley20"), paper_map("alley20")
    assert (named.label, named.start, named.goal) == ("alley20", chosen.start, chosen.goal)
    assert np.array_equal(np.asarray(named.graph.free), ~chosen.obstacles.ravel())
    assert named_map("alley20", start=(4, 9), goal=(15, 9))[2:] == ((4, 9), (15, 9))


def test_a_path_map_name_gives_its_size_its_corners_and_its_seed_the_walls():
    named = named_map("pathmap12x7", seed=3)
    assert (named.label, named.graph.shape, named.start, named.goal) == (
        "pathmap12x7", (7, 12), (0, 0), (11, 6))
    assert np.array_equal(named_map("pathmap12x7", seed=3).graph.open, named.graph.open)
    assert not np.array_equal(named_map("pathmap12x7", seed=4).graph.open, named.graph.open)


@pytest.mark.parametrize("name, endpoints, message", [
    ("atlantis", {}, "--map must be one of mosaic20, "),
    ("nosuch.map", dict(start=(1, 1), goal=(2, 2)), "--map nosuch.map: no such file"),
    ("nosuch.map", dict(start=(1, 1)), "--start and --goal are required with a .map file")])
def test_a_bad_name_is_an_error_naming_the_option(name, endpoints, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        named_map(name, **endpoints)
