"""Names that moved in 0.5.0, still found at their old place for one release, with a
``DeprecationWarning`` that says where they live now."""
from __future__ import annotations

import importlib
import warnings
from typing import Callable


def forwarder(old: str, new: dict[str, str] | str) -> Callable[[str], object]:
    """A module ``__getattr__`` (PEP 562) for the old module ``old``.

    Args:
      old: the old module's name, as users imported it (``"jaxswarm.graph"``).
      new: the module that now holds every name, or a dict from each moved name to its module.

    Returns:
      ``(name) -> object``: the name from its new module, after a ``DeprecationWarning`` that
      names both places; ``AttributeError`` for a name that never lived in ``old``.
    """

    def __getattr__(name: str):
        home = new if isinstance(new, str) else new.get(name)
        if home is None or name.startswith("__"):
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(home), name)
        warnings.warn(f"{old}.{name} moved to {home}.{name} in jaxswarm 0.5.0; the old path "
                      "goes in 0.6.0", DeprecationWarning, stacklevel=2)
        return value

    return __getattr__


def warn_module(old: str, new: str) -> None:
    """Warn that the module ``old`` moved to ``new`` (called when the old module is imported)."""
    warnings.warn(f"{old} moved to {new} in jaxswarm 0.5.0; the old module goes in 0.6.0",
                  DeprecationWarning, stacklevel=3)
