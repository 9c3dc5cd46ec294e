"""The compile ledger (``compile_ledger.py``) run on a suite of its own, in a process of its own:
it counts a test file's programs and fails the default tier, naming the file, when a file builds
more than its budget."""
import os
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

NEW_PROGRAM = """
import jax
import jax.numpy as jnp

def test_a_program_of_its_own():
    assert int(jax.jit(lambda x: jnp.cumsum(x * 3))(jnp.arange(4))[-1]) == 18

def test_eager_operations_are_no_program():
    assert int(jnp.sum(jnp.arange(5) * 2)) == 20
"""


@pytest.fixture
def suite(pytester, monkeypatch):
    """A suite of one file that no budget names, whose process finds the ledger's plugin."""
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(
        [str(Path(__file__).parent), *filter(None, [os.environ.get("PYTHONPATH")])]))
    pytester.makepyfile(test_unbudgeted=NEW_PROGRAM)
    return pytester


def test_a_file_over_its_budget_fails_the_default_tier_naming_it(suite):
    done = suite.runpytest_subprocess("-p", "compile_ledger", "-m", "not slow", "-p",
                                      "no:cacheprovider", "--compile-ledger", "ledger.json")
    done.assert_outcomes(passed=2)
    assert done.ret == pytest.ExitCode.TESTS_FAILED
    done.stdout.fnmatch_lines([
        "*compile ledger (default tier): 1 programs (1 XLA, 0 numba)*",
        "OVER BUDGET: test_unbudgeted.py built 1 programs, over its budget of 0 in *<lambda>"])


def test_the_slow_tier_counts_but_has_no_budget(suite):
    done = suite.runpytest_subprocess("-p", "compile_ledger", "-m", "slow", "-p",
                                      "no:cacheprovider")
    assert done.ret == pytest.ExitCode.NO_TESTS_COLLECTED
    done.stdout.fnmatch_lines(["*compile ledger (slow tier): 0 programs*"])
    done.stdout.no_fnmatch_line("*OVER BUDGET*")
