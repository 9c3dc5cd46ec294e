"""A tuner's search space: the domains of a swarm's params and how settings are drawn from them.

A setting is a dict ``name -> value`` over every param of the space. Domains:

* :class:`Real`: a float in ``[low, high]``, on a log scale when ``log`` (then ``low > 0``);
* :class:`Integer`: an integer in ``[low, high]`` (a float param whose values are counts);
* :class:`Choice`: one of a few values; a ``static`` choice is a value of the swarm's factory
  (a population size, a switch), each of whose values compiles a program of its own;
* :class:`Tied`: the value of another param (IWD's ``beta = alpha``), never drawn.

Draws are keyed (NumPy generators seeded from the tuner's key), so a resumed tune draws the
same settings. The unit cube ``[0, 1]^d`` of the free params (log-scaled where ``log``) is the
space the grid, the evolution strategies and irace's normal draws work in
(:func:`to_unit`, :func:`from_unit`). Draws of an integer take its values as cells of equal width,
``[v, v + 1)`` for each ``v`` of ``[low, high]``, as irace draws them (:func:`cell_unit`,
:func:`from_cell_unit`), so that the ends of its range come up as often as the inner values.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
from typing import Union

import numpy as np


@dataclasses.dataclass(frozen=True)
class Real:
    """A float in ``[low, high]`` (log-uniform when ``log``)."""

    low: float
    high: float
    log: bool = False


@dataclasses.dataclass(frozen=True)
class Integer:
    """An integer in ``[low, high]`` (log-spaced when ``log``)."""

    low: int
    high: int
    log: bool = False


@dataclasses.dataclass(frozen=True)
class Choice:
    """One of ``values``; ``static`` when it is a config value of the swarm's factory."""

    values: tuple
    static: bool = False


@dataclasses.dataclass(frozen=True)
class Tied:
    """The value of param ``to``."""

    to: str


Domain = Union[Real, Integer, Choice, Tied]


@dataclasses.dataclass(frozen=True)
class Space:
    """Named domains, in the order the spec gives them.

    Attributes:
      domains: name -> domain.
    """

    domains: dict

    @property
    def free(self) -> list[str]:
        """The params that are drawn (all but the tied ones)."""
        return [name for name, domain in self.domains.items() if not isinstance(domain, Tied)]

    @property
    def numeric(self) -> list[str]:
        """The free params with a range (Real and Integer)."""
        return [name for name in self.free
                if isinstance(self.domains[name], (Real, Integer))]

    @property
    def static(self) -> list[str]:
        """The params that are config values of the swarm's factory."""
        return [name for name, domain in self.domains.items()
                if isinstance(domain, Choice) and domain.static]

    def complete(self, free: dict) -> dict:
        """The setting of ``free`` values (name -> value of every free param), tied params
        filled in, integers rounded, in the space's order."""
        setting = {}
        for name, domain in self.domains.items():
            if isinstance(domain, Tied):
                setting[name] = free[domain.to]
            elif isinstance(domain, Integer):
                setting[name] = int(round(free[name]))
            else:
                setting[name] = free[name]
        return setting

    def uniform(self, rng: np.random.Generator, count: int) -> list[dict]:
        """``count`` settings drawn uniformly (log-uniformly on log scales; every value of an
        integer range equally often, :func:`from_cell_unit`)."""
        settings = []
        for _ in range(count):
            free = {}
            for name in self.free:
                domain = self.domains[name]
                if isinstance(domain, Choice):
                    free[name] = domain.values[rng.integers(len(domain.values))]
                else:
                    free[name] = from_cell_unit(domain, rng.random())
            settings.append(self.complete(free))
        return settings

    def grid(self, points: int) -> list[dict]:
        """Every combination of ``points`` values evenly spaced over each numeric param (on its
        scale; fewer for an integer range with fewer values) and every value of each choice."""
        return [self.complete(dict(zip(self.free, combination)))
                for combination in itertools.product(*self._axes(points))]

    def grid_size(self, points: int) -> int:
        """``len(self.grid(points))``, counted from the axes without building the grid."""
        return math.prod(len(axis) for axis in self._axes(points))

    def most_points(self, most_settings: int) -> int:
        """The most points per numeric param whose grid has at most ``most_settings`` settings
        (at least 2), by bisection over the grids' sizes (counted, not built), which grow with
        the points; past the values an integer range holds they stay, and so do the points."""
        if not self.numeric:
            return 2
        ranges = [self.domains[name] for name in self.numeric]
        useful = (most_settings if any(isinstance(d, Real) for d in ranges)
                  else max(d.high - d.low + 1 for d in ranges))
        fits, over = 2, max(useful, 2) + 1  # grid_size(fits) <= most_settings < grid_size(over)
        while over - fits > 1:
            middle = (fits + over) // 2
            if self.grid_size(middle) <= most_settings:
                fits = middle
            else:
                over = middle
        return fits

    def _axes(self, points: int) -> list[list]:
        """Each free param's grid values: ``points`` values evenly spaced over a numeric param
        (on its scale; the distinct ones for an integer range), every value of a choice."""
        axes = []
        for name in self.free:
            domain = self.domains[name]
            if isinstance(domain, Choice):
                axes.append(list(domain.values))
            else:
                values = [from_unit(domain, u) for u in np.linspace(0.0, 1.0, points)]
                if isinstance(domain, Integer):
                    values = sorted({int(round(v)) for v in values})
                axes.append(values)
        return axes


def to_unit(domain: Real | Integer, value: float) -> float:
    """``value`` of a numeric domain as a point of ``[0, 1]`` (on its scale)."""
    low, high, value = float(domain.low), float(domain.high), float(value)
    if high == low:
        return 0.0
    if domain.log:
        return (math.log(value) - math.log(low)) / (math.log(high) - math.log(low))
    return (value - low) / (high - low)


def from_unit(domain: Real | Integer, unit: float) -> float:
    """The value of a numeric domain at ``unit`` (in ``[0, 1]``, clipped) on its scale; an
    integer domain's value rounded."""
    unit = min(max(float(unit), 0.0), 1.0)
    low, high = float(domain.low), float(domain.high)
    if domain.log:
        value = math.exp(math.log(low) + unit * (math.log(high) - math.log(low)))
    else:
        value = low + unit * (high - low)
    value = min(max(value, low), high)
    return int(round(value)) if isinstance(domain, Integer) else value


def cell_unit(domain: Real | Integer, value: float) -> float:
    """``value`` of a numeric domain as a point of ``[0, 1]`` on the scale draws use: a real's
    :func:`to_unit`; an integer ``v`` as the middle of its cell ``[v, v + 1)`` of the interval
    ``[low, high + 1)`` (on its log scale when ``log``)."""
    if isinstance(domain, Real):
        return to_unit(domain, value)
    return to_unit(_cells(domain), float(value) + 0.5)


def from_cell_unit(domain: Real | Integer, unit: float) -> float:
    """The value of a numeric domain at ``unit`` (in ``[0, 1]``, clipped) on the scale draws use:
    a real's :func:`from_unit`; for an integer the cell of ``[low, high + 1)`` it falls in (the
    last cell at 1), so a uniform ``unit`` draws every integer equally often."""
    if isinstance(domain, Real):
        return from_unit(domain, unit)
    return int(min(math.floor(from_unit(_cells(domain), unit)), domain.high))


def _cells(domain: Integer) -> Real:
    """The reals ``[low, high + 1)`` an integer's cells cover, on its scale."""
    return Real(float(domain.low), float(domain.high + 1), domain.log)
