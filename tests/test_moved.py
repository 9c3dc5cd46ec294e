"""0.4.0's import paths still work until 0.6.0: each gives the object from its new home, with a
``DeprecationWarning`` that names the new place; paths that did not move do not warn."""
from __future__ import annotations

import importlib
import sys
import warnings

import pytest

import jaxswarm

SHIMS = {
    "jaxswarm.graph": {"Graph": "jaxswarm.world.graph", "grid_graph": "jaxswarm.world.graph"},
    "jaxswarm.robot": {"dstar_robot": "jaxswarm.dynamic.robot",
                       "swarm_robot": "jaxswarm.dynamic.robot"},
    "jaxswarm.maps.plane": {"shortest_path": "jaxswarm.exact.visibility",
                            "paper_plane": "jaxswarm.maps.planes",
                            "Plane": "jaxswarm.world.plane"},
}
"""The old modules (files that only forward) and names in them, with each name's new home."""
FORWARDING_PACKAGES = {
    "jaxswarm.plot": {"plot_solutions": "jaxswarm.plot.graph"},
    "jaxswarm.dynamic": {"change": "jaxswarm.dynamic.events",
                         "make_event": "jaxswarm.dynamic.events"},
}
"""0.4.0's modules that became packages: their old names are forwarded from the package."""


@pytest.fixture
def fresh(monkeypatch):
    """Forget an already imported module (until the test ends), so that importing it runs it."""

    def forget(module: str) -> None:
        parent, _, child = module.rpartition(".")
        monkeypatch.delitem(sys.modules, module, raising=False)
        monkeypatch.delattr(sys.modules[parent], child, raising=False)

    return forget


def from_import(module: str, name: str):
    """``from <module> import <name>``, spelt as a statement (the path users wrote)."""
    scope: dict = {}
    exec(f"from {module} import {name} as value", scope)  # noqa: S102 - a fixed import line
    return scope["value"]


@pytest.mark.parametrize("module, name, home", [(m, n, h) for m, names in SHIMS.items()
                                                 for n, h in names.items()])
def test_an_old_module_path_forwards_with_a_warning(fresh, module, name, home):
    fresh(module)
    with pytest.warns(DeprecationWarning) as caught:
        value = from_import(module, name)
    assert value is getattr(importlib.import_module(home), name)
    messages = [str(w.message) for w in caught if w.category is DeprecationWarning]
    assert any(f"{module} moved to" in m and "0.6.0" in m for m in messages), messages  # import
    assert f"{module}.{name} moved to {home}.{name}" in " ".join(messages)  # the name


@pytest.mark.parametrize("package, name, home", [
    (p, n, h) for p, names in FORWARDING_PACKAGES.items() for n, h in names.items()])
def test_an_old_name_of_a_module_that_became_a_package_forwards_with_a_warning(package, name,
                                                                               home):
    with pytest.warns(DeprecationWarning, match=f"{package}.{name} moved to {home}.{name}"):
        value = from_import(package, name)
    assert value is getattr(importlib.import_module(home), name)


def test_the_old_module_paths_warn_once_imported_too():
    """A second import of a shim (already in ``sys.modules``) still warns for each name."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # the first import's, if it is one
        importlib.import_module("jaxswarm.graph")
    with pytest.warns(DeprecationWarning, match="jaxswarm.graph.Graph moved"):
        from jaxswarm.graph import Graph
    assert Graph is jaxswarm.world.graph.Graph


@pytest.mark.parametrize("module", [*SHIMS, *FORWARDING_PACKAGES])
def test_a_name_that_never_lived_there_is_an_import_error(module):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # the import of a shim itself
        importlib.import_module(module)
        with pytest.raises(ImportError, match="no_such_name"):
            from_import(module, "no_such_name")


def test_a_path_that_did_not_move_does_not_warn(fresh):
    import jaxswarm.world.graph

    fresh("jaxswarm.maps.movingai")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_map = from_import("jaxswarm.maps.movingai", "load_map")
        graph = from_import("jaxswarm.world.graph", "Graph")
    assert load_map is sys.modules["jaxswarm.maps.movingai"].load_map
    assert graph is jaxswarm.world.graph.Graph
