"""Native CPU kernels called from jitted programs through XLA's typed FFI.

A kernel is C++ (``uniforms.cc`` and ``walk.cc`` beside this module, built into one library)
written against the XLA FFI headers that jaxlib ships (``jax.ffi.include_dir()``), compiled at
first use into a cache folder, loaded with ``ctypes`` and registered with
:func:`jax.ffi.register_ffi_target` for the ``cpu`` platform; a jitted program calls it with
:func:`jax.ffi.ffi_call`, as one ``stablehlo.custom_call`` that XLA runs like any other kernel
(no Python, no host callback), so the program is kept in JAX's persistent compilation cache
like any other. See ``docs/native.md`` for the choices and
measurements.

The compiled library is named by a digest of everything it depends on (the sources, the FFI
headers, the compiler's version and the flags), in ``$JAXSWARM_CACHE/native`` when
``JAXSWARM_CACHE`` is set, else ``$XDG_CACHE_HOME/jaxswarm/native`` (``~/.cache/jaxswarm/native``);
a build writes a temporary file and moves it into place, so processes building at once do not
see each other's half-written files. The compiler is ``$CXX``, else ``c++``, ``g++`` or
``clang++``, whichever is found first.
"""
from __future__ import annotations

import ctypes
import functools
import hashlib
import os
import platform
import shutil
import subprocess
import threading
from pathlib import Path

import jax
import jax.numpy as jnp

from jaxswarm.runtime.atomic import atomic_path
from jaxswarm.runtime.cache import VARIABLE as CACHE_VARIABLE

SOURCES = (Path(__file__).with_name("uniforms.cc"), Path(__file__).with_name("walk.cc"),
           Path(__file__).with_name("backtrack.cc"), Path(__file__).with_name("smooth.cc"))
"""The kernels' C++ sources, compiled together into one library."""
HEADERS = tuple(Path(__file__).with_name(name)
                for name in ("arithmetic.h", "choice.h", "streams.h"))
"""The headers the sources share (beside them; part of the library's digest)."""
UNIFORMS_TARGET = "jaxswarm_uniforms_v1"
"""The FFI target name of :func:`uniforms`. A compiled program names its kernels by target name
only, so a change to a kernel's arguments or results must change its name (the ``_v1``): a
program from the persistent cache would otherwise call a kernel that reads its buffers
otherwise."""
WALK_TARGET = "jaxswarm_walk_v1"
"""The FFI target name of the plain walk (``walk.cc``; called by
:mod:`jaxswarm.swarm.walking.native`), versioned as :data:`UNIFORMS_TARGET` is."""
HOOKED_WALK_TARGET = "jaxswarm_hooked_walk_v1"
"""The FFI target name of the walk with a hook that has a native twin (``walk.cc``)."""
DEPTH_FIRST_TARGET = "jaxswarm_depth_first_v1"
"""The FFI target name of the depth-first walk (``backtrack.cc``; called by
:mod:`jaxswarm.swarm.walking.native_backtrack`), versioned as :data:`UNIFORMS_TARGET` is."""
SMOOTH_TARGET = "jaxswarm_smooth_v1"
"""The FFI target name of IWD_PG's smooth operator (``smooth.cc``; called by
:mod:`jaxswarm.swarm.iwd.native_smooth`), versioned as :data:`UNIFORMS_TARGET` is."""
TARGETS = {UNIFORMS_TARGET: "JaxswarmUniforms", WALK_TARGET: "JaxswarmWalk",
           HOOKED_WALK_TARGET: "JaxswarmHookedWalk", DEPTH_FIRST_TARGET: "JaxswarmDepthFirst",
           SMOOTH_TARGET: "JaxswarmSmooth"}
"""Each FFI target and the handler symbol (``XLA_FFI_DEFINE_HANDLER_SYMBOL``) that runs it."""
FLAGS = ("-O3", "-std=c++17", "-shared", "-fPIC", "-ffp-contract=off", "-w")
"""Compiler flags. No floating-point contraction: XLA:CPU's arithmetic has none (the uniforms
have no multiply-add, but the walker's kernels will). No ``-march=native``: the library runs on
any x86-64 (a cache folder may be shared between machines), at the cost of SSE2 only (the
uniforms' 32-bit products are then emulated; see docs/native.md). ``-w``: the FFI headers warn
under gcc."""
COMPILERS = ("c++", "g++", "clang++")
"""C++ compilers tried in turn when ``$CXX`` is not set."""


class NativeUnavailable(RuntimeError):
    """The native kernels cannot be built or loaded here (no C++ compiler, or it failed)."""


_lock = threading.Lock()


def library_folder() -> Path:
    """The folder compiled libraries go to: ``$JAXSWARM_CACHE/native``, else
    ``$XDG_CACHE_HOME/jaxswarm/native`` (``~/.cache/jaxswarm/native``)."""
    if os.environ.get(CACHE_VARIABLE):
        return Path(os.environ[CACHE_VARIABLE]).expanduser().resolve() / "native"
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base).expanduser().resolve() / "jaxswarm" / "native"


def compiler() -> str:
    """The C++ compiler's path: ``$CXX``, else the first of :data:`COMPILERS` on ``PATH``.

    Raises:
      NativeUnavailable: none is found.
    """
    names = [os.environ["CXX"]] if os.environ.get("CXX") else list(COMPILERS)
    for name in names:
        found = shutil.which(name)
        if found:
            return found
    raise NativeUnavailable(f"no C++ compiler found (tried {', '.join(names)}; set CXX)")


def library_path(folder: str | os.PathLike | None = None) -> Path:
    """Where the library built from :data:`SOURCES` with this compiler, these headers and
    :data:`FLAGS` is (or will be): ``kernels-<digest>.so`` in ``folder`` (default
    :func:`library_folder`)."""
    cxx = compiler()
    digest = hashlib.sha256()
    for source in SOURCES + HEADERS:
        digest.update(source.name.encode() + source.read_bytes())
    for header in sorted((Path(jax.ffi.include_dir()) / "xla" / "ffi" / "api").glob("*.h")):
        digest.update(header.name.encode() + header.read_bytes())
    digest.update(_compiler_version(cxx).encode())
    digest.update(" ".join(FLAGS + (platform.machine(),)).encode())
    root = Path(folder) if folder is not None else library_folder()
    return root / f"kernels-{digest.hexdigest()[:16]}.so"


@functools.cache
def _compiler_version(cxx: str) -> str:
    done = subprocess.run([cxx, "--version"], capture_output=True, text=True, check=False)
    return cxx + "\n" + done.stdout


def build(folder: str | os.PathLike | None = None) -> Path:
    """Compile :data:`SOURCES` into :func:`library_path` unless it is there already.

    Returns:
      The library's path.

    Raises:
      NativeUnavailable: no compiler, or it failed (its messages in the error).
    """
    path = library_path(folder)
    if path.exists():
        return path
    with atomic_path(path) as temporary:
        done = subprocess.run(
            [compiler(), *FLAGS, "-I", jax.ffi.include_dir(), *map(str, SOURCES), "-o",
             str(temporary)],
            capture_output=True, text=True, check=False)
        if done.returncode != 0:
            names = ", ".join(source.name for source in SOURCES)
            raise NativeUnavailable(f"compiling {names} failed:\n{done.stderr[-4000:]}")
    return path


_library: ctypes.CDLL | None = None
_failure: NativeUnavailable | None = None


def register() -> ctypes.CDLL:
    """Build (if needed), load and register the kernels, once per process; thread-safe.

    Registration must come before a program that calls a kernel is compiled or read from the
    persistent cache; :func:`uniforms` calls it when it is traced. A failure is remembered:
    the process does not try again.

    Returns:
      The loaded library (kept loaded for the life of the process: XLA holds pointers into it).

    Raises:
      NativeUnavailable: the library cannot be built or loaded.
    """
    global _library, _failure  # pylint: disable=global-statement
    with _lock:
        if _failure is not None:  # tried once in this process: not again at every trace
            raise _failure
        if _library is None:
            try:
                _library = _load()
            except NativeUnavailable as error:
                _failure = error
                raise
        return _library


def _load() -> ctypes.CDLL:
    """Build (if needed) and load the library, and register its :data:`TARGETS`."""
    path = build()
    try:
        library = ctypes.CDLL(str(path))
    except OSError as error:
        raise NativeUnavailable(f"loading {path} failed: {error}") from error
    for target, symbol in TARGETS.items():
        jax.ffi.register_ffi_target(target, jax.ffi.pycapsule(getattr(library, symbol)),
                                    platform="cpu")
    return library


def available() -> bool:
    """Whether the native kernels can be built and loaded here (builds and registers them)."""
    try:
        register()
    except NativeUnavailable:
        return False
    return True


def uniforms(seed: jax.Array, agent: jax.Array, move: jax.Array) -> jax.Array:
    """:func:`jaxswarm.swarm.walking.streams.uniforms`, bit for bit, as one native kernel call.

    Args:
      seed: u32[..., 2], the walk's key words.
      agent, move: i32[...], broadcast against each other and against ``seed``'s leading axes.

    Returns:
      f32[...] in [0, 1), the broadcast shape.

    Under ``vmap`` the kernel is called once for the whole batch (``vmap_method="broadcast_all"``:
    every input gets the batch axes in front, and the kernel draws each member with its seed row).
    """
    register()
    seed = jnp.asarray(seed, jnp.uint32)
    agent = jnp.asarray(agent, jnp.int32)
    move = jnp.asarray(move, jnp.int32)
    shape = jnp.broadcast_shapes(seed.shape[:-1], agent.shape, move.shape)
    full = shape if shape else (1,)
    seeds = seed.reshape((1,) * (len(full) + 1 - seed.ndim) + seed.shape)
    if seeds.shape[-2] == 1:  # one seed row per batch member: the kernel's own layout
        seeds = jnp.broadcast_to(seeds, full[:-1] + (1, 2)).reshape(full[:-1] + (2,))
        out = _call(seeds, jnp.broadcast_to(agent, full), jnp.broadcast_to(move, full))
    else:  # a seed per element: each element its own batch member of width 1
        seeds = jnp.broadcast_to(seeds, full + (2,))
        out = _call(seeds, jnp.broadcast_to(agent, full)[..., None],
                    jnp.broadcast_to(move, full)[..., None])[..., 0]
    return out.reshape(shape)


def _call(seed: jax.Array, agent: jax.Array, move: jax.Array) -> jax.Array:
    """The kernel on its own layout: seed u32[B..., 2], agent and move i32[B..., A]."""
    return jax.ffi.ffi_call(UNIFORMS_TARGET, jax.ShapeDtypeStruct(agent.shape, jnp.float32),
                            vmap_method="broadcast_all")(seed, agent, move)
