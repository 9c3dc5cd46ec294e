"""Deprecated: the RFD paper's dynamic scenarios are :mod:`jaxswarm.studies.rfd_dynamic`.

This old path gives their names with a ``DeprecationWarning`` until jaxswarm 0.12.0 and is
removed then: import them from :mod:`jaxswarm.studies.rfd_dynamic`.
"""
from __future__ import annotations

import warnings

MOVED = ("MAX_BLOCK", "PAPER_DYNAMIC_LENGTH", "PAPER_DYNAMIC_MS", "Scenario", "TABLE2_GOALS",
         "TABLE5_GOALS", "TABLES", "nearest_free", "paper_scenario")
"""The names this path still gives, each from :mod:`jaxswarm.studies.rfd_dynamic`."""


def __getattr__(name: str):
    """The moved ``name`` from its new home, with a DeprecationWarning naming it."""
    if name not in MOVED:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    warnings.warn(f"jaxswarm.dynamic.scenarios.{name} moved to jaxswarm.studies.rfd_dynamic."
                  f"{name}; this path is removed in jaxswarm 0.12.0", DeprecationWarning,
                  stacklevel=2)
    from jaxswarm.studies import rfd_dynamic  # above dynamic/: the layers contract names it

    return getattr(rfd_dynamic, name)
