"""IWD_PG's fuzzy section scores: where on a remembered path local search should work.

The map is split into ``S`` equal sections along x or y (drawn at random each time). For a
path and a section, SPL is the length of its moves inside the section (a move belongs to the
section of its midpoint) and OSPL its length outside. Over the remembered paths that enter the
section, both are scaled to [0, 1] by their minimum and maximum there (0 when they are all
equal). The paper's membership functions (Table 1, Figure 7) and rules (Table 2) did not survive
the text; from its words ("higher score assign to a sub path that behave better"), ours are

* inputs and output: *low* a trapezoid (1 up to 0.25, 0 from 0.5), *medium* a triangle (0.25,
  0.5, 0.75), *high* a trapezoid (0 up to 0.5, 1 from 0.75);
* rules (SPL, OSPL -> score), short inside weighing more than short outside::

      SPL \\ OSPL   low     medium  high
      low          high    high    medium
      medium       medium  medium  low
      high         medium  low     low

* Mamdani inference (a rule fires with the minimum of its two memberships, clips its output
  set; the clipped sets are joined by maximum) and centre-of-gravity defuzzification over
  ``OUTPUT_POINTS`` points of [0, 1].

A path's chance of local search in a section is proportional to ``1 - score`` over the sections
it enters: its worst sections are improved first.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import move_lengths
from jaxswarm.world.paths import step_slots

LOW, MEDIUM, HIGH = 0, 1, 2

RULES = np.array([[HIGH, HIGH, MEDIUM],
                  [MEDIUM, MEDIUM, LOW],
                  [MEDIUM, LOW, LOW]])
"""The output set of each rule, indexed by the SPL set and the OSPL set."""

OUTPUT_POINTS = 101
"""Points of [0, 1] the centre of gravity is taken over."""


def memberships(x: jax.Array) -> jax.Array:
    """f32[..., 3]: the low, medium and high memberships of ``x`` (f32[...], in [0, 1])."""
    low = jnp.clip((0.5 - x) / 0.25, 0.0, 1.0)
    medium = jnp.clip(1.0 - jnp.abs(x - 0.5) / 0.25, 0.0, 1.0)
    high = jnp.clip((x - 0.5) / 0.25, 0.0, 1.0)
    return jnp.stack([low, medium, high], axis=-1)


def fuzzy_score(spl: jax.Array, ospl: jax.Array) -> jax.Array:
    """f32[...]: the defuzzified score of scaled inputs ``spl`` and ``ospl`` (f32[...], in
    [0, 1]); higher is better."""
    firing = jnp.minimum(memberships(spl)[..., :, None], memberships(ospl)[..., None, :])
    # The strength of each output set: the strongest rule that concludes it.
    strength = jnp.stack([jnp.max(jnp.where(RULES == s, firing, 0.0), axis=(-2, -1))
                          for s in (LOW, MEDIUM, HIGH)], axis=-1)
    points = jnp.linspace(0.0, 1.0, OUTPUT_POINTS)
    shape = jnp.max(jnp.minimum(strength[..., None, :], memberships(points)), axis=-1)
    return ordered_sum(shape * points) / jnp.maximum(ordered_sum(shape), 1e-12)


def section_of(graph: Graph, coordinate: jax.Array, axis, sections: int) -> jax.Array:
    """i32[...]: the section (of ``sections`` equal ones along ``axis``, 0 = x, 1 = y) that a
    coordinate (f32[...]) along that axis lies in."""
    along = graph.xy[:, axis]
    low, high = jnp.min(along), jnp.max(along)
    share = (coordinate - low) / jnp.maximum(high - low, 1e-6)
    return jnp.clip(jnp.floor(share * sections), 0, sections - 1).astype(jnp.int32)


def section_lengths(graph: Graph, path: jax.Array, axis, sections: int) -> jax.Array:
    """f32[S]: the length of the moves of ``path`` (i32[L], -1 padded) inside each section."""
    here, there = path[:-1], path[1:]
    cost = move_lengths(graph, here, step_slots(graph, path))  # 0 past the end
    middle = 0.5 * (graph.xy[jnp.maximum(here, 0), axis] + graph.xy[jnp.maximum(there, 0), axis])
    return jax.ops.segment_sum(cost, section_of(graph, middle, axis, sections),
                               num_segments=sections)


def section_scores(lengths: jax.Array, present: jax.Array) -> jax.Array:
    """f32[P, S]: each path's fuzzy score in each section.

    Args:
      lengths: f32[P, S] SPL of each path in each section (:func:`section_lengths`).
      present: bool[P] the paths to compare (remembered ones); the others score 0.
    """
    total = ordered_sum(lengths)[:, None]
    inputs = []
    for value in (lengths, total - lengths):  # SPL, OSPL
        enters = present[:, None] & (lengths > 0)
        low = jnp.min(jnp.where(enters, value, jnp.inf), axis=0)
        high = jnp.max(jnp.where(enters, value, -jnp.inf), axis=0)
        spread = jnp.where(high > low, high - low, 1.0)
        inputs.append(jnp.where(enters, (value - jnp.where(enters, low, 0.0)) / spread, 0.0))
    score = fuzzy_score(*inputs)
    return jnp.where(present[:, None] & (lengths > 0), score, 0.0)
