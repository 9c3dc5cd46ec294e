"""Compiled programs kept on disk, so that a second process does not compile them again.

Most of a short run's time is compiling: a swarm's run is one XLA program per swarm, map shape,
agent count and iteration budget, seconds to a minute each, and the exact planners' numba loops
take seconds more. Two caches keep them between processes:

* JAX's persistent compilation cache (``jax_compilation_cache_dir``), here with no minimum
  compile time or size, so that the many small programs of a sweep or a test suite are kept too.
  A program is found again only by a process with the same jax, jaxlib, XLA flags and device.
* numba's cache of the exact planners' loops (``NUMBA_CACHE_DIR``; without it numba writes next
  to the installed sources). numba reads the variable when ``jaxswarm.exact`` is imported.

:func:`enable` turns both on for one folder; :func:`from_environment`, run when jaxswarm is
imported, does so when ``JAXSWARM_CACHE`` names a folder, which is how scripts, notebook kernels
and subprocesses started with that variable set share it (``make test`` sets it to
``~/.cache/jaxswarm``). Neither changes a result: a cached program is the program XLA built.
"""
from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path

import jax

VARIABLE = "JAXSWARM_CACHE"
"""The environment variable naming the cache folder that :func:`from_environment` enables."""
NUMBA_VARIABLE = "NUMBA_CACHE_DIR"
"""numba's own variable for its cache folder, read when a cached function is defined."""


def enable(folder: str | os.PathLike) -> Path:
    """Keep JAX's compiled programs in ``folder/jax`` and numba's in ``folder/numba``.

    Call it before the programs are compiled; JAX's part applies from the next compile on,
    numba's to the functions numba has not yet set up a cache for (those of ``jaxswarm.exact``
    are set up when it is imported, so set ``JAXSWARM_CACHE`` or ``NUMBA_CACHE_DIR`` before
    that to include them). A ``NUMBA_CACHE_DIR`` already set is left as it is.

    Args:
      folder: the cache folder; created if missing.

    Returns:
      The folder, resolved.

    Raises:
      ValueError: ``folder`` exists and is not a folder.
    """
    root = Path(folder).expanduser().resolve()
    if root.exists() and not root.is_dir():
        raise ValueError(f"{VARIABLE}: {root} is not a folder")
    (root / "jax").mkdir(parents=True, exist_ok=True)
    jax.config.update("jax_compilation_cache_dir", str(root / "jax"))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
    os.environ.setdefault(NUMBA_VARIABLE, str(root / "numba"))
    if "numba" in sys.modules:  # numba read its settings when it was imported: read them again
        sys.modules["numba"].core.config.reload_config()
    return root


def from_environment() -> Path | None:
    """:func:`enable` the folder ``$JAXSWARM_CACHE`` names, if it is set and not empty. Runs when
    jaxswarm is imported, so a folder it cannot use is a warning (naming the variable and the
    reason), not an error: jaxswarm then compiles as without a cache.

    Returns:
      The enabled folder, or None.
    """
    folder = os.environ.get(VARIABLE, "")
    if not folder:
        return None
    try:
        return enable(folder)
    except (OSError, ValueError) as error:
        warnings.warn(f"{VARIABLE}={folder!r} is not used: {error}", RuntimeWarning, stacklevel=2)
        return None
