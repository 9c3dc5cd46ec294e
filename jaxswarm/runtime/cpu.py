"""How JAX uses the CPU: devices and XLA's thread pool, set before JAX's first computation.

XLA:CPU runs a compiled program as a graph of small kernels ("thunks") on a pool of
``XLAEigen`` threads, one per core by default, and starts any kernel whose inputs are ready on
whichever thread is free. A swarm iteration is thousands of tiny kernels in a row (one walk
step of 256 lanes is about 15 of them, each a microsecond or two), so with two threads each step
hands its data back and forth between the cores: in a ``perf`` profile of the maze100 walk each
core spent about a third of its time looking for the next kernel and a quarter more in the
runtime, allocations and thread wake-ups, against 40 % in the kernels themselves. With one
thread the same kernels run back to back: on a 2-core machine an RFD* run on maze100 took about
0.78x the time (``benchmarks/rfd.py --threads``). Large batches (a sweep of many runs under
``vmap``, a walk of thousands of agents) have bigger kernels and can gain from more threads.

The pool size is read once, when JAX creates its CPU client, from the environment variable
``PJRT_NPROC`` (XLA's own setting; the number of JAX CPU devices raises it to at least that many).
:func:`configure` sets both and refuses once JAX has started, when they would no longer apply.
"""
from __future__ import annotations

import os
import platform
from pathlib import Path

import jax

from jaxswarm.runtime.cache import enable as enable_cache

THREADS_VARIABLE = "PJRT_NPROC"
"""The environment variable XLA:CPU reads for the size of its intra-op thread pool."""


def configure(*, devices: int | None = None, threads: int | None = None,
              cache: str | os.PathLike | None = None) -> None:
    """Split the CPU into ``devices`` JAX devices, give XLA ``threads`` intra-op threads and keep
    compiled programs in ``cache``.

    Call it before JAX's first computation (importing jaxswarm's modules does not start JAX):
    JAX reads the device count and the thread pool size when it starts its CPU client. None
    leaves a setting as it is.

    Args:
      devices: JAX CPU devices (``jax.devices()``), at least 1; several devices let
        ``shard_map`` and sharded sweeps run on several cores. None: JAX's default (one, or
        what ``--xla_force_host_platform_device_count`` in ``XLA_FLAGS`` asks for).
      threads: XLA:CPU intra-op threads, at least 1 (raised to the device count by XLA if
        lower). None: XLA's default (one per core, or ``$PJRT_NPROC`` if set).
      cache: a folder for compiled programs, kept between processes
        (:func:`jaxswarm.runtime.cache.enable`; setting ``JAXSWARM_CACHE`` before jaxswarm is
        imported does the same for every process that inherits it). None: no cache, or the
        one ``JAXSWARM_CACHE`` named.

    Raises:
      ValueError: ``devices`` or ``threads`` below 1, or ``cache`` is not a folder.
      RuntimeError: JAX has already started its backends.
    """
    for name, value in (("devices", devices), ("threads", threads)):
        if value is not None and (not isinstance(value, int) or value < 1):
            raise ValueError(f"{name} must be a whole number of at least 1, got {value!r}")
    if backends_started():
        raise RuntimeError("jaxswarm.runtime.cpu.configure must be called before JAX's first "
                           "computation (JAX reads the device count and thread pool size when "
                           "it starts); call it right after `import jax`")
    if devices is not None:
        jax.config.update("jax_num_cpu_devices", devices)
    if threads is not None:
        os.environ[THREADS_VARIABLE] = str(threads)
    if cache is not None:
        enable_cache(cache)


def backends_started() -> bool:
    """Whether JAX has started its backends. JAX's public API has no query for it, but it refuses
    a new CPU device count once they have started: try one, then put the old one back."""
    current = jax.config.jax_num_cpu_devices
    try:
        jax.config.update("jax_num_cpu_devices", current + 1 if current > 0 else 1)
    except RuntimeError:
        return True
    jax.config.update("jax_num_cpu_devices", current)
    return False


def cpu_model(cpuinfo: Path = Path("/proc/cpuinfo")) -> str:
    """The CPU model, for the provenance of measured figures: the first ``model name`` of
    ``cpuinfo`` (Linux), else the platform's processor string, else "unknown"."""
    try:
        for line in cpuinfo.read_text(encoding="utf-8", errors="replace").splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name":
                return value.strip()
    except OSError:
        pass
    return platform.processor() or "unknown"
