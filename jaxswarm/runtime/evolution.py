"""Evolution strategies' gradient estimate, shared by every search that steps optax on it (the
bees' inverse problem, the tuner's ``es`` method).

An objective that is piecewise constant in its parameters for fixed seeds (a count of arrivals,
a mean of paths whose every step is a discrete choice) has no useful derivative, but its Gaussian
smoothing does: antithetic pairs ``x +- sigma eps`` share their seeds (common random numbers), and
their objectives enter as centred ranks, so the estimate does not depend on the objective's scale.
"""
from __future__ import annotations

import numpy as np


def centred_ranks(values: np.ndarray) -> np.ndarray:
    """f64[n] the ranks of ``values`` (f64[n]) scaled to [-0.5, 0.5], ties sharing the mean of
    their ranks."""
    order = np.argsort(np.argsort(values, kind="stable"), kind="stable").astype(np.float64)
    for value in np.unique(values):
        same = values == value
        order[same] = order[same].mean()
    return order / max(len(values) - 1, 1) - 0.5


def antithetic_gradient(eps: np.ndarray, objectives: np.ndarray, sigma: float) -> np.ndarray:
    """f32[d] the estimated gradient of the smoothed objective at the pairs' centre (the ranks'
    weighted sum of the directions in float64, divided by ``2 p sigma`` in float32).

    Args:
      eps: f32/f64[p, d] the pairs' standard normal directions.
      objectives: f64[2 p] the objective at ``x + sigma eps`` (the first ``p``) and at
        ``x - sigma eps`` (the last ``p``), lower better.
      sigma: the perturbations' standard deviation.
    """
    pairs = len(eps)
    ranked = centred_ranks(np.asarray(objectives, np.float64))
    weighted = (ranked[:pairs] - ranked[pairs:]) @ np.asarray(eps, np.float64)
    return weighted.astype(np.float32) / np.float32(2 * pairs * sigma)
