"""Host-side checks of the limits a multi-agent planner stops at (its time, its nodes), made
before any search with the rules of the ``jaxswarm mapf`` command, so that a bad limit is a
clear error naming the argument, never a search that stops at once or never."""
from __future__ import annotations

import numbers


def check_seconds(name: str, value) -> None:
    """``value`` is a positive number of seconds (``math.inf``: no limit).

    Raises:
      TypeError: not a real number (a bool is none); ValueError: not positive (NaN included).
    """
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise TypeError(f"{name} must be a number of seconds, got {value!r}")
    if not value > 0:
        raise ValueError(f"{name} must be positive, got {value!r}")


def check_count(name: str, value) -> None:
    """``value`` is a whole number, at least 1.

    Raises:
      TypeError: not an integer (a bool is none); ValueError: below 1.
    """
    if not isinstance(value, numbers.Integral) or isinstance(value, bool):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    if value < 1:
        raise ValueError(f"{name} must be at least 1, got {value!r}")
