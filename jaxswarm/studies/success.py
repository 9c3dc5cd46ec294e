"""When a run counts as reaching the optimum: its relative gap to it below
:data:`jaxswarm.sweep.SUCCESS_GAP` (1e-4), the rule the sweeps use too."""
from __future__ import annotations

from jaxswarm.sweep import SUCCESS_GAP

__all__ = ["SUCCESS_GAP", "at_optimum", "reaches_optimum", "relative_gap"]


def relative_gap(cost: float, optimum: float) -> float:
    """``(cost - optimum) / optimum``: 0 at the optimum, inf when no path was found (cost inf)."""
    return (cost - optimum) / optimum


def reaches_optimum(gap: float) -> bool:
    """Whether a run whose best cost has relative ``gap`` to the optimum reaches it."""
    return bool(gap < SUCCESS_GAP)


def at_optimum(cost: float, optimum: float) -> bool:
    """Whether a best ``cost`` reaches the ``optimum`` (:func:`reaches_optimum`)."""
    return reaches_optimum(relative_gap(cost, optimum))
