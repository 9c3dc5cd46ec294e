"""The registry of MAPF planners: every option of every entry refused, naming it, before any
search; unknown and fixed options; the variants' switches; the deprecated ``PLANNERS``; and the
extending guide's example planner, registered with one entry, through the validator, the
``jaxswarm mapf`` command and the MAPF study."""
from __future__ import annotations

import runpy

import numpy as np
import pytest

from jaxswarm.cli import main
from jaxswarm.multiagent import registry, validate
from jaxswarm.multiagent.cbs import SWITCHES, _name
from jaxswarm.multiagent.limits import OptionError
from jaxswarm.world.graph import grid_graph
from repo_scripts import ROOT, load_script

BAD = {"time_limit": [(-1, ValueError, "must be"), ("5", TypeError, "must be a number")],
       "max_nodes": [(0, ValueError, "at least 1"), (2.5, TypeError, "an integer")],
       "max_expansions": [(-3, ValueError, "at least 1"), (True, TypeError, "an integer")],
       "w": [(0.5, ValueError, "at least 1"), ("1.2", TypeError, "a number")],
       "refine": [(-1, ValueError, "at least 0"), (None, TypeError, "a number")],
       "max_configurations": [(0, ValueError, "at least 1"), (1e6, TypeError, "an integer")],
       "seed": [(-1, ValueError, "at least 0"), (1.5, TypeError, "an integer")],
       "restart_rate": [(2, ValueError, "between 0 and 1"), (True, TypeError, "a number")],
       "max_steps": [(0, ValueError, "at least 1"), ("9", TypeError, "an integer")],
       "order": [("longest", ValueError, "one of given, distance, random"),
                 (3, TypeError, "sequence of agents")],
       "max_repairs": [(-1, ValueError, "at least 0"), (2.0, TypeError, "an integer or None")]}
"""Option -> (a bad value, the error it raises, part of its message), two per option."""

CASES = [(name, option, *bad) for name in registry.registered()
         for option in registry.options(name) for bad in BAD.get(option, [(None, None, None)])]


@pytest.mark.parametrize("name, option, value, error, message", CASES)
def test_every_option_of_every_planner_is_refused_naming_it_before_any_search(
        name, option, value, error, message):
    assert error is not None, f"add bad values of {name}'s option {option} to BAD"
    with pytest.raises(error) as raised:
        registry.make_planner(name, **{option: value})
    assert option in str(raised.value) and name in str(raised.value)
    assert message in str(raised.value)
    with pytest.raises(error, match=option):  # called directly: refused before the instance
        registry.entry(name).plan(None, None, None, **{option: value})


def test_an_unknown_option_or_planner_lists_the_known_ones():
    with pytest.raises(ValueError, match=r"^unknown option 'w' of cbs; its options: max_nodes, "
                                         r"time_limit, max_expansions$"):
        registry.make_planner("cbs", w=1.5)
    with pytest.raises(ValueError, match=r"unknown planner 'astar'; registered: report, "
                                         r"prioritized, cbs, icbs"):
        registry.make_planner("astar")


@pytest.mark.parametrize("name, option, value", [("icbs", "prioritize", False),
                                                 ("cbs", "wdg", True), ("lacam", "swap", True),
                                                 ("lacam_star", "swap", False)])
def test_an_option_a_variant_fixes_is_refused(name, option, value):
    with pytest.raises(ValueError, match=f"^{option} of {name} is fixed"):
        registry.make_planner(name, **{option: value})


def test_each_cbs_variant_fixes_the_switches_its_plans_are_named_by():
    family = [name for name in registry.registered() if registry.entry(name).config
              is registry.entry("cbs").config]
    assert family == ["cbs", "icbs", "cbsh", "cbsh_tc", "cbsh_rtc"]
    for name in family:
        fixed = registry.entry(name).fixed
        assert set(fixed) == set(SWITCHES) and _name(*(fixed[s] for s in SWITCHES)) == name
        assert registry.entry(name).guarantee == "optimal"
    assert registry.entry("lacam_star").fixed == {"swap": True}


def test_options_are_checked_once_with_the_configs_defaults():
    checked = registry.config("ecbs", w=1.5)
    assert (checked.w, checked.max_nodes, checked.time_limit) == (1.5, 100_000, 60.0)
    with pytest.raises(OptionError) as raised:
        registry.config("lacam", time_limit=0.0)
    assert (raised.value.option, raised.value.problem) == (
        "time_limit", "must be positive, got 0.0 (an option of lacam)")


def test_every_entry_has_a_label_a_source_and_a_style_of_its_own():
    entries = [registry.entry(name) for name in registry.registered()]
    assert all(entry.label and entry.source for entry in entries)
    assert len({entry.style.marker for entry in entries}) == len(entries)


def test_planners_is_deprecated_and_maps_names_to_the_variants_functions():
    with pytest.warns(DeprecationWarning, match="PLANNERS is deprecated"):
        from jaxswarm.multiagent import PLANNERS
    assert list(PLANNERS) == list(registry.registered())
    assert PLANNERS["icbs"].keywords["prioritize"] and PLANNERS["pibt"] is registry.entry(
        "pibt").plan


@pytest.fixture
def example(monkeypatch):
    """The extending guide's example registered in a copy of the registry (undone after)."""
    monkeypatch.setattr(registry, "REGISTRY", dict(registry.REGISTRY))
    runpy.run_path(str(ROOT / "docs" / "examples" / "mapf_planner.py"))
    return registry.entry("staggered")


def test_the_example_planner_is_one_entry_and_its_plans_pass_the_validator(example):
    assert registry.options("staggered") == ("stagger",)
    with pytest.raises(ValueError, match="stagger must be at least 0, got -1"):
        registry.make_planner("staggered", stagger=-1)
    graph = grid_graph(np.zeros((3, 3), bool), connectivity=4)
    starts, goals = [(0, 1), (1, 0)], [(2, 1), (1, 2)]  # both cross the centre at step 1
    crossing = registry.plan("staggered", graph, starts, goals)
    assert not crossing.solved and crossing.reason == "agents 0 and 1 collide at step 1"
    assert [v.kind for v in validate(graph, crossing.paths, starts, goals,
                                     crossing.lengths)] == ["vertex"]
    waiting = registry.plan("staggered", graph, starts, goals, stagger=1)
    assert waiting.solved and validate(graph, waiting.paths, starts, goals,
                                       waiting.lengths) == []
    assert waiting.lengths.tolist() == [2, 3]  # by hand: two moves; one wait and two moves
    with pytest.raises(ValueError, match="registered already"):
        registry.register("staggered", example)


def test_the_command_and_the_study_offer_a_registered_planner(example, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["mapf", "x.map", "x.scen", "--planner", "staggered", "--w", "1.5"])
    assert stop.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1].endswith(
        "--w applies to --planner ecbs or eecbs, not staggered")
    with pytest.raises(SystemExit):
        main(["mapf", "--help"])
    assert "staggered: staggered (example)" in " ".join(capsys.readouterr().out.split())
    study = load_script("sweeps/mapf_study.py")
    assert study.PLANNERS[-3:] == ("staggered", "pymapf lacam", "pymapf cbs")
    assert study.LABELS["staggered"] == "staggered (example)" and "1" in study.MARKERS
    assert "staggered" in [call[0] for call in study.planner_calls(1, 5.0, 1.2, False)]
