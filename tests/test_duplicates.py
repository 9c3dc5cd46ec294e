"""No repeated code across the package and the table scripts: pylint's duplicate-code checker
over ``jaxswarm/`` and ``sweeps/`` together finds no run of similar lines (imports, docstrings,
comments and signatures aside)."""
from __future__ import annotations

import subprocess
import sys

from repo_scripts import ROOT

MIN_SIMILAR_LINES = 6
"""The shortest run of similar lines that counts as a duplicate."""
COMMAND = [sys.executable, "-m", "pylint", "--recursive=y", "--disable=all",
           "--enable=duplicate-code", f"--min-similarity-lines={MIN_SIMILAR_LINES}",
           "--ignore-imports=yes", "--ignore-docstrings=yes", "--ignore-comments=yes",
           "--ignore-signatures=yes", "--score=no", "jaxswarm", "sweeps"]
"""The check, run from the repository root (``sweeps/`` is no package: ``--recursive``)."""


def test_no_duplicate_code_in_the_package_and_the_scripts():
    done = subprocess.run(COMMAND, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, (
        f"pylint's duplicate-code check failed (exit status {done.returncode}):\n"
        f"{done.stdout}{done.stderr}")
