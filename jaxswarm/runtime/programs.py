"""Compiled programs held by a process, and when to let them go.

XLA:CPU loads the kernels of every compiled program into code pages of their own, and each
page range is a memory mapping of the process. Measured with jax 0.10.2 on Linux (maze20, 8 and
16 agents, 4 iterations): one ``aco_star`` run program adds about 550 mappings, ``iwd`` 700,
``rfd_star`` 550, ``iwd_pg`` 2,800. Linux lets a process hold at most ``vm.max_map_count``
mappings (65,530 by default); a process that keeps on compiling (a test suite, a sweep over maps
of many shapes, a table script over algorithms and maps) reaches it after a few dozen programs,
and then the next page XLA maps, loading a program or serialising one for the persistent
compilation cache, fails and the process aborts or crashes without a Python error.

:func:`release_if_crowded`, called before a compile, lets every compiled program go
(``jax.clear_caches``) once the process holds more than a share of its limit; a program needed
again is compiled again, or read back from the persistent cache
(:mod:`~jaxswarm.runtime.cache`). Results do not change: a program compiled again is the same
program.
"""
from __future__ import annotations

import gc
from pathlib import Path

import jax

MAPS = Path("/proc/self/maps")
"""The process's memory mappings, one a line (Linux)."""
LIMIT = Path("/proc/sys/vm/max_map_count")
"""The most mappings a Linux process may hold."""
CROWDED = 0.5
"""The share of the limit above which :func:`release_if_crowded` lets the programs go: a
program that compiles next (IWD_PG's take 2,800 mappings each; a sweep chunk of several
devices more) still finds room."""


def mapped_regions() -> int | None:
    """The number of memory mappings this process holds, or None where the system does not
    say (not Linux)."""
    try:
        with MAPS.open("rb") as lines:
            return sum(1 for _ in lines)
    except OSError:
        return None


def region_limit() -> int | None:
    """The most memory mappings a process may hold (``vm.max_map_count``), or None where the
    system does not say."""
    try:
        return int(LIMIT.read_text())
    except (OSError, ValueError):
        return None


def release_if_crowded(share: float = CROWDED) -> bool:
    """Let every compiled program of the process go (``jax.clear_caches()``, then a garbage
    collection) if it holds more than ``share`` of the mappings it may hold.

    Args:
      share: the share of :func:`region_limit` above which the programs go, in [0, 1].

    Returns:
      Whether they went; False where the system does not say how many mappings there are.

    Raises:
      ValueError: ``share`` is outside [0, 1].
    """
    if not 0.0 <= share <= 1.0:
        raise ValueError(f"share must be in [0, 1], got {share}")
    regions, limit = mapped_regions(), region_limit()
    if regions is None or limit is None or regions <= share * limit:
        return False
    jax.clear_caches()
    gc.collect()
    return True
