"""Map entries resolved in one place (jaxswarm.maps.entry): each form's world, task and optimum
against hand-built expectations, independent oracles (tests/oracle.py's Dijkstra, shapely and
networkx, the Moving AI files' published optima) and the values jaxswarm 0.10.2 resolved; the
entry check naming the key at fault before anything is built; the old names of
jaxswarm.sweep.maps forwarding with a DeprecationWarning."""
import hashlib
import math
import re

import jax
import numpy as np
import oracle
import pytest
from test_plane import shapely_shortest

from jaxswarm.maps.entry import ResolvedMap, check, resolve, world_kind
from jaxswarm.maps.paper import paper_map
from jaxswarm.maps.planes import paper_plane, random_plane
from jaxswarm.maps.random import random_grid, random_path_map
from jaxswarm.sweep.spec import file_digests
from jaxswarm.world.graph import Graph, path_map_graph
from jaxswarm.world.plane import Plane

MAZE_ROW = 5
"""Row 5 of maze-32-32-2-even-1.scen: ``13 5 5 1 20.24264069`` (start, goal, published optimum)."""


def _tiny_map(folder):
    """A Moving AI map of the 20 x 20 shape of the other maps here (one program for their
    optima), open but for the obstacle at (2, 0)."""
    rows = ["..@" + "." * 17] + ["." * 20] * 19
    path = folder / "tiny.map"
    path.write_text("type octile\nheight 20\nwidth 20\nmap\n" + "\n".join(rows) + "\n")
    return path


def _free(world) -> np.ndarray:
    return np.asarray(world.free)


@pytest.mark.parametrize("entry, label, optimum", [
    # Resolved by jaxswarm 0.10.2's jaxswarm.sweep.maps.resolve_map and its optimum(): the same
    # labels and the same float32 sums, bit for bit.
    ("mosaic20", "mosaic20", 18.6568546295166),
    ("maze20", "maze20", 78.0),
    ({"random": 20, "seed": 3}, "random20-s3", 30.384775161743164),
    ({"random": 20, "seed": 1, "density": 0.2}, "random20-s1-d0.2", 29.21320343017578),
    ({"pathmap": "12x8", "seed": 4}, "pathmap12x8-s4", 15.656854629516602),
    ({"plane": "map2"}, "map2", 68.4173449358973),
    ({"plane": "random", "seed": 3, "rectangles": 10}, "plane-s3-r10", 63.830474617798856),
    ({"movingai": "mapf/maze-32-32-2.map", "scenario": MAZE_ROW}, "maze-32-32-2#5",
     20.24264144897461),
    ({"movingai": "mapf/random-32-32-10.map", "scenario": 3, "scenario_file": "random"},
     "random-32-32-10#3", 8.414213180541992),
])
def test_every_form_resolves_to_the_label_and_optimum_of_before(movingai_dir, entry, label,
                                                                 optimum):
    resolved = resolve(entry)
    assert (resolved.label, resolved.optimum()) == (label, optimum)
    assert isinstance(resolved.world, world_kind(entry))


def test_a_paper_map_is_the_papers_grid_query_and_dijkstra_optimum():
    resolved, chosen = resolve("alley20"), paper_map("alley20")
    assert (resolved.start, resolved.goal) == (chosen.start, chosen.goal)
    np.testing.assert_array_equal(_free(resolved.world), ~chosen.obstacles.reshape(-1))
    width = chosen.obstacles.shape[1]
    assert (int(resolved.task.start), int(resolved.task.goal)) == (
        chosen.start[1] * width + chosen.start[0], chosen.goal[1] * width + chosen.goal[0])
    expected = oracle.dijkstra(oracle.grid_adjacency(chosen.obstacles.tolist()), chosen.start,
                               chosen.goal)
    assert resolved.optimum() == pytest.approx(expected, rel=1e-6)
    assert resolved.files == {} and resolved.size == "20x20"


def test_a_random_grid_is_the_seeded_grid_corner_to_corner():
    resolved = resolve({"random": 20, "seed": 7, "density": 0.4})
    grid = random_grid(20, 7, density=0.4)
    np.testing.assert_array_equal(_free(resolved.world), ~grid.obstacles.reshape(-1))
    assert (resolved.start, resolved.goal) == ((0, 0), (19, 19))
    other = resolve({"random": 20, "seed": 8, "density": 0.4})
    assert not np.array_equal(_free(other.world), _free(resolved.world))
    expected = oracle.dijkstra(oracle.grid_adjacency(grid.obstacles.tolist()), (0, 0), (19, 19))
    assert resolved.optimum() == pytest.approx(expected, rel=1e-6)


def test_a_path_map_is_the_seeded_thin_wall_map_top_left_to_bottom_right():
    resolved = resolve({"pathmap": "12x8", "seed": 2})
    expected = path_map_graph(random_path_map(12, 8, 2))
    np.testing.assert_array_equal(np.asarray(resolved.world.open), np.asarray(expected.open))
    np.testing.assert_array_equal(np.asarray(resolved.world.nbr), np.asarray(expected.nbr))
    assert (resolved.label, resolved.start, resolved.goal) == ("pathmap12x8-s2", (0, 0), (11, 7))


def test_a_moving_ai_row_is_the_scenario_files_query_with_its_published_optimum(movingai_dir):
    folder = movingai_dir / "mapf"
    resolved = resolve({"movingai": "mapf/maze-32-32-2.map", "scenario": MAZE_ROW},
                       base_dir=movingai_dir)
    assert (resolved.start, resolved.goal) == ((13, 5), (5, 1))
    assert resolved.optimum() == pytest.approx(20.24264069, rel=1e-6)
    scenario = folder / "maze-32-32-2-even-1.scen"
    assert resolved.files == {
        "map": (str(movingai_dir / "mapf/maze-32-32-2.map"),
                hashlib.sha256((folder / "maze-32-32-2.map").read_bytes()).hexdigest()),
        "scenario": (str(scenario), hashlib.sha256(scenario.read_bytes()).hexdigest())}
    # A store records them under the keys it recorded before (a store written before resumes).
    assert file_digests([resolve("mosaic20"), resolved], "sweep.maps") == {
        f"sweep.maps[1].{role}": dict(file=path, sha256=digest)
        for role, (path, digest) in resolved.files.items()}


def test_a_moving_ai_map_with_its_own_query_is_labelled_by_its_file(tmp_path):
    path = _tiny_map(tmp_path)
    resolved = resolve({"movingai": "tiny.map", "start": [0, 0], "goal": [5, 3]},
                       base_dir=tmp_path)
    assert (resolved.label, resolved.start, resolved.goal) == ("tiny", (0, 0), (5, 3))
    assert resolved.optimum() == pytest.approx(2 + 3 * math.sqrt(2), rel=1e-6)  # octile
    assert resolved.files == {"map": (str(path), hashlib.sha256(path.read_bytes()).hexdigest())}


@pytest.mark.parametrize("entry", [{"plane": "map1"},
                                   {"plane": "random", "seed": 5, "rectangles": 12}])
def test_a_plane_has_the_visibility_graph_optimum_of_shapely_and_networkx(entry):
    chosen = (paper_plane("map1") if entry["plane"] == "map1"
              else random_plane(jax.random.key(5), num_rectangles=12))
    resolved = resolve(entry)
    assert isinstance(resolved.world, Plane)
    assert (resolved.start, resolved.goal) == (chosen.start, chosen.goal)
    np.testing.assert_array_equal(np.asarray(resolved.task.goal), np.float32(chosen.goal))
    assert resolved.optimum() == pytest.approx(
        shapely_shortest(chosen.plane, chosen.start, chosen.goal), rel=1e-6)


def test_given_endpoints_replace_the_entrys_own():
    resolved = resolve("alley20", start=(4, 9), goal=(15, 9))
    assert (resolved.label, resolved.start, resolved.goal) == ("alley20", (4, 9), (15, 9))
    assert int(resolved.task.start) == 9 * 20 + 4


@pytest.mark.parametrize("entry, message", [
    ("atlantis", "unknown map 'atlantis'; paper maps: "),
    ("pathmap20x20", "unknown map 'pathmap20x20'"),
    (3, "a map is a paper map name or a table, got 3"),
    ({"maze": 20}, "a map table needs a 'random', 'movingai', 'plane' or 'pathmap' key"),
    ({"random": 1, "seed": 0}, "random = 1: the size must be an integer >= 2"),
    ({"random": 20}, "seed = None: a random map needs a non-negative integer seed"),
    ({"random": 20, "seed": 0, "density": 1.0}, "density = 1.0: must be in [0, 1)"),
    ({"random": 20, "seed": 0, "walls": 3}, "unknown keys ['walls'] for a random map"),
    ({"pathmap": "20", "seed": 0}, "pathmap = '20': the size must be 'WxH'"),
    ({"pathmap": "20x20", "seed": True}, "seed = True: a path map needs a non-negative"),
    ({"plane": "map3"}, "plane = 'map3': one of map1, map2 (alone) or 'random'"),
    ({"plane": "random", "seed": 1, "rectangles": -1}, "rectangles = -1: must be a non-negative"),
    ({"movingai": "x.txt", "scenario": 0}, "movingai = 'x.txt': must name a .map file"),
    ({"movingai": "x.map"}, "a Moving AI map needs scenario = ROW"),
    ({"movingai": "x.map", "scenario": 0, "start": [0, 0], "goal": [1, 1]},
     "a Moving AI map takes scenario = ROW or start and goal, not both"),
    ({"movingai": "x.map", "start": [0, 0]}, "goal = None: must be [x, y]"),
    ({"movingai": "x.map", "start": [0, -1], "goal": [1, 1]}, "start = [0, -1]: must be [x, y]"),
    ({"movingai": "x.map", "scenario": 0, "scenario_file": 2}, "scenario_file = 2: 'even'"),
])
def test_a_bad_entry_is_refused_naming_its_key_before_anything_is_built(entry, message):
    assert message in check(entry)
    with pytest.raises(ValueError, match=re.escape(message)):
        resolve(entry)


def test_a_bad_start_or_goal_or_file_is_refused_before_anything_is_compiled(tmp_path):
    _tiny_map(tmp_path)
    with pytest.raises(ValueError, match=r"start \(2, 0\) is blocked"):
        resolve({"movingai": "tiny.map", "start": [2, 0], "goal": [5, 3]}, base_dir=tmp_path)
    with pytest.raises(ValueError, match=r"goal \(20, 3\) is off the 20x20 map"):
        resolve({"movingai": "tiny.map", "start": [0, 0], "goal": [20, 3]}, base_dir=tmp_path)
    with pytest.raises(ValueError, match="Moving AI map 'gone.map' not found"):
        resolve({"movingai": "gone.map", "start": [0, 0], "goal": [1, 1]}, base_dir=tmp_path)


def test_world_kind_says_a_plane_or_a_graph():
    assert world_kind({"plane": "map1"}) is Plane
    assert world_kind("maze20") is Graph and world_kind({"random": 20, "seed": 1}) is Graph


@pytest.mark.parametrize("name, new", [
    ("SweepMap", ResolvedMap), ("check_map_entry", check), ("file_digests", file_digests)])
def test_the_old_names_of_sweep_maps_forward_with_a_deprecation_warning(name, new):
    import jaxswarm.sweep.maps as old

    with pytest.warns(DeprecationWarning, match=f"jaxswarm.sweep.maps.{name} is deprecated"):
        assert getattr(old, name) is new


def test_the_old_resolve_functions_give_the_new_maps():
    import jaxswarm.sweep.maps as old

    with pytest.warns(DeprecationWarning, match="use jaxswarm.maps.entry.resolve"):
        resolve_map = old.resolve_map
    with pytest.warns(DeprecationWarning, match="use jaxswarm.sweep.spec.resolve_maps"):
        resolve_maps = old.resolve_maps
    assert resolve_map("maze20").label == "maze20"
    with pytest.raises(ValueError, match=re.escape("s.toml: sweep.maps[1] = 'x': unknown map")):
        resolve_maps(["maze20", "x"], "sweep.maps", "s.toml")
    with pytest.raises(AttributeError, match="no attribute 'entry_world'"):
        old.entry_world  # noqa: B018
