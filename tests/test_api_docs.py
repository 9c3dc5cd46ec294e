"""The API reference (``make docs``) builds from the docstrings without a warning, every Sphinx
role of a docstring (``:func:`name```, ...) becomes a link, and every public function, class,
method and property has a docstring. Built once, without the source views and the search index
(the rest of the pages is what ``make docs`` writes)."""
from __future__ import annotations

import pytest
from repo_scripts import load_script

build_api = load_script("docs/build_api.py")


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("api")
    modules, caught = build_api.build(out, source=False, search=False)
    return out, modules, caught


def listed(problems) -> str:
    return "\n".join(str(problem) for problem in problems)


def test_pdoc_emits_no_warning(reference):
    _, _, caught = reference
    assert not caught, "pdoc warned:\n" + "\n".join(
        f"{w.filename}:{w.lineno}: {w.message}" for w in caught)


def test_every_public_object_has_a_docstring(reference):
    _, modules, _ = reference
    missing = build_api.missing_docstrings(modules)
    assert not missing, f"{len(missing)} public objects without a docstring:\n{listed(missing)}"


def test_every_cross_reference_is_a_link(reference):
    _, modules, _ = reference
    broken = build_api.broken_references(modules)
    assert not broken, f"{len(broken)} references pdoc does not link:\n{listed(broken)}"


def test_every_room_is_documented(reference):
    out, modules, _ = reference
    rooms = ["world", "maps", "exact", "swarm", "dynamic", "multiagent", "sweep", "plot",
             "runtime", "studies"]
    for name in ["jaxswarm", "jaxswarm.cli", *(f"jaxswarm.{room}" for room in rooms),
                 "jaxswarm.world.graph", "jaxswarm.swarm.core", "jaxswarm.exact.astar"]:
        assert name in modules, name
        assert (out / f"{name.replace('.', '/')}.html").is_file(), name
    assert not [name for name in modules if any(p.startswith("_") for p in name.split("."))]


def test_the_roles_render_as_links(reference):
    """The package page links its rooms (``:mod:``, under the package's ``__all__``) and a
    function in another module (``:func:`jaxswarm.runtime.cpu.configure```)."""
    out, _, _ = reference
    page = (out / "jaxswarm.html").read_text()
    assert 'href="jaxswarm/runtime/cpu.html#configure"' in page
    for room in ["world", "maps", "exact", "swarm", "multiagent", "dynamic", "plot"]:
        assert f'href="jaxswarm/{room}.html"' in page, room
    assert ":func:" not in page and ":mod:" not in page and "~jaxswarm" not in page
