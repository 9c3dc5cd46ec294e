"""The vector instructions XLA compiles for while the golden records are written and replayed.

XLA:CPU compiles for the host's widest vector instructions, and a float reduction over 8 lanes
(AVX2) adds in another order than one over 16 (AVX-512): the same run ends a few ulps apart on two
x86-64 machines (measured: 9 of IWD's 3,200 soil values on alley20, at most 2.7e-6). The records
are written and replayed with XLA capped at AVX2, which every x86-64 machine that runs JAX has, so
that they hold bit for bit on any of them. Other architectures keep XLA's default.
"""
import os
import platform

FLAG = "--xla_cpu_max_isa=AVX2"
"""The ``XLA_FLAGS`` entry that caps XLA:CPU's vector instructions at AVX2."""


def cap_isa(environ=os.environ) -> None:
    """Add :data:`FLAG` to ``environ["XLA_FLAGS"]`` on x86-64 (before JAX starts its backend)."""
    if platform.machine().lower() not in ("x86_64", "amd64"):
        return
    flags = environ.get("XLA_FLAGS", "")
    if "--xla_cpu_max_isa" not in flags:
        environ["XLA_FLAGS"] = f"{flags} {FLAG}".strip()
