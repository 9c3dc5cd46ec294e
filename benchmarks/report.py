"""Write ``docs/performance.md`` from the benchmarks: each script of ``BENCHMARKS`` runs in its own
process (so each configures JAX's devices and threads its own way), and its printed table goes
into the document verbatim under a paragraph saying what it measures, with the commit, versions
and machine of the run at the top. The document is written only once every benchmark finished.

Run from the repository root (about 35 minutes on 2 cores; ``make performance`` does the same)::

    python benchmarks/report.py
    python benchmarks/report.py --quick --out /tmp/performance.md   # small sizes, for a smoke run
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

from jaxswarm.runtime.atomic import write_atomically
from jaxswarm.studies import provenance

ROOT = Path(__file__).resolve().parents[1]


BENCHMARKS = [
    ("Walks: moves per second against a scalar C loop", "walk.py", [],
     ["--repeats", "2", "--layouts", "64x4", "--maps", "maze20"],
     "Moves per second of one jitted call of the walker, with each implementation (the XLA "
     "lanes and the native kernels; `as lanes`: agents whose outputs equal the lanes', "
     "`compile s`: the walk program's compile seconds), on maze100 and on the 256 x 256 Moving AI "
     "map Berlin_1_256 (a device's seeds' walks share one queue over its lanes), from the swarm's "
     "first memory and from its memory after 30 iterations, on one JAX CPU device and with the "
     "seeds shared out over one device per core (`jax.shard_map`, as sweeps run), beside "
     "`benchmarks/scalar/walk.c` on one core and on all cores (`share`: all against all; "
     "`1 / 1`: one device against one core), which writes the walker's outputs in its layout "
     "(the log of moves, journaled and then laid out agent by agent, as the walker does). "
     "`busy` is the "
     "share of lane-steps that moved an agent; `same` counts the agents whose outputs all equal "
     "the C loop's (it draws the walker's own uniforms); `MiB` is the compiled walk's own memory "
     "(outputs and temporary buffers) at the default step budget and `x2` at twice that budget. "
     "Water drops: IWD's walk as the swarm walks by default and with `while_walking` updates, "
     "beside ACO*'s, on all devices, each an iteration's walk with its per-walk table (IWD's "
     "goal term, ACO*'s transition rule), the three taking turns within each repeat."),
    ("rfd_graded on the paper maps", "rfd.py", [], ["--maps", "maze20,maze100", "--seeds", "3"],
     "Median wall time of one `rfd_graded` run (100 iterations at most, patience 30, 256 drops, "
     "one XLA thread) per paper map over 20 seeds, beside the RFD paper's C# time of RFD*, and "
     "how many seeds reached the optimum."),
    ("IWD_PG per iteration", "iwd_pg.py", ["--repeats", "3"],
     ["--map", "mosaic20", "--keys", "0", "--iterations", "5", "--repeats", "1"],
     "Milliseconds per iteration of `iwd_pg` (its default config) on mosaic50, keys 0-2, 100 "
     "iterations without patience, with each walker implementation (the XLA lanes and the "
     "native kernels), the compile seconds of each, and whether the runs equal the recorded "
     "digests and each other."),
    ("Sweeps against the same runs one at a time", "sweep.py", [],
     ["--values", "2", "--seeds", "8", "--iterations", "10", "--loop-runs", "4"],
     "1,280 `rfd_graded` runs on mosaic50 (8 x 8 values of p_base x alpha, 20 seeds, 100 "
     "iterations) by the sweep runner and by `run` in a Python loop, in one process, for runs "
     "of 16 and of 64 drops, with each walker implementation; the CPU is split into one JAX "
     "device per core."),
    ("Settling and the distance field", "relax.py", [], ["--maps", "maze20", "--repeats", "3"],
     "The batched relaxation behind `rfd_graded`'s settling and the exact distance field, on "
     "maze100."),
    ("Exact planners", "exact.py", [], ["--scenarios", "5", "--repeats", "1"],
     "The exact planners (compiled) beside pyastar2d (C++ A*) and networkx on three Moving AI "
     "maps, one query at a time and in a batch, and D* Lite's repair after a single-cell edit "
     "against A* from scratch."),
    ("Re-planning after the RFD paper's changes", "dynamic.py", ["--seeds", "5"],
     ["--maps", "maze20", "--tables", "2", "--seeds", "1", "--swarms", "rfd_graded"],
     "`rfd_star`, `rfd_graded` and ACO* continuing from their memory after each change of the "
     "RFD paper's Tables 2-5 on the 100 x 100 paper maps (5 seeds here; the issue's check runs "
     "20): time from the change to the first iteration with the new optimum and to the run's "
     "own stop, beside A* from scratch on the changed map and D* Lite's repair."),
    ("Bees: evaluations per second", "bees.py", [], ["--quick", "--maps", "map1"],
     "`cabc` on the bees paper's maps #1 and #2 (ours): one run alone, and a 1,000-run weight "
     "sweep (10 x 10 x 10 values of w1, w2, w3) in one compiled `vmap`; guided-function "
     "evaluations per second (the useful work the traces count), the share of the sweep loop's "
     "iterations that belonged to a run still going, and the peak resident memory."),
    ("Multi-agent planning and the conflict check", "multiagent.py", [], ["--quick"],
     "`prioritized` on the first 100 rows of `random-32-32-10-random-1.scen` (4-connected) in "
     "the given, distance and random orders: median wall time after a warm-up call, expanded "
     "space-time states per second, sum of costs beside `lower_bound`, and `validate`'s verdict. "
     "Then `find_conflicts` (the batched JAX check, host transfers included) beside a "
     "per-time-step hash check in pure Python on 1,000 agents x 1,000 steps of seeded random "
     "walks on `random-64-64-10`, with and without conflicts: both must flag the same vertex "
     "conflicts and swap partners; agent-steps per second and the goal of a 20x speed-up. "
     "Then PIBT's step for 400 agents, LaCAM's and LaCAM*'s solve times, and CBSH-RTC's "
     "constraint-tree nodes and space-time states per second on room-32-32-4-even-1 and "
     "maze-32-32-2-even-1 (20 agents, stopped after 2,000 nodes)."),
    ("One key, one result: what it costs", "one_key.py", ["--runs", "16", "--rounds", "1"],
     ["--swarms", "aco_star,cabc", "--runs", "4", "--iterations", "3", "--repeats", "1",
      "--rounds", "1"],
     "Moves and evaluations per second of every registered swarm, 16 runs of 30 iterations "
     "(32 agents) in one vmapped batch on random-64-64-10 (the bees on plane map1), each "
     "measurement a process of its own; `python benchmarks/one_key.py --baseline REV` puts a "
     "git revision beside it (before 0.7.0: XLA at the host's instruction set, its own `exp` "
     "and sums)."),
]
"""(title, script, arguments, quick arguments, what it measures) of each section."""

BY_HAND = "## Constants measured by hand"
"""The heading of ``docs/performance.md``'s last section, written by hand: a new report keeps it."""


def by_hand() -> str:
    """The hand-written last section of ``docs/performance.md`` (from ``BY_HAND`` on), or ""."""
    path = ROOT / "docs" / "performance.md"
    text = path.read_text() if path.is_file() else ""
    return text[text.index(BY_HAND):] if BY_HAND in text else ""


def run_benchmark(script: str, arguments: list[str]) -> tuple[str, float]:
    """The benchmark's printed output and its wall time; exits naming the script if it fails."""
    command = [sys.executable, str(ROOT / "benchmarks" / script), *arguments]
    began = time.perf_counter()
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True)
    if done.returncode:
        sys.exit(f"benchmarks/{script} failed ({done.returncode}):\n{done.stderr[-3000:]}")
    return done.stdout.rstrip(), time.perf_counter() - began


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "performance.md"))
    parser.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    parser.add_argument("--only", default=None,
                        help="comma-separated scripts to run (default: all)")
    args = parser.parse_args(argv)
    record = provenance.begin(__file__, argv)
    chosen = [entry for entry in BENCHMARKS
              if args.only is None or entry[1] in args.only.split(",")]
    sections = []
    for title, script, arguments, quick, about in chosen:
        used = quick if args.quick else arguments
        print(f"running benchmarks/{script} {' '.join(used)}", flush=True)
        output, seconds = run_benchmark(script, used)
        shown = " ".join(["python", f"benchmarks/{script}", *used])
        sections.append(f"## {title}\n\n{about}\n\n`{shown}` ({seconds:.0f} s):\n\n"
                        f"```text\n{output}\n```\n")
    record.finish(title="Performance on CPU",
                  about="Every table below is the output of a script of `benchmarks/`, run once "
                  "by `benchmarks/report.py` on the machine named here (compile time excluded; "
                  "medians after a warm-up). Shared machines are noisy: compare figures of one "
                  "run, and rerun a script rather than trusting a number here. Each script's "
                  "docstring says exactly what it measures.")
    write_atomically(Path(args.out), record.document("\n".join([*sections, by_hand()])))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
