"""The RFD paper's dynamic scenarios on the 20 x 20 maps, and replaying a run with a budget."""
import jax
import numpy as np
import pytest
import sizes

from graphs import solved_paper_map
from jitted import apply_event, change
from jaxswarm.dynamic.events import check_events
from jaxswarm.exact import dijkstra
from jaxswarm.maps.paper import PAPER_OPTIMA, paper_map
from jaxswarm.studies import rfd_dynamic
from jaxswarm.studies.rfd_dynamic import (PAPER_DYNAMIC_LENGTH, TABLE2_GOALS, nearest_free,
                                          paper_scenario)
from jaxswarm.swarm import make_task, run
from jaxswarm.world.graph import grid_graph


@pytest.mark.parametrize("name", [
    "mosaic20",
    pytest.param("alley20", marks=pytest.mark.slow),
    pytest.param("maze20", marks=pytest.mark.slow)])
@pytest.mark.parametrize("table", [2, 3, 4, 5])
def test_scenarios_change_the_optimum_as_described(name, table):
    scenario = paper_scenario(name, table)
    chosen = paper_map(name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    # Padded to one size: every scenario of a 20 x 20 map shares one program of apply_event.
    event = scenario.event(graph, size=graph.num_nodes)
    check_events(graph, task, event)
    edited, new_task = apply_event(event, graph, task)
    # The optimum after the change, measured independently on a map built from the obstacles.
    rebuilt = grid_graph(scenario.obstacles())
    np.testing.assert_array_equal(np.asarray(rebuilt.free), np.asarray(edited.free))
    after = dijkstra(rebuilt, chosen.start, scenario.goal or chosen.goal)
    assert after.found and after.cost == pytest.approx(scenario.optimum)
    assert scenario.optimum != pytest.approx(scenario.static_optimum)
    assert scenario.target == pytest.approx(
        scenario.static_optimum * PAPER_DYNAMIC_LENGTH[table]["Dijkstra"][name]
        / PAPER_OPTIMA[name])
    kinds = {2: "goal", 3: "added", 4: "removed"}
    assert scenario.kind == kinds.get(table, "goal" if name == "mosaic20" else "major removal")
    if scenario.kind == "added":  # a cut of the static optimal path
        assert scenario.block and scenario.optimum > scenario.static_optimum
    if scenario.kind in ("removed", "major removal"):
        assert scenario.unblock and scenario.optimum < scenario.static_optimum
    if scenario.kind == "goal":
        assert not scenario.block and not scenario.unblock
        assert int(new_task.goal) == scenario.goal[1] * 20 + scenario.goal[0]


def test_a_goal_on_an_obstacle_moves_to_the_nearest_free_cell():
    scenario = paper_scenario("alley20", 2)
    assert scenario.paper_goal == TABLE2_GOALS["alley20"]
    x, y = scenario.paper_goal
    assert paper_map("alley20").obstacles[y, x]  # the paper's cell is a wall on our map
    gx, gy = scenario.goal
    assert not paper_map("alley20").obstacles[gy, gx]
    assert np.hypot(gx - x, gy - y) == 1.0


def test_nearest_free_keeps_a_free_cell_and_skips_unreachable_ones():
    obstacles = np.zeros((5, 5), bool)
    obstacles[:, 2] = True
    graph = grid_graph(obstacles)
    assert nearest_free(graph, (0, 0), (1, 1)) == (1, 1)
    assert nearest_free(graph, (0, 0), (2, 2)) == (1, 2)  # (3, 2) is as near, unreachable


def test_unknown_map_or_table():
    with pytest.raises(ValueError, match="unknown paper map"):
        paper_scenario("maze30", 2)
    with pytest.raises(ValueError, match="tables are 2-5"):
        paper_scenario("maze20", 6)


def test_the_old_path_gives_the_moved_names_with_a_deprecation_warning():
    from jaxswarm.dynamic import scenarios  # importing the old path alone does not warn

    for name in scenarios.MOVED:
        with pytest.warns(DeprecationWarning, match=rf"scenarios\.{name} moved to "
                                                     rf"jaxswarm\.studies\.rfd_dynamic\.{name}"):
            assert getattr(scenarios, name) is getattr(rfd_dynamic, name)
    with pytest.raises(AttributeError, match="has no attribute 'paper_scenarios'"):
        scenarios.paper_scenarios  # noqa: B018 - a name that never lived there


def test_budget_replays_a_run_up_to_an_iteration():
    _, graph, task, swarm, params, state = solved_paper_map("maze20", "rfd_graded")
    scenario = paper_scenario("maze20", 5)  # a major change: the run goes on for a while
    changed, edited, new_task = change(swarm, state, scenario.event(graph), graph, task, params)
    _, full = run(swarm, jax.random.key(1), edited, new_task, params,
                  iterations=sizes.ITERATIONS, state=changed)
    _, short = run(swarm, jax.random.key(1), edited, new_task, params,
                   iterations=sizes.ITERATIONS, state=changed, budget=3)
    assert int(full.iterations) > 3 and int(short.iterations) == 3
    np.testing.assert_array_equal(np.asarray(short.best_cost)[:3], np.asarray(full.best_cost)[:3])
