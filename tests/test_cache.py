"""jaxswarm.runtime.cache: compiled programs kept between processes (JAX's and numba's)."""
import json
import os
import subprocess
import sys

import pytest

from jaxswarm.runtime.cache import VARIABLE, enable, from_environment

PROBE = """
import json, jax, jax.numpy as jnp, numba
import jaxswarm  # enables the cache JAXSWARM_CACHE names, before anything compiles
hits = []
jax.monitoring.register_event_listener(
    lambda event, **_: hits.append(event) if event == "/jax/compilation_cache/cache_hits" else None)
jax.jit(lambda x: jnp.sin(x) * 2.0 + 1.0)(jnp.arange(7.0)).block_until_ready()

@numba.njit(cache=True)
def add_one(x):
    return x + 1

add_one(1)
print(json.dumps({"hits": len(hits)}))
"""


def run_probe(script, environment) -> dict:
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=300, env=environment)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_second_process_finds_what_the_first_compiled(tmp_path):
    script = tmp_path / "probe.py"
    script.write_text(PROBE)
    environment = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    environment[VARIABLE] = str(tmp_path / "cache")
    first = run_probe(script, environment)
    assert any((tmp_path / "cache" / "jax").iterdir())
    # numba's cache goes to the same folder (not beside the source): the index of add_one.
    assert list((tmp_path / "cache" / "numba").rglob("probe.add_one-*.nbi"))
    assert not list(tmp_path.glob("__pycache__/*.nbi"))
    second = run_probe(script, environment)
    assert first["hits"] == 0 and second["hits"] >= 1


def test_a_file_is_not_a_cache_folder(tmp_path):
    path = tmp_path / "a file"
    path.write_text("")
    with pytest.raises(ValueError, match=f"{VARIABLE}: .*a file is not a folder"):
        enable(path)


def test_an_unusable_folder_in_the_variable_is_a_warning_and_no_cache(tmp_path, monkeypatch):
    path = tmp_path / "a file"
    path.write_text("")
    monkeypatch.setenv(VARIABLE, str(path))
    with pytest.warns(RuntimeWarning, match=f"{VARIABLE}=.*is not used: .*not a folder"):
        assert from_environment() is None
    monkeypatch.setenv(VARIABLE, "")
    assert from_environment() is None
