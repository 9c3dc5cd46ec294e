"""Every Python snippet of the README and of docs/ runs as written, from the repository root, and
prints what the document says it prints.

The snippets of one file run in order in one interpreter (later ones may use what earlier ones
defined), in a subprocess, as a reader would run them from the repository root: here from a view
of it (links to its files, with ``../shared`` beside it), so that what they write under ``out/``
stays in the test's folder. A snippet that prints is followed by a block fenced as ``output``
holding what it prints, where ``...`` stands for any text (doctest's ELLIPSIS; runs of spaces
compare equal). A snippet that needs what a test machine lacks is marked in the Markdown by the line
``<!-- skip: REASON -->`` right above it; the test checks that every skipped one is marked so.

Running the snippets compiles the programs of their own sizes in processes of their own, so they
run in the slow tier; their twin in the default tier compiles each snippet and imports every name
it imports, which fails on the usual way a snippet goes stale (a renamed or moved name).
"""
from __future__ import annotations

import doctest
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import SHARED
from repo_scripts import import_what_it_imports

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
SNIPPET = re.compile(r"(?:<!-- skip: (?P<skip>[^>]*) -->\n)?```python\n(?P<code>.*?)```\n"
                     r"(?:\n?```output\n(?P<output>.*?)```\n)?", re.DOTALL)
MARKER = "<<< end of snippet {} >>>"
"""Printed after each snippet, to split the interpreter's output by snippet."""
CHECKER = doctest.OutputChecker()
OPTIONS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def snippets(document: Path) -> list[tuple[str | None, str, str]]:
    """``(skip reason or None, code, expected output)`` of every Python snippet of
    ``document``, in order (the output is empty where the snippet has no output block)."""
    return [(m["skip"], m["code"], m["output"] or "")
            for m in SNIPPET.finditer(document.read_text())]


def test_the_documents_have_snippets_and_mark_what_they_skip():
    found = {path.name: snippets(path) for path in DOCUMENTS}
    assert found["README.md"] and found["sweeps.md"]
    skipped = [reason for blocks in found.values() for reason, _, _ in blocks if reason]
    assert skipped == ["needs several hosts"]  # the multi-host sweep, nothing else


def test_the_checker_tells_a_wrong_output():
    assert CHECKER.check_output("27.79 ...\n", "27.79   True 40\n", OPTIONS)
    assert not CHECKER.check_output("27.79 ...\n", "28.04 True 40\n", OPTIONS)


def root_view(folder: Path) -> Path:
    """``folder/repo``: a link to each top-level entry of the repository but ``out/``, beside
    ``folder/shared``, a link to the shared data."""
    view = folder / "repo"
    view.mkdir()
    for entry in ROOT.iterdir():
        if entry.name != "out":
            (view / entry.name).symlink_to(entry)
    (folder / "shared").symlink_to(SHARED)
    return view


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda path: path.name)
def test_every_snippet_parses_and_its_imports_resolve(document):
    for skip, code, _ in snippets(document):
        if skip is not None:
            continue
        import_what_it_imports(code, f"{document.name} snippet")


@pytest.mark.slow  # processes of their own, at the snippets' sizes (twin: the test above)
@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda path: path.name)
def test_every_snippet_runs_as_written_and_prints_what_it_says(document, tmp_path):
    blocks = [(code, output) for skip, code, output in snippets(document) if skip is None]
    if not blocks:
        pytest.skip(f"{document.name} has no Python snippet")
    script = tmp_path / f"{document.stem}_snippets.py"
    script.write_text("".join(f"{code}\nprint({MARKER.format(i)!r}, flush=True)\n"
                              for i, (code, _) in enumerate(blocks)))
    done = subprocess.run([sys.executable, str(script)], cwd=root_view(tmp_path),
                          capture_output=True,
                          text=True, timeout=600,
                          env=dict(os.environ, JAX_PLATFORMS="cpu", MPLBACKEND="Agg"))
    assert done.returncode == 0, f"{document.name}:\n{done.stderr[-3000:]}"
    printed = re.split("|".join(re.escape(MARKER.format(i)) + r"\n"
                                for i in range(len(blocks))), done.stdout)
    for i, ((code, expected), got) in enumerate(zip(blocks, printed)):
        assert CHECKER.check_output(expected, got, OPTIONS), (
            f"{document.name}, snippet {i + 1} ({code.splitlines()[0]!r}) printed:\n{got}"
            f"which is not its output block:\n{expected}")
