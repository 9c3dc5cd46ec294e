"""Deprecated: map entries are resolved by :mod:`jaxswarm.maps.entry` since jaxswarm 0.11.0 (the
old names go in 0.12.0)."""
from __future__ import annotations

import warnings

from jaxswarm.maps import entry
from jaxswarm.sweep import spec

_MOVED = {"SweepMap": ("jaxswarm.maps.entry.ResolvedMap", entry.ResolvedMap),
          "check_map_entry": ("jaxswarm.maps.entry.check", entry.check),
          "resolve_maps": ("jaxswarm.sweep.spec.resolve_maps", spec.resolve_maps),
          "file_digests": ("jaxswarm.sweep.spec.file_digests", spec.file_digests)}
"""Each old name: where it lives now, and what it is."""


def _resolve_map(map_entry, base_dir=None) -> entry.ResolvedMap:
    """The old ``resolve_map(entry, base_dir)``: :func:`jaxswarm.maps.entry.resolve`."""
    return entry.resolve(map_entry, base_dir=base_dir)


_MOVED["resolve_map"] = ("jaxswarm.maps.entry.resolve", _resolve_map)


def __getattr__(name: str):
    if name not in _MOVED:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    home, value = _MOVED[name]
    warnings.warn(f"{__name__}.{name} is deprecated since jaxswarm 0.11.0: use {home}; the old "
                  "name goes in 0.12.0", DeprecationWarning, stacklevel=2)
    return value
