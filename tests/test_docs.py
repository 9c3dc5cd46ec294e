"""Every Python snippet of the README and of docs/ runs as written, from the repository root.

The snippets of one file run in order in one interpreter (later ones may use what earlier ones
defined), in a subprocess whose working directory is the repository root, as a reader would run
them. A snippet that needs what a test machine lacks is marked in the Markdown by the line
``<!-- skip: REASON -->`` right above it; the test checks that every skipped one is marked so.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
SNIPPET_OUTPUTS = ["out/my_study"]
"""What the snippets write under the repository root."""

SNIPPET = re.compile(r"(?:<!-- skip: (?P<skip>[^>]*) -->\n)?```python\n(?P<code>.*?)```",
                     re.DOTALL)


def snippets(document: Path) -> list[tuple[str | None, str]]:
    """``(skip reason or None, code)`` of every Python snippet of ``document``, in order."""
    return [(m["skip"], m["code"]) for m in SNIPPET.finditer(document.read_text())]


def test_the_documents_have_snippets_and_mark_what_they_skip():
    found = {path.name: snippets(path) for path in DOCUMENTS}
    assert found["README.md"] and found["sweeps.md"]
    skipped = [reason for blocks in found.values() for reason, _ in blocks if reason]
    assert skipped == ["needs several hosts"]  # the multi-host sweep, nothing else


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda path: path.name)
def test_every_snippet_runs_as_written(document, tmp_path):
    code = "\n".join(code for skip, code in snippets(document) if skip is None)
    if not code:
        pytest.skip(f"{document.name} has no Python snippet")
    # The snippets run from the repository root, as a reader would; what an earlier version
    # wrote there would be refused as another swarm definition.
    for written in SNIPPET_OUTPUTS:
        shutil.rmtree(ROOT / written, ignore_errors=True)
    script = tmp_path / f"{document.stem}_snippets.py"
    script.write_text(code)
    done = subprocess.run([sys.executable, str(script)], cwd=ROOT, capture_output=True,
                          text=True, timeout=600,
                          env=dict(os.environ, JAX_PLATFORMS="cpu", MPLBACKEND="Agg"))
    assert done.returncode == 0, f"{document.name}:\n{done.stderr[-3000:]}"
