"""jaxswarm.runtime.native: a C++ kernel called from jitted programs through XLA's typed FFI:
bit for bit the walker's uniforms under jit, vmap, a custom_vmap rule
and shard_map over two CPU devices, and its programs kept in JAX's persistent cache."""
import json
import os
import shutil
import subprocess
import sys
import textwrap

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from jax.custom_batching import custom_vmap

from jaxswarm.runtime import native
from jaxswarm.swarm.walking.streams import uniforms

pytestmark = pytest.mark.skipif(
    not os.environ.get("CXX") and not any(shutil.which(c) for c in native.COMPILERS),
    reason="no C++ compiler")

AGENTS = 300
SEEDS = np.array([[123, 4567], [0xFFFFFFFF, 0], [7, 0x9E3779B1]], np.uint32)


def bits(x) -> np.ndarray:
    return np.asarray(x).view(np.uint32)


def inputs():
    agent = np.arange(AGENTS, dtype=np.int32) - 5  # negative agents wrap as uint32, as in JAX
    move = (np.arange(AGENTS, dtype=np.int32) * 7919) ^ np.int32(0x7FFFFFFF)
    return agent, move


def test_uniforms_are_the_walkers_bit_for_bit_under_jit():
    agent, move = inputs()
    for seed in SEEDS:
        assert np.array_equal(bits(jax.jit(native.uniforms)(seed, agent, move)),
                              bits(uniforms(jnp.asarray(seed), agent, move)))
    # Broadcasting as streams.uniforms does: a scalar draw, and a seed per element.
    assert bits(native.uniforms(SEEDS[0], np.int32(3), np.int32(4))) == bits(
        uniforms(jnp.asarray(SEEDS[0]), jnp.int32(3), jnp.int32(4)))
    per_element = np.repeat(SEEDS, 2, axis=0)[:, None, :]  # u32[6, 1, 2] against i32[6, 4]
    grid = np.arange(24, dtype=np.int32).reshape(6, 4)
    assert np.array_equal(bits(native.uniforms(per_element, grid, grid)),
                          bits(uniforms(jnp.asarray(per_element), grid, grid)))


def test_vmap_calls_the_kernel_once_for_the_whole_batch():
    agent, move = inputs()
    moves = np.stack([move + k for k in range(len(SEEDS))])
    batched = jax.jit(jax.vmap(native.uniforms, in_axes=(0, None, 0)))
    assert np.array_equal(bits(batched(SEEDS, agent, moves)),
                          bits(jax.vmap(uniforms, in_axes=(0, None, 0))(SEEDS, agent, moves)))
    text = batched.lower(SEEDS, agent, moves).as_text()
    assert text.count(f"custom_call @{native.UNIFORMS_TARGET}(") == 1
    assert "tensor<3x300xf32>" in text


def test_a_custom_vmap_rule_calls_it_once_per_batch():
    """As the walker's rule would: its batch rule hands the whole batch to one kernel call."""
    calls = []

    @custom_vmap
    def draw(seed, agent, move):
        return native.uniforms(seed, agent, move)

    @draw.def_vmap
    def rule(axis_size, in_batched, seed, agent, move):
        calls.append(axis_size)
        seed, agent, move = (x if b else jnp.broadcast_to(x, (axis_size,) + x.shape)
                             for x, b in zip((seed, agent, move), in_batched))
        # A seed row per batch member: u32[B, 1, 2] against i32[B, A].
        return native.uniforms(seed[:, None, :], agent, move), True

    agent, move = inputs()
    moves = np.stack([move - k for k in range(len(SEEDS))])
    got = jax.jit(jax.vmap(draw, in_axes=(0, None, 0)))(SEEDS, agent, moves)
    assert calls == [len(SEEDS)]
    assert np.array_equal(bits(got), bits(jax.vmap(uniforms, in_axes=(0, None, 0))(
        SEEDS, agent, moves)))


PROBE = """
import json, logging, threading, time
import jax, jax.numpy as jnp, numpy as np
import jaxswarm  # enables the cache JAXSWARM_CACHE names
from jax.sharding import PartitionSpec as P
from jaxswarm.runtime import native
from jaxswarm.swarm.walking.streams import uniforms

class Programs(logging.Handler):  # the programs JAX writes to and reads from its cache
    written, read = [], []
    def emit(self, record):
        if record.msg.startswith("Writing %s to persistent"):
            self.written.append(record.args[0])
        elif record.msg.startswith("Persistent compilation cache hit"):
            self.read.append(record.args[0])
for name in ("jax._src.compiler", "jax._src.compilation_cache"):
    logging.getLogger(name).addHandler(Programs())
    logging.getLogger(name).setLevel(logging.DEBUG)
events = []
jax.monitoring.register_event_listener(lambda event, **_: events.append(event))
started = time.perf_counter()
native.register()
registered = time.perf_counter() - started
mesh = jax.sharding.Mesh(np.asarray(jax.devices()), ("runs",))
seeds = np.arange(2 * RUNS, dtype=np.uint32).reshape(RUNS, 2) * np.uint32(2654435761)
agent = np.arange(AGENTS, dtype=np.int32)
moves = np.arange(RUNS * AGENTS, dtype=np.int32).reshape(RUNS, AGENTS)

def native_draws(seeds, agent, moves):
    return jax.vmap(native.uniforms, in_axes=(0, None, 0))(seeds, agent, moves)

sharded = jax.jit(jax.shard_map(native_draws, mesh=mesh, in_specs=(P("runs"), P(), P("runs")),
                                out_specs=P("runs")))
calls = sharded.lower(seeds, agent, moves).as_text().count("custom_call @" + native.UNIFORMS_TARGET)
got = sharded(seeds, agent, moves)
want = np.asarray(jax.jit(jax.vmap(uniforms, in_axes=(0, None, 0)))(seeds, agent, moves))
same = bool(np.array_equal(np.asarray(got).view(np.uint32), want.view(np.uint32)))
# Two host threads calling the same compiled program at once, each on both devices.
results = []
def call():
    for _ in range(5):
        results.append(np.asarray(sharded(seeds, agent, moves)).view(np.uint32))
threads = [threading.Thread(target=call) for _ in range(2)]
[t.start() for t in threads]
[t.join() for t in threads]
threaded = len(results) == 10 and all(np.array_equal(r, want.view(np.uint32)) for r in results)
print(json.dumps({"devices": len(jax.devices()), "same": same, "threaded": threaded,
                  "shards": len(got.sharding.device_set), "calls": calls,
                  "registered_s": registered, "written": Programs.written, "read": Programs.read,
                  "hits": events.count("/jax/compilation_cache/cache_hits")}))
"""


def run_probe(tmp_path, environment) -> dict:
    script = tmp_path / "probe.py"
    script.write_text(textwrap.dedent(PROBE).replace("RUNS", "8").replace("AGENTS", "4096"))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=300, env=environment)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_shard_map_over_two_devices_and_the_persistent_cache(tmp_path):
    """Two devices run their shards at once (and two host threads the program at once): the
    kernel keeps no state. A second process reads the program with the custom call from the
    persistent cache instead of compiling it (and finds the library already built)."""
    environment = dict(os.environ, JAXSWARM_CACHE=str(tmp_path / "cache"),
                       XLA_FLAGS=(os.environ.get("XLA_FLAGS", "")
                                  + " --xla_force_host_platform_device_count=2").strip())
    environment.pop("NUMBA_CACHE_DIR", None)
    first = run_probe(tmp_path, environment)
    assert first["devices"] == 2 and first["shards"] == 2 and first["calls"] == 1
    assert first["same"] and first["threaded"]
    assert "jit_native_draws" in first["written"] and not first["read"] and not first["hits"]
    assert len(list((tmp_path / "cache" / "native").glob("kernels-*.so"))) == 1
    second = run_probe(tmp_path, environment)
    assert second["same"] and second["threaded"]
    assert "jit_native_draws" in second["read"] and not second["written"]
    assert second["hits"] == len(second["read"])
    assert second["registered_s"] < first["registered_s"]


def test_no_compiler_is_a_clear_error(tmp_path, monkeypatch):
    monkeypatch.setenv("CXX", str(tmp_path / "no-such-compiler"))
    with pytest.raises(native.NativeUnavailable, match="no C.. compiler found"):
        native.build(tmp_path)
