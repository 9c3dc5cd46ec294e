"""What a process compiles: the hooks the compile ledger (``tests/compile_ledger.py``) installs in
each test process and, through ``sitecustomize.py`` beside this file, in every Python process a
test starts (scripts, the CLI, notebook kernels).

A program is recorded once per process under a fingerprint that is the same in every process:

* an XLA program: ``xla:`` and a digest of its lowered module without debug locations (the same
  program from two call sites is one program). Eager operations (a primitive or a function of
  JAX's own, such as ``jnp.where`` or ``jax.random.split``, applied outside ``jit``, which JAX
  wraps in a small program of its own) are left out: they are cheap and every test has them;
  a loop or a branch applied outside ``jit`` is counted, being a whole program.
* a numba function: ``numba:`` its dispatcher and argument types, counted where Python asks
  numba for it (compiled, or loaded from numba's disk cache), not where numba compiles it
  inside another function's compile, so that a cold and a warm run record the same.

:func:`forget` drops the process's compiled programs (JAX's executables, numba's loaded
overloads) so that the next use of each program records it again. JAX keeps each program's trace
and lowered module, so a program is traced, lowered and fingerprinted once a process, and the
on-disk caches keep the programs, so what is forgotten is loaded again cheaply.
"""
from __future__ import annotations

import hashlib
import os
import sys
import threading
import time
import weakref
from typing import Callable

Record = Callable[[str, str, float], None]
"""``record(fingerprint, name, seconds)``: told of each program as it is built, with the seconds
XLA took to compile it or to load it from the persistent cache (0 for a numba function, and for
an XLA program lowered but not compiled)."""

OUT_VARIABLE = "JAXSWARM_LEDGER_OUT"
"""Names the folder where the processes a test starts write what they built
(``sitecustomize.py``)."""
CONTROL_FLOW = frozenset({"while", "scan", "cond"})
"""Primitives that make an eager operation a program worth counting (a loop's or a branch's)."""
KEEP_TRACES_BELOW = 4 << 30
"""Resident bytes of the process above which :func:`forget` drops JAX's traces and lowered
modules too (all its caches), so that what a long run keeps cannot exhaust the machine."""

_installed: list[Record] = []
_dispatchers: weakref.WeakSet = weakref.WeakSet()
_computations: weakref.WeakSet = weakref.WeakSet()
# id of a lowered module -> its fingerprint and name; every lowering sets or drops its id's entry
_lowered: dict[int, tuple[str, str]] = {}
_depth = threading.local()


def install(record: Record) -> None:
    """Tell ``record`` of every program built from now on (JAX and numba are patched as they are
    imported, or now if they already are). Installs once per process."""
    if _installed:
        _installed[0] = record
        return
    _installed.append(record)
    if "jax._src.interpreters.pxla" in sys.modules:
        _patch_jax()
    else:
        _after_import("jax._src.interpreters.pxla", _patch_jax)
    if "numba.core.dispatcher" in sys.modules:
        _patch_numba()
    else:
        _after_import("numba.core.dispatcher", _patch_numba)


def forget() -> None:
    """Drop the compiled programs this process holds in memory (not those on disk), so that the
    next use of each compiles it again, or loads it from the persistent cache, and records it.
    JAX keeps its traces and lowered modules: a program is traced and lowered once a process."""
    if "jax._src.interpreters.pxla" in sys.modules and _resident_bytes() > KEEP_TRACES_BELOW:
        sys.modules["jax"].clear_caches()
    elif "jax._src.interpreters.pxla" in sys.modules:
        from jax._src import pjit
        from jax._src.interpreters import pxla
        from jax._src.lib import _jax

        # JAX's executables live in its C++ dispatch caches, its compile cache and on each
        # lowering (which compiles once); its traces and lowerings live in other caches.
        pjit._cpp_pjit_cache_fun_only.clear()
        pjit._cpp_pjit_cache_explicit_attributes.clear()
        _jax.PjitFunctionCache.clear_all()
        pxla._cached_compilation.cache_clear()
        for computation in list(_computations):
            computation._executable = None
    for dispatcher in list(_dispatchers):
        dispatcher._reset_overloads()


def _resident_bytes() -> int:
    """The process's resident memory in bytes (Linux; 0 where the system does not say)."""
    try:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _record(fingerprint: str, name: str, seconds: float = 0.0) -> None:
    _installed[0](fingerprint, name, seconds)


def _patch_jax() -> None:
    import jax
    from jax._src.core import jaxprs_in_params
    from jax._src.interpreters import pxla

    lower, compile_ = pxla.lower_sharding_computation, pxla._cached_compilation
    # A program's function is named with its source ("name at file:line"): JAX's own functions
    # (and the primitives it applies one at a time) are the eager operations, but for a loop or
    # a branch applied outside jit, which is a whole program of its own.
    eager_source = f" at {os.path.dirname(jax.__file__)}{os.sep}"

    def loops(jaxpr) -> bool:
        return any(eqn.primitive.name in CONTROL_FLOW
                   or any(map(loops, jaxprs_in_params(eqn.params))) for eqn in jaxpr.eqns)

    def eager(closed_jaxpr) -> bool:
        debug_info = closed_jaxpr.jaxpr.debug_info
        return (debug_info is not None and eager_source in (debug_info.func_src_info or "")
                and not loops(closed_jaxpr.jaxpr))

    def lower_and_record(closed_jaxpr, api_name, fun_name, *args, **kwargs):
        computation = lower(closed_jaxpr, api_name, fun_name, *args, **kwargs)
        _computations.add(computation)
        if eager(closed_jaxpr):
            _lowered.pop(id(computation._hlo), None)
        else:
            text = computation._hlo.operation.get_asm(enable_debug_info=False)
            digest = hashlib.sha256(text.encode()).hexdigest()[:16]
            _lowered[id(computation._hlo)] = (f"xla:{digest}", str(fun_name))
            _record(f"xla:{digest}", str(fun_name))
        return computation

    def compile_and_time(computation, *args, **kwargs):
        began = time.perf_counter()
        executable = compile_(computation, *args, **kwargs)
        if id(computation) in _lowered:
            _record(*_lowered[id(computation)], time.perf_counter() - began)
        return executable

    compile_and_time.cache_clear = compile_.cache_clear
    pxla.lower_sharding_computation = lower_and_record
    pxla._cached_compilation = compile_and_time


def _patch_numba() -> None:
    from numba.core import dispatcher, sigutils

    compile_ = dispatcher.Dispatcher.compile

    def compile_and_record(self, sig):
        outermost = not getattr(_depth, "value", 0)
        args, _ = sigutils.normalize_signature(sig)
        new = tuple(args) not in self.overloads
        _depth.value = getattr(_depth, "value", 0) + 1
        try:
            entry = compile_(self, sig)
        finally:
            _depth.value -= 1
        _dispatchers.add(self)
        if outermost and new:
            function = f"{self.py_func.__module__}.{self.py_func.__qualname__}"
            _record(f"numba:{function}({', '.join(map(str, args))})", function)
        return entry

    dispatcher.Dispatcher.compile = compile_and_record


def _after_import(module: str, then: Callable[[], None]) -> None:
    """Run ``then()`` right after ``module`` is first imported (a finder that wraps its loader)."""
    import importlib.abc
    import importlib.machinery

    class Finder(importlib.abc.MetaPathFinder):
        def find_spec(self, fullname, path, target=None):
            if fullname != module:
                return None
            sys.meta_path.remove(self)
            spec = importlib.machinery.PathFinder.find_spec(fullname, path)
            if spec is None or spec.loader is None:
                return spec
            exec_module = spec.loader.exec_module

            def exec_then_patch(loaded):
                exec_module(loaded)
                then()

            spec.loader.exec_module = exec_then_patch
            return spec

    sys.meta_path.insert(0, Finder())
