"""The API reference, generated from the docstrings with pdoc: ``make docs`` writes it into
``docs/api/`` (open ``docs/api/index.html``); ``tests/test_api_docs.py`` builds it into a
temporary folder and fails on pdoc's warnings, on cross-references that do not become links and
on public functions, classes and methods without a docstring.

    python docs/build_api.py [OUT]      # default OUT: docs/api; lists what check() finds

The docstrings are Google style (``Args:``, ``Returns:``) with Sphinx roles (``:func:`name```,
``:mod:`~package.module```), so pdoc runs with ``docformat="google"``, which also reads the roles
as code that pdoc links to the object it names. Beyond pdoc's defaults:

* every public module of the package is documented and listed under its package, whatever the
  package's ``__all__`` says (pdoc would document only the submodules that ``__all__`` names,
  and ``jaxswarm.__all__`` names the few functions a user needs first);
* the deprecation shims (``jaxswarm.graph``, ``jaxswarm.robot``, ``jaxswarm.maps.plane``) and the
  private modules are left out;
* a role's ``~`` (Sphinx's "show the last part only") is dropped before pdoc reads the role, so
  that ``:class:`~jaxswarm.world.graph.Graph``` becomes a link rather than ``~`` and a link,
  and the ``::`` that opens a literal block reads ``:``, as reStructuredText shows it;
* the fields of a ``NamedTuple`` whose module postpones annotations (``from __future__ import
  annotations``) are resolved in that module (pdoc looks for them in the namespace
  ``collections.namedtuple`` builds the constructor in, and warns).
"""
from __future__ import annotations

import contextlib
import functools
import importlib
import inspect
import os
import pkgutil
import re
import sys
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import NamedTuple

import pdoc
import pdoc.doc
import pdoc.docstrings
import pdoc.extract
import pdoc.render
import pdoc.render_helpers

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "jaxswarm"
SPECS = (PACKAGE, r"!.*\._")
"""pdoc's module specifications: the package and all its modules, less the private modules
(``!`` drops the names the pattern matches)."""
DOCFORMAT = "google"
ROLE = re.compile(r"(?::py)?:(mod|func|data|const|class|meth|attr|exc|obj):`(~?)([^`]+)`")
"""A Sphinx cross-reference role, as pdoc's reStructuredText conversion reads it."""
LITERAL_MARK = re.compile(r"(\S)::$", re.MULTILINE)
"""reStructuredText's ``text::`` before an indented literal block (Markdown's code block)."""


class Problem(NamedTuple):
    """Something to fix in a docstring.

    Attributes:
      file: the source file, relative to the repository root.
      line: the line of the object's definition (1 for a module).
      name: the object's full name where it is defined.
      what: ``"no docstring"``, or ``"reference :func:`name` is not a link"`` and the pages.
    """

    file: str
    line: int
    name: str
    what: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: {self.name}: {self.what}"


def configure(*, source: bool = True, search: bool = True) -> None:
    """Set pdoc's rendering options and the departures from its defaults listed in the module
    docstring; safe to call again.

    Args:
      source: whether each object's page shows its source (most of the rendering time).
      search: whether to write the search index (``search.js``; pdoc compiles it with Node.js
        where there is one).
    """
    version = importlib.import_module(PACKAGE).__version__
    pdoc.render.configure(docformat=DOCFORMAT, show_source=source, search=search,
                          footer_text=f"{PACKAGE} {version}")
    _patch_pdoc()


def _patch_pdoc() -> None:
    """The departures from pdoc's defaults that the module docstring lists, made once."""
    if getattr(pdoc.docstrings.rst, "drops_tilde", False):
        return
    original = pdoc.docstrings.rst

    @functools.wraps(original)
    def rst(contents: str, source_file: Path | None) -> str:
        contents = LITERAL_MARK.sub(r"\1:", ROLE.sub(lambda m: f":{m[1]}:`{m[3]}`", contents))
        return original(contents, source_file)

    rst.drops_tilde = True
    pdoc.docstrings.rst = rst
    pdoc.extract.iter_modules2 = _child_modules
    pdoc.doc.Module.submodules = functools.cached_property(_documented_submodules)
    pdoc.doc.Module.submodules.__set_name__(pdoc.doc.Module, "submodules")


def _child_modules(module) -> dict[str, pkgutil.ModuleInfo]:
    """A package's direct submodules by short name, whether or not its ``__all__`` names them
    (pdoc's ``extract.iter_modules2`` without that filter)."""
    return {info.name.rpartition(".")[2]: info
            for info in pkgutil.iter_modules(getattr(module, "__path__", []),
                                             f"{module.__name__}.")}


def _documented_submodules(module: pdoc.doc.Module) -> list[pdoc.doc.Module]:
    """The submodules a package's page lists: the public ones."""
    return [pdoc.doc.Module.from_name(info.name)
            for short, info in _child_modules(module.obj).items() if not short.startswith("_")]


def module_names() -> list[str]:
    """Every module the reference documents, each package before its modules."""
    _patch_pdoc()
    return pdoc.extract.walk_specs(SPECS)


@contextlib.contextmanager
def _namedtuple_fields_in_their_modules(names: list[str]) -> Iterator[None]:
    """While open, the constructor of every NamedTuple of the modules ``names`` says it belongs
    to the NamedTuple's module, where pdoc then resolves its postponed field annotations."""
    moved = []
    for name in names:
        for value in list(vars(importlib.import_module(name)).values()):
            if isinstance(value, type) and issubclass(value, tuple) and hasattr(value, "_fields"):
                new = value.__new__
                if getattr(new, "__module__", "").startswith("namedtuple_"):
                    moved.append((new, new.__module__))
                    new.__module__ = value.__module__
    try:
        yield
    finally:
        for new, module in moved:
            new.__module__ = module


def build(out: Path, *, source: bool = True, search: bool = True
          ) -> tuple[dict[str, pdoc.doc.Module], list[warnings.WarningMessage]]:
    """Write the HTML reference of :data:`SPECS` into ``out`` with ``pdoc.pdoc``.

    Args:
      out: the folder to write (``index.html``, one page per module, ``search.js``).
      source: whether the pages show the source (see :func:`configure`).
      search: whether to write the search index (see :func:`configure`).

    Returns:
      The documented modules by name, and the warnings pdoc emitted while reading and rendering
      them (a module it could not import, a name of ``__all__`` that does not resolve, a type
      annotation it could not read, a docstring it could not convert, ...).
    """
    configure(source=source, search=search)
    # pdoc hides a constant whose value is also an environment variable's, for fear of secrets;
    # jaxswarm's own constants are public, and one (the instruction set flag) is what importing
    # jaxswarm puts in $XLA_FLAGS.
    os.environ["PDOC_DISPLAY_ENV_VARS"] = "1"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        names = module_names()
        with _namedtuple_fields_in_their_modules(names):
            pdoc.pdoc(*SPECS, output_directory=Path(out))
            modules = {name: pdoc.doc.Module.from_name(name) for name in names}
    pdoc_dir = str(Path(pdoc.__file__).parent)
    return modules, [w for w in caught if w.filename.startswith(pdoc_dir)]


def _is_public(doc: pdoc.doc.Doc, page: pdoc.doc.Module, modules: dict) -> str:
    """pdoc's ``is_public`` template macro (default template, ``include_undocumented``): any
    text for a member the page shows, ``""`` for one it hides."""
    if "@private" in doc.docstring:
        return ""
    if "@public" in doc.docstring:
        return "true"
    if doc.name == "__init__" and (doc.docstring or (
            doc.kind == "function" and doc.signature_without_self.parameters)):
        return "true"
    if doc.name == "__doc__" or (doc.kind == "variable" and doc.is_typevar and not doc.docstring):
        return ""
    if doc.kind == "module" and doc.fullname not in modules:
        return ""
    if (doc.qualname or doc.name) in (getattr(page.obj, "__all__", None) or []):
        return "true"
    return "" if doc.name.startswith("_") else "true"


def _shown(page: pdoc.doc.Module, modules: dict) -> Iterator[pdoc.doc.Doc]:
    """Every object whose docstring ``page`` shows: the module, its public members and, in a
    public class, its own public members (recursively)."""
    yield page
    todo = [page]
    while todo:
        for doc in todo.pop().own_members:
            if _is_public(doc, page, modules):
                yield doc
                if isinstance(doc, pdoc.doc.Class):
                    todo.append(doc)


def _where(doc: pdoc.doc.Doc) -> tuple[str, int, str]:
    """(file relative to the repository, line, full name) of the object's definition."""
    module, qualname = doc.taken_from
    path = doc.source_file
    try:
        file = str(Path(path).resolve().relative_to(ROOT)) if path else module
    except ValueError:
        file = str(path)
    line = doc.source_lines[0] if doc.kind != "module" and doc.source_lines else 1
    return file, line, f"{module}.{qualname}".rstrip(".")


def _is_method_like(doc: pdoc.doc.Doc, owner) -> bool:
    """Whether ``doc`` is a function, a class, or a property of class ``owner``."""
    if isinstance(doc, (pdoc.doc.Function, pdoc.doc.Class)):
        return True
    static = inspect.getattr_static(owner, doc.name, None) if owner is not None else None
    return isinstance(static, (property, functools.cached_property))


def missing_docstrings(modules: dict[str, pdoc.doc.Module]) -> list[Problem]:
    """The public functions, classes, methods and properties the reference shows without a
    docstring (also those reached through a package's ``__all__``), each once, where defined."""
    found = set()
    for page in modules.values():
        for doc in _shown(page, modules):
            if doc.kind == "module" or doc.docstring.strip() or doc.name.startswith("_") \
                    or not doc.taken_from[0].startswith(PACKAGE):  # numba's njit, say
                continue
            owner_name = doc.qualname.rpartition(".")[0]
            owner = page.get(owner_name).obj if owner_name else None
            if _is_method_like(doc, owner):
                found.add(Problem(*_where(doc), "no docstring"))
    return sorted(found)


def _external(target: str) -> bool:
    """Whether a reference names something outside the package (``jax.Array``, ``np.ndarray``):
    pdoc cannot link those, and they are not broken."""
    head = target.lstrip(".").split(".")[0]
    return "." in target and head != PACKAGE and (head in sys.modules or head in {"np", "jnp"})


def broken_references(modules: dict[str, pdoc.doc.Module]) -> list[Problem]:
    """The roles (``:func:`name```, ...) of the docstrings that pdoc does not turn into a link
    on some page that shows them (a misspelt or moved name, a private or undocumented target, a
    name the page's module neither defines nor exports), each with the pages."""
    pages: dict[tuple, list[str]] = {}
    for page in modules.values():
        context = {"module": page, "all_modules": modules,
                   "is_public": functools.partial(_is_public, page=page, modules=modules)}
        for doc in _shown(page, modules):
            for role, _, target in ROLE.findall(doc.docstring):
                if _external(target):
                    continue
                code = f"{target}()" if role in ("func", "meth") else target
                html = pdoc.render_helpers.linkify(context, f"<code>{code}</code>",
                                                   namespace=doc.qualname)
                if "<a " not in html:
                    key = (*_where(doc), f":{role}:`{target}`")
                    pages.setdefault(key, []).append(page.fullname)
    return sorted(Problem(file, line, name, f"reference {ref} is not a link on "
                          f"{', '.join(sorted(set(on)))}")
                  for (file, line, name, ref), on in pages.items())


def check(modules: dict[str, pdoc.doc.Module]) -> list[Problem]:
    """:func:`missing_docstrings` and :func:`broken_references`, by file and line."""
    return sorted(missing_docstrings(modules) + broken_references(modules))


def main(argv: list[str] | None = None) -> int:
    """``python docs/build_api.py [OUT]``: build the reference, then list pdoc's warnings and
    what :func:`check` finds (the tests fail on them; the build does not)."""
    args = sys.argv[1:] if argv is None else argv
    out = Path(args[0]) if args else ROOT / "docs" / "api"
    modules, caught = build(out)
    for warning in caught:
        print(f"pdoc warning: {warning.message}", file=sys.stderr)
    for problem in check(modules):
        print(problem, file=sys.stderr)
    print(f"{len(modules)} modules documented in {out}/index.html")
    return 0


if __name__ == "__main__":
    sys.exit(main())
