"""Host-side checks of a multi-agent planner's options (its time, its nodes, its weights and
switches), made by its config before any search, so that a bad option is a clear error naming
it, never a search that stops at once or never."""
from __future__ import annotations

import numbers

import numpy as np


class OptionError(ValueError):
    """An option's value out of its range, as ``"{option} {problem}"``.

    Attributes:
      option: the option's name (``"time_limit"``).
      problem: what is wrong with its value (``"must be positive, got 0"``), for a caller that
        names the option its own way (the ``jaxswarm mapf`` command: ``--time-limit``).
    """

    def __init__(self, option: str, problem: str):
        super().__init__(f"{option} {problem}")
        self.option, self.problem = option, problem


def check_seconds(name: str, value) -> None:
    """``value`` is a positive number of seconds (``math.inf``: no limit).

    Raises:
      TypeError: not a real number (a bool is none); OptionError: not positive (NaN included).
    """
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise TypeError(f"{name} must be a number of seconds, got {value!r}")
    if not value > 0:
        raise OptionError(name, f"must be positive, got {value!r}")


def check_count(name: str, value, least: int = 1) -> None:
    """``value`` is a whole number, at least ``least``.

    Raises:
      TypeError: not an integer (a bool is none); OptionError: below ``least``.
    """
    if not isinstance(value, numbers.Integral) or isinstance(value, bool):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    if value < least:
        raise OptionError(name, f"must be at least {least}, got {value!r}")


def check_number(name: str, value, least: float, most: float | None = None) -> None:
    """``value`` is a real number from ``least`` to ``most`` (None: no upper end).

    Raises:
      TypeError: not a real number (a bool is none); OptionError: out of the range (NaN
        included).
    """
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise TypeError(f"{name} must be a number, got {value!r}")
    if most is None and not value >= least:
        raise OptionError(name, f"must be at least {least:g}, got {value}")
    if most is not None and not least <= value <= most:
        raise OptionError(name, f"must be between {least:g} and {most:g}, got {value}")


def check_switch(name: str, value) -> None:
    """``value`` is True or False (a NumPy bool too).

    Raises:
      TypeError: anything else (1 and "yes" included).
    """
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {value!r}")
