"""Float arithmetic whose result does not depend on how XLA fuses and batches a program.

A key fixes a run only if every float that reaches a discrete choice (a draw, a comparison, a
best path) is the same bit for bit alone, in a ``vmap`` of any width, on any thread or device
count. On XLA:CPU three things break that, and this module offers their remedies:

* contraction of a multiply and an add into one rounding: :data:`ISA_FLAG` caps XLA at AVX,
  which has no FMA (:func:`fixed_arithmetic_flags`, :func:`require_fixed_arithmetic`); divide
  by an operand a batch shares as ``x * (1 / y)``, as XLA rewrites such a division;
* XLA's ``exp``, ``log`` and ``pow``, whose last bits depend on the width: :func:`exp`,
  :func:`log` and :func:`integer_power`, by IEEE operations only;
* reductions in an order XLA picks per program: :func:`ordered_sum` and :func:`ordered_cumsum`,
  in an order fixed by the axis length alone.

The guarantee is "same key, same version, same platform" (x86-64 with AVX, or the same CPU family
elsewhere). ``docs/sweeps.md`` ("How one key gives one result") has what was measured and where
in jaxswarm each float that reaches a choice comes from.
"""
from __future__ import annotations

import os
import platform
import warnings

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.cpu import backends_started

ISA_FLAG = "--xla_cpu_max_isa=AVX"
"""The ``XLA_FLAGS`` entry that caps XLA:CPU's vector instructions at AVX (no FMA), on x86-64."""

FLAGS_VARIABLE = "XLA_FLAGS"
"""The environment variable XLA reads its flags from when JAX starts its CPU client."""


def fixed_arithmetic_flags(environ=os.environ, machine: str | None = None) -> bool:
    """Add :data:`ISA_FLAG` to ``environ["XLA_FLAGS"]`` on x86-64 unless the flags already cap
    the instruction set (the user's choice stands). It applies to the XLA:CPU client JAX starts
    afterwards; importing jaxswarm calls it (:func:`require_fixed_arithmetic`).

    Args:
      environ: the environment to change (``os.environ``).
      machine: the processor architecture (``platform.machine()`` when None).

    Returns:
      Whether it added the flag.
    """
    machine = platform.machine() if machine is None else machine
    flags = environ.get(FLAGS_VARIABLE, "")
    if machine.lower() not in ("x86_64", "amd64") or "--xla_cpu_max_isa" in flags:
        return False
    environ[FLAGS_VARIABLE] = f"{flags} {ISA_FLAG}".strip()
    return True


def require_fixed_arithmetic() -> None:
    """:func:`fixed_arithmetic_flags`, with a warning when JAX has already started its CPU
    client, which then compiles with FMA: one key still gives one result within one program,
    but not across batch widths. Called when jaxswarm is imported."""
    if fixed_arithmetic_flags() and backends_started():
        warnings.warn(f"jaxswarm was imported after JAX started its CPU backend, so XLA compiles "
                      f"with fused multiply-adds and a run may differ in its last bits between "
                      f"batches; import jaxswarm before JAX's first computation, or set "
                      f"XLA_FLAGS={ISA_FLAG}", RuntimeWarning, stacklevel=3)


# Cephes' expf: exp(x) = 2^n exp(r), n = round(x / ln 2), r = x - n ln 2 in two parts (the first
# has few bits, so n * its value is exact), exp(r) by a polynomial of degree 7 (about 1 ulp).
_LOG2E = np.float32(1.44269504088896341)
_LN2_HIGH = np.float32(0.693359375)
_LN2_LOW = np.float32(-2.12194440e-4)
_EXP_POLY = tuple(np.float32(c) for c in (1.9875691500e-4, 1.3981999507e-3, 8.3334519073e-3,
                                          4.1665795894e-2, 1.6666665459e-1, 5.0000001201e-1))
_EXP_MAX, _EXP_MIN = np.float32(88.72283935546875), np.float32(-103.972084045410)


def exp(x: jax.Array) -> jax.Array:
    """``exp`` of f32[...] by IEEE operations only, at most 1 ulp from the true value where
    that is a normal float (XLA's own: up to 5): the same bits in every program and on every
    width (XLA's ``exp`` is not; see the module docstring). Below the smallest normal float the
    result is 0, as XLA:CPU flushes subnormals; ``-inf`` gives 0, anything above 88.72 ``inf``,
    NaN NaN."""
    x = jnp.asarray(x, jnp.float32)
    clipped = jnp.clip(x, _EXP_MIN, _EXP_MAX)
    n = jnp.floor(clipped * _LOG2E + np.float32(0.5))
    r = (clipped - n * _LN2_HIGH) - n * _LN2_LOW
    p = _EXP_POLY[0]
    for c in _EXP_POLY[1:]:
        p = p * r + c
    y = p * (r * r) + r + np.float32(1.0)
    # 2^n as two normal powers of two (n is in [-150, 128]): the product and the quotient are
    # exact but the last, which rounds once. Dividing by 2^-rest gives the bits multiplying by
    # 2^rest would, and XLA counts a division as expensive: it computes the result once for
    # all its consumers instead of copying this chain of cheap operations into each consumer's
    # fusion (three copies in a walk step). Not ``/ 2^-half / 2^-rest``: XLA rewrites that as
    # one division by a product that is subnormal near overflow.
    half = jnp.floor(n * np.float32(0.5)).astype(jnp.int32)
    rest = n.astype(jnp.int32) - half
    value = y * _power_of_two(half) / _power_of_two(-rest)
    value = jnp.where(x > _EXP_MAX, jnp.inf, value)
    return jnp.where(jnp.isnan(x), x, value)


def _power_of_two(n: jax.Array) -> jax.Array:
    """f32[...] ``2^n`` for i32[...] ``n`` in [-126, 127], from its exponent bits."""
    return jax.lax.bitcast_convert_type((n + 127) << 23, jnp.float32)


# Cephes' logf: x = m 2^e with m in [sqrt(1/2), sqrt(2)), log(x) = log(m) + e ln 2, log(m) =
# log(1 + f) by a polynomial of degree 9 in f = m - 1, e ln 2 in the two parts exp uses.
_SQRT_HALF = np.float32(0.707106781186547524)
_LOG_POLY = tuple(np.float32(c) for c in (7.0376836292e-2, -1.1514610310e-1, 1.1676998740e-1,
                                          -1.2420140846e-1, 1.4249322787e-1, -1.6668057665e-1,
                                          2.0000714765e-1, -2.4999993993e-1, 3.3333331174e-1))
_SMALLEST_NORMAL = np.float32(np.finfo(np.float32).tiny)


def log(x: jax.Array) -> jax.Array:
    """The natural ``log`` of f32[...] by IEEE operations only, at most 1 ulp from the true
    value (XLA's own differs in its last bits between programs, as its ``exp`` does): the same
    bits in every program and on every width, and in the native kernels, which copy it.
    Below the smallest normal float (0 and the subnormals, which XLA:CPU flushes) the result is
    ``-inf``; negative numbers give NaN, ``inf`` gives ``inf``, NaN NaN."""
    x = jnp.asarray(x, jnp.float32)
    word = jax.lax.bitcast_convert_type(x, jnp.uint32)
    exponent = (word >> 23).astype(jnp.int32) - 126  # x = m 2^exponent, m in [1/2, 1)
    m = jax.lax.bitcast_convert_type((word & np.uint32(0x007FFFFF)) | np.uint32(0x3F000000),
                                     jnp.float32)
    below = m < _SQRT_HALF
    e = jnp.where(below, exponent - 1, exponent).astype(jnp.float32)
    f = jnp.where(below, (m + m) - np.float32(1.0), m - np.float32(1.0))
    z = f * f
    p = _LOG_POLY[0]
    for c in _LOG_POLY[1:]:
        p = p * f + c
    y = p * f * z
    y = y + _LN2_LOW * e
    y = y - np.float32(0.5) * z
    value = (f + y) + _LN2_HIGH * e
    value = jnp.where(x < _SMALLEST_NORMAL, -jnp.inf, value)
    value = jnp.where(x < 0, jnp.nan, value)
    value = jnp.where(x == jnp.inf, jnp.inf, value)
    return jnp.where(jnp.isnan(x), x, value)


def integer_power(x: jax.Array, n: jax.Array, max_exponent: int) -> jax.Array:
    """``x ** n`` for f32[...] ``x`` and i32[...] ``n`` in ``[0, max_exponent]`` (a static
    bound), by squaring: the product of ``x^(2^b)`` over the set bits ``b`` of ``n``, lowest
    first (``x ** n`` with an array exponent is XLA's ``pow``, whose last bits vary as its
    ``exp`` and ``log`` do). The native kernels copy it."""
    x = jnp.asarray(x, jnp.float32)
    n = jnp.asarray(n, jnp.int32)
    result = jnp.ones(jnp.broadcast_shapes(x.shape, n.shape), jnp.float32)
    square = x
    for bit in range(max(max_exponent, 1).bit_length()):
        result = jnp.where((n >> bit) & 1 == 1, result * square, result)
        square = square * square
    return result


def ordered_sum(x: jax.Array, axis: int = -1) -> jax.Array:
    """The sum of f32[...] ``x`` over ``axis`` in a fixed order: padded with zeros to a power of
    two, then halved (the first half plus the second) until one term is left. The order depends
    on the axis length only, so the sum is the same bits alone and in any batch."""
    x = jnp.moveaxis(jnp.asarray(x), axis, -1)
    length = x.shape[-1]
    if length == 0:
        return jnp.zeros(x.shape[:-1], x.dtype)
    width = 1 << (length - 1).bit_length()
    x = jnp.pad(x, [(0, 0)] * (x.ndim - 1) + [(0, width - length)])
    while x.shape[-1] > 1:
        half = x.shape[-1] // 2
        x = x[..., :half] + x[..., half:]
    return x[..., 0]


def ordered_cumsum(x: jax.Array, axis: int = -1, *, reverse: bool = False) -> jax.Array:
    """The running sums of ``x`` along ``axis`` (``reverse``: from the end) by
    :func:`jax.lax.associative_scan`, whose adds are elementwise operations arranged by the axis
    length alone: the same bits alone and in any batch (``jnp.cumsum`` is a reduce-window whose
    order XLA chooses)."""
    return jax.lax.associative_scan(jnp.add, jnp.asarray(x), reverse=reverse, axis=axis)
