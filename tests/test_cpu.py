"""jaxswarm.runtime.cpu: devices and XLA's thread pool, set before JAX starts."""
import json
import subprocess
import sys

import jax.numpy as jnp
import pytest

from jaxswarm.runtime.cpu import configure

PROBE = """
import importlib, json, os, pkgutil
import jax
import jaxswarm
for module in pkgutil.walk_packages(jaxswarm.__path__, "jaxswarm."):
    importlib.import_module(module.name)
from jaxswarm.runtime.cpu import configure
configure(devices={devices}, threads={threads})  # after every import: none may start JAX
import jax.numpy as jnp
jnp.ones(3).block_until_ready()
names = [open(f"/proc/self/task/{{t}}/comm").read().strip() for t in os.listdir("/proc/self/task")]
print(json.dumps({{"devices": len(jax.devices()), "pool": sum(n.startswith("tf_XLAEigen")
                                                             for n in names)}}))
"""


@pytest.mark.parametrize("devices, threads", [(0, None), (None, 0), (1, 1.5), (-2, 1)])
def test_configure_names_a_bad_count(devices, threads):
    with pytest.raises(ValueError, match="must be a whole number of at least 1"):
        configure(devices=devices, threads=threads)


def test_configure_refuses_once_jax_has_started():
    jnp.ones(1).block_until_ready()
    with pytest.raises(RuntimeError, match="before JAX's first computation"):
        configure(threads=1)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/task")
@pytest.mark.parametrize("devices, threads, pool", [
    (2, 1, 2),
    # A process each, about 5 s: in the slow tier, their twin the case above.
    pytest.param(1, 1, 1, marks=pytest.mark.slow),
    pytest.param(1, 2, 2, marks=pytest.mark.slow),
])
def test_configure_sizes_the_device_list_and_the_thread_pool(devices, threads, pool):
    """XLA raises the pool to the device count; the pool threads are named tf_XLAEigen.
    Importing every jaxswarm module first must not start JAX (configure would refuse)."""
    result = subprocess.run([sys.executable, "-c", PROBE.format(devices=devices, threads=threads)],
                            capture_output=True, text=True, timeout=120, check=True)
    seen = json.loads(result.stdout.strip().splitlines()[-1])
    if seen["pool"] == 0:
        pytest.skip("this jaxlib no longer names its pool threads tf_XLAEigen")
    assert seen == {"devices": devices, "pool": pool}
