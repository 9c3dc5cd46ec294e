"""No repeated code across the package and the table scripts: pylint's duplicate-code checker
over ``jaxswarm/`` and ``sweeps/`` together (the slow tier; the swarm families alone in the
default tier) finds no run of similar lines (imports, docstrings, comments and signatures
aside)."""
from __future__ import annotations

import subprocess
import sys

import pytest

from repo_scripts import ROOT

MIN_SIMILAR_LINES = 6
"""The shortest run of similar lines that counts as a duplicate."""
OPTIONS = ["--recursive=y", "--disable=all", "--enable=duplicate-code",
           f"--min-similarity-lines={MIN_SIMILAR_LINES}", "--ignore-imports=yes",
           "--ignore-docstrings=yes", "--ignore-comments=yes", "--ignore-signatures=yes",
           "--score=no"]
"""pylint's options of the check, run from the repository root on folders (``sweeps/`` is no
package: ``--recursive``)."""


@pytest.mark.parametrize("folders", [
    # The swarm families, where a new family most often repeats an old one's code (3 s).
    ["jaxswarm/swarm"],
    # The twin above; the whole package and the scripts, about 15 s.
    pytest.param(["jaxswarm", "sweeps"], marks=pytest.mark.slow),
], ids=" ".join)
def test_no_duplicate_code(folders):
    done = subprocess.run([sys.executable, "-m", "pylint", *OPTIONS, *folders], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, (
        f"pylint's duplicate-code check of {' '.join(folders)} failed (exit status "
        f"{done.returncode}):\n{done.stdout}{done.stderr}")
