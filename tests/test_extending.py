"""The extending guide's new swarm (``docs/examples/trail_swarm.py``): one file and one registry
entry, and it passes the conformance suite every registered walker passes; what it does not
declare (a drawing of its memory, a change rule) is a clear error where it is asked for; the
names the protocol's reshaping moved forward with a warning."""
import importlib
import re
import runpy

import jax
import numpy as np
import pytest
import sizes
from conformance import field, maze  # noqa: F401 (fixtures)
from repo_scripts import ROOT
from test_conformance import WalkerConformance, walled  # noqa: F401 (fixture)

from jaxswarm.dynamic.rules import change_rule
from jaxswarm.plot.memory import MEMORY, MemoryView, memory_view
from jaxswarm.swarm import make, registry
from jaxswarm.swarm.core import ParamError


@pytest.fixture(scope="module", autouse=True)
def trail():
    """The example registered for this module's tests (the registry as it was after)."""
    before = dict(registry.REGISTRY)
    runpy.run_path(str(ROOT / "docs" / "examples" / "trail_swarm.py"))
    yield registry.entry("trail")
    registry.REGISTRY.clear()
    registry.REGISTRY.update(before)


class TestTrailConformance(WalkerConformance):
    name = "trail"


def test_the_example_is_one_entry_with_checked_options_and_params(trail):
    assert registry.config_options("trail") == ("num_agents", "max_steps", "walker")
    assert not trail.faithful and "trail" in registry.registered()
    with pytest.raises(ValueError, match="unknown option 'decay' of trail"):
        make("trail", decay=0.5)
    swarm = make("trail", **sizes.CONFIG)
    with pytest.raises(ParamError, match="decay"):
        swarm.check_params(swarm.params_with(decay=1.5))
    with pytest.raises(ValueError, match="registered already"):
        registry.register("trail", trail)


def test_what_the_example_does_not_declare_is_a_clear_error(monkeypatch):
    swarm = make("trail", **sizes.CONFIG)
    with pytest.raises(ValueError, match="'trail' has no drawing of its memory: add one to "
                                         "jaxswarm.plot.memory.MEMORY"):
        memory_view(swarm)
    with pytest.raises(ValueError, match="'trail' has no rule for a change of its world"):
        change_rule(swarm)
    view = MemoryView(lambda state: state.trail, "trail")
    monkeypatch.setitem(MEMORY, "trail", view)
    assert memory_view(swarm) is view


def test_two_steps_lay_the_trail_as_computed_by_hand(maze):
    # trail_1 = deposit on the best path's nodes; trail_2 = (1 - decay) trail_1 + the same on
    # the (possibly new) best path's, 0 elsewhere (each best path found).
    graph, task, _ = maze
    swarm = make("trail", **sizes.CONFIG)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    expected = np.zeros(graph.num_nodes, np.float32)
    for _ in range(2):
        state, _ = swarm.step(state, graph, task, params)
        path = np.asarray(state.best_path)
        assert np.isfinite(float(state.best_cost)), "no agent arrived"
        on = np.zeros(graph.num_nodes, bool)
        on[path[path >= 0]] = True
        expected = (np.float32(1) - params.decay) * expected + np.where(on, params.deposit, 0)
        np.testing.assert_allclose(np.asarray(state.trail), expected, rtol=1e-6)


@pytest.mark.parametrize("old, new", [
    ("jaxswarm.swarm.core.run", "jaxswarm.swarm.executor.run"),
    ("jaxswarm.swarm.core.with_room", "jaxswarm.swarm.executor.with_room"),
    ("jaxswarm.swarm.core.again_with_room", "jaxswarm.swarm.executor.retried"),
    ("jaxswarm.dynamic.events.memory_frames", "jaxswarm.plot.memory.memory_frames")])
def test_moved_names_forward_with_a_warning_until_0_12(old, new):
    module, name = old.rsplit(".", 1)
    home, moved = new.rsplit(".", 1)
    with pytest.warns(DeprecationWarning, match=rf"{re.escape(old)} is .*0\.12\.0"):
        found = getattr(importlib.import_module(module), name)
    assert found is getattr(importlib.import_module(home), moved)
