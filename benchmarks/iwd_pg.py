"""Speed of ``iwd_pg`` (IWD_PG with its default config): compile seconds, milliseconds per
iteration, and the share of each stage; and a check that its results are the recorded ones.

For each key of ``--keys`` one run of ``--iterations`` iterations (default 100, no patience:
a run stops early only when every drop of an iteration took one path) on ``--map`` (default
mosaic50, the map of ``jaxswarm demo``, with its start and goal), by each of the walker's
implementations of ``--implementations`` (default ``lanes,native``: the XLA lanes, the
reference, and the native kernels, :mod:`jaxswarm.swarm.walking.native`), named in the swarm's
config (``walker=WalkerOptions(implementation=...)``), one after the other in the same process,
one row each (``walker``). The run is compiled once per implementation (without the compile
cache: its seconds are printed), then each key is timed ``--repeats`` times and the median per
key is printed, divided by the iterations it ran.

``--stages`` also times variants with one stage switched off (:class:`IWDPGConfig`), each
compiled on its own: ``no smooth``, ``no operators`` (the memory operators compiled but never
due: ``operator_patience`` above the iterations), ``no intersections``, ``no local search``;
a stage's share is how much of the default run's time per iteration (of the same
implementation) the variant saves. The variants' runs take other paths (a stage off changes
what the drops find), so the shares are estimates; the variant ``walk only`` (smooth and
operators off) is the drops' walk with the bookkeeping of the iteration.

Same results: the SHA-256 of every leaf of each run's state and trace (PRNG keys as their data;
not the trace's ``lane_steps``, the walker's schedule) are compared with :data:`RECORDED`, the
digests of jaxswarm 0.7.0's runs (the same runs as before IWD_PG was sped up, in 0.7.0's
arithmetic, :mod:`jaxswarm.runtime.arithmetic`; ``same results: yes`` when every leaf matches;
printed for the default map, iterations and config, per implementation; ``--record`` prints
the digests of this run as the record's source text, per implementation). ``same as lanes``:
whether every other implementation's runs have the lanes' digests, every key (any map).

XLA:CPU runs each run on ``--threads`` intra-op threads (default 1; see
:mod:`jaxswarm.runtime.cpu`).

Run from the repository root::

    python benchmarks/iwd_pg.py
    python benchmarks/iwd_pg.py --stages --repeats 3
    python benchmarks/iwd_pg.py --map maze50 --keys 0
    python benchmarks/iwd_pg.py --implementations native   # the native walker alone
"""
from __future__ import annotations

import argparse
import hashlib
import os
import platform
import statistics
import time

import jax
import numpy as np

from jaxswarm.maps.named import named_map
from jaxswarm.runtime.cpu import configure
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.testing import key_data
from jaxswarm.swarm.walking.native import check_implementations
from jaxswarm.swarm.walking.options import IMPLEMENTATIONS, WalkerOptions

DEFAULT_MAP, DEFAULT_ITERATIONS = "mosaic50", 100

RECORDED = {
    "mosaic50": {
        0: {
            "[0].key": "2c1f94e5b9ee9b5a", "[0].soil": "4ba817617095f6ea",
            "[0].memory.paths": "458a1dca8eda1c65", "[0].memory.costs": "7e3d4200ed1d489a",
            "[0].stale": "67abdd721024f0ff", "[1].best_cost": "ce88b07c3f1acd28",
            "[1].iteration_cost": "aa908661e8a35611", "[1].arrived": "4debf29cf4a84b43",
            "[1].iterations": "972b8373b897c65c", "[1].moves": "b92dbbc426935283",
            "[1].evaluations": "01d8a5fd17c1c23e",
        },
        1: {
            "[0].key": "4ac7a7d758b49208", "[0].soil": "403462fd0b78550e",
            "[0].memory.paths": "a0d11cde30b78448", "[0].memory.costs": "9079d5d8486da594",
            "[0].stale": "6fea016a651b6460", "[1].best_cost": "01e312a0b472c10a",
            "[1].iteration_cost": "237b93b815f432ba", "[1].arrived": "27344980c0e2539c",
            "[1].iterations": "40e736c02a102a05", "[1].moves": "6706359b7c0ba562",
            "[1].evaluations": "dedd1c9fffb9f2f1",
        },
        2: {
            "[0].key": "fc34219733dd7ee7", "[0].soil": "4705109515e32d71",
            "[0].memory.paths": "8a2f096761ea40a6", "[0].memory.costs": "234328b8a31aba7e",
            "[0].stale": "6cb5a8ec7215303a", "[1].best_cost": "5057b7c4e04e0c99",
            "[1].iteration_cost": "ba7fe94fa56a4823", "[1].arrived": "ce14ae54da14e99c",
            "[1].iterations": "40e736c02a102a05", "[1].moves": "1e4d5adfb23d6716",
            "[1].evaluations": "94b8c717852a08a1",
        },
    },
    "mosaic20": {
        0: {
            "[0].key": "8ffd190d67796d1d", "[0].soil": "929487c2e2a6c580",
            "[0].memory.paths": "9f2cbf86d4262183", "[0].memory.costs": "d95e9a95d9498a7c",
            "[0].stale": "91ce314c0a497422", "[1].best_cost": "942d5dfff171f2ca",
            "[1].iteration_cost": "3454cb8d1144f62a", "[1].arrived": "77d216a69772d7a1",
            "[1].iterations": "40e736c02a102a05", "[1].moves": "f4c87a3dd175dc01",
            "[1].evaluations": "e4ba20658830cd73",
        },
        1: {
            "[0].key": "c612fd0369ff1964", "[0].soil": "5e675b430d0f01ba",
            "[0].memory.paths": "74879d9ef76c9f74", "[0].memory.costs": "779f0a83fb2c2433",
            "[0].stale": "a376d173ece243d5", "[1].best_cost": "5dd5ee3055823fe7",
            "[1].iteration_cost": "1de1324fe01000e7", "[1].arrived": "ded4f45924fb0267",
            "[1].iterations": "0623ccb9b1619bd3", "[1].moves": "6464498b60a7aa45",
            "[1].evaluations": "bc6f5d65baa5e027",
        },
        2: {
            "[0].key": "fc34219733dd7ee7", "[0].soil": "f0a491624ef4a133",
            "[0].memory.paths": "ca56cbfde6887f8d", "[0].memory.costs": "bc7dd1e1b68b9511",
            "[0].stale": "c0736411a62ec0f4", "[1].best_cost": "02052479abb1a729",
            "[1].iteration_cost": "4a4771c75b17503b", "[1].arrived": "88fb9eb024a10e75",
            "[1].iterations": "40e736c02a102a05", "[1].moves": "a12c8dbaae46a27f",
            "[1].evaluations": "9d61ea05c722ff6c",
        },
    },
    "maze20": {
        0: {
            "[0].key": "1049b4c0445a9d42", "[0].soil": "c4a8ca2bb2e9ae52",
            "[0].memory.paths": "ae7b09b13a79e553", "[0].memory.costs": "f941ecf371914389",
            "[0].stale": "67abdd721024f0ff", "[1].best_cost": "6599e3077e4c71c1",
            "[1].iteration_cost": "c951e83b7fd01857", "[1].arrived": "71d1ee93fb6ba870",
            "[1].iterations": "9d9f290527a6be62", "[1].moves": "2f743625054d30c4",
            "[1].evaluations": "99c28d92a8b1e901",
        },
        1: {
            "[0].key": "891e380f28824aeb", "[0].soil": "2dccc92f5a84afef",
            "[0].memory.paths": "ae7b09b13a79e553", "[0].memory.costs": "f941ecf371914389",
            "[0].stale": "67abdd721024f0ff", "[1].best_cost": "0eafcd13528da8af",
            "[1].iteration_cost": "0eafcd13528da8af", "[1].arrived": "26537abd03a9ae64",
            "[1].iterations": "26b25d457597a7b0", "[1].moves": "94103ee33d1e1c2f",
            "[1].evaluations": "083f49d9f68ded5d",
        },
        2: {
            "[0].key": "9827dae0d0651570", "[0].soil": "b655529514fecd3f",
            "[0].memory.paths": "ae7b09b13a79e553", "[0].memory.costs": "f941ecf371914389",
            "[0].stale": "67abdd721024f0ff", "[1].best_cost": "8b9bcd3b847ce1eb",
            "[1].iteration_cost": "f164f01eb94852fc", "[1].arrived": "6655e76886672b22",
            "[1].iterations": "9d9f290527a6be62", "[1].moves": "917e4ded805b4496",
            "[1].evaluations": "5a4548452968743e",
        },
    },
}
"""Per map and key: the digest (first 16 hex digits of SHA-256) of each leaf of the run's
``(state, trace)``, 100 iterations, default config, jaxswarm 0.7.0. The records of mosaic20 and
maze20, where the drops arrive early and the memory operators run from the first iterations,
check the smoothing and the operators on small maps too."""

VARIANTS = {
    "no smooth": dict(smooth=False),
    "no operators": dict(operator_patience=10**9),
    "no intersections": dict(first_intersection=False, second_intersection=False),
    "no local search": dict(local_search=False),
    "walk only": dict(smooth=False, operator_patience=10**9),
}
"""The config of each variant ``--stages`` times beside the default."""


def digests(result) -> dict[str, str]:
    """The digest of each leaf of a run's ``(state, trace)`` but the trace's ``lane_steps`` (the
    walker's schedule, not the run's result), by its place in the tree."""
    return {jax.tree_util.keystr(where): hashlib.sha256(
        np.ascontiguousarray(np.asarray(leaf)).tobytes()).hexdigest()[:16]
        for where, leaf in jax.tree_util.tree_leaves_with_path(key_data(result))
        if jax.tree_util.keystr(where) != "[1].lane_steps"}


def record_source(records: dict) -> str:
    """``records`` (map -> key -> leaf -> digest) as the source text of :data:`RECORDED`."""
    lines = ["RECORDED = {"]
    for name, keys in records.items():
        lines.append(f'    "{name}": {{')
        for key, leaves in keys.items():
            lines.append(f"        {key}: {{")
            items = [f'"{leaf}": "{digest}",' for leaf, digest in leaves.items()]
            lines += ["            " + " ".join(items[i:i + 2]) for i in range(0, len(items), 2)]
            lines.append("        },")
        lines.append("    },")
    return "\n".join(lines + ["}"])


def measure(swarm, graph, task, keys, iterations: int, repeats: int):
    """``(compile seconds, {key: (ms per iteration, iterations, best cost, digests)})``."""
    params = swarm.default_params

    def once(key):
        return jax.block_until_ready(run(swarm, jax.random.key(key), graph, task, params,
                                         iterations=iterations, patience=None))

    began = time.perf_counter()
    once(keys[0])
    compile_seconds = time.perf_counter() - began
    out = {}
    for key in keys:
        seconds = []
        for _ in range(repeats):
            began = time.perf_counter()
            state, trace = once(key)
            seconds.append(time.perf_counter() - began)
        ran = int(trace.iterations)
        out[key] = (1e3 * statistics.median(seconds) / ran, ran, float(state.best_cost),
                    digests((state, trace)))
    # The first call also ran once: its compile is the rest.
    return compile_seconds - out[keys[0]][0] * out[keys[0]][1] / 1e3, out


def chosen_implementations(text: str, parser: argparse.ArgumentParser) -> list[str]:
    """The walker's implementations ``--implementations`` names, checked
    (:func:`~jaxswarm.swarm.walking.native.check_implementations`: the native kernels built or
    loaded, so that no compile time below includes that)."""
    try:
        return check_implementations(text.split(","))
    except ValueError as error:
        parser.error(f"--implementations: {error}")


def check_results(args, keys: list[int], defaults: dict) -> None:
    """Print whether each implementation's default runs (``defaults``: implementation -> key
    -> (ms, iterations, cost, digests)) have the recorded digests, and the lanes' (and, with
    ``--record``, the record's source text)."""
    for implementation, out in defaults.items():
        if args.record:
            print(f"# {implementation}\n" + record_source(
                {args.map: {key: leaves for key, (*_, leaves) in out.items()}}))
        record = RECORDED.get(args.map, {}) if args.iterations == DEFAULT_ITERATIONS else {}
        recorded = [key for key in keys if key in record]
        if recorded:
            changed = {key: sorted(leaf for leaf, digest in record[key].items()
                                   if out[key][3].get(leaf) != digest) for key in recorded}
            same = not any(changed.values())
            print(f"{implementation}: same results as recorded (keys {recorded}): "
                  f"{'yes' if same else 'NO'}" + ("" if same else f" changed leaves: {changed}"))
        if implementation != "lanes" and "lanes" in defaults:
            same = all(out[key][3] == defaults["lanes"][key][3] for key in keys)
            print(f"{implementation}: same as lanes (keys {keys}): {'yes' if same else 'NO'}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default=DEFAULT_MAP, help="a map jaxswarm demo takes")
    parser.add_argument("--iterations", type=int, default=DEFAULT_ITERATIONS)
    parser.add_argument("--keys", default="0,1,2", help="comma-separated PRNG seeds")
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per key (median)")
    parser.add_argument("--threads", type=int, default=1,
                        help="XLA:CPU intra-op threads (jaxswarm.runtime.cpu.configure)")
    parser.add_argument("--stages", action="store_true",
                        help="also time the variants with a stage switched off")
    parser.add_argument("--record", action="store_true",
                        help="print this run's digests as RECORDED's source text")
    parser.add_argument("--implementations", default=",".join(IMPLEMENTATIONS),
                        help=f"comma-separated walker implementations, from "
                             f"{', '.join(IMPLEMENTATIONS)}")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error(f"--repeats must be at least 1, got {args.repeats}")
    # Before JAX's first computation; compile seconds are measured, so no cached programs.
    jax.config.update("jax_enable_compilation_cache", False)
    try:
        configure(threads=args.threads)
        keys = [int(key) for key in args.keys.split(",")]
        chosen = named_map(args.map)
    except ValueError as error:
        parser.error(str(error))
    implementations = chosen_implementations(args.implementations, parser)
    graph = chosen.graph
    task = make_task(graph, chosen.start, chosen.goal)
    print(f"machine: {platform.platform()} | {os.cpu_count()} CPUs | jax {jax.__version__} "
          f"({jax.default_backend()}, {args.threads} XLA thread(s)) | load "
          f"{os.getloadavg()[0]:.1f}")
    print(f"iwd_pg on {args.map} ({graph.shape[1]}x{graph.shape[0]}), {args.iterations} "
          f"iterations, no patience, keys {keys}, median of {args.repeats}")
    print(f"{'variant':18} {'walker':6} {'compile s':>9} {'ms/iter':>8} {'share':>6}  per key: "
          f"ms/iter (iterations, best cost)")
    rows = [("default", {})] + (list(VARIANTS.items()) if args.stages else [])
    defaults = {}
    for label, options in rows:
        for implementation in implementations:
            walker = WalkerOptions(implementation=implementation)
            compile_seconds, out = measure(make("iwd_pg", walker=walker, **options), graph, task,
                                           keys, args.iterations, args.repeats)
            defaults.setdefault(implementation, out)
            print_row(label, implementation, compile_seconds, out, defaults[implementation])
    check_results(args, keys, defaults)
    return 0


def print_row(label: str, implementation: str, compile_seconds: float, out: dict,
              default: dict) -> None:
    """One row of the table: a variant's runs by one implementation (``out``: key -> (ms,
    iterations, cost, digests)), its share against that implementation's ``default`` runs."""
    per_iteration = statistics.median(ms for ms, *_ in out.values())
    baseline = statistics.median(ms for ms, *_ in default.values())
    share = "" if out is default else f"{(baseline - per_iteration) / baseline:>6.0%}"
    print(f"{label:18} {implementation:6} {compile_seconds:>9.1f} {per_iteration:>8.2f} "
          f"{share:>6}  " + ", ".join(f"{ms:.2f} ({ran}, {cost:.2f})"
                                      for ms, ran, cost, _ in out.values()), flush=True)


if __name__ == "__main__":
    raise SystemExit(main())
