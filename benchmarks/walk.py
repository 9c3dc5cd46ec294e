"""Moves per second of the walker with the rfd_graded and ACO* transition rules, beside a
scalar C loop of the same rule doing the same work, and the walker's memory.

Maps (``--maps``): paper maps (default maze100) and Moving AI MAPF maps by name (default
Berlin_1_256, 256 x 256, from ``$JAXSWARM_MOVINGAI/mapf`` or ``../shared/benchdata/movingai/mapf``,
start and goal from the mid-length row of its even scenario file, as the studies take them).
For each swarm (``--swarms``), each memory (``initial``: the swarm's first altitudes or
pheromone; ``converged``: its memory after ``--converge`` iterations of a run, when most agents
follow a river, from runs of the largest layout's drops) and each total agent count
(``--layouts`` DROPSxSEEDS: 16 = 16 x 1, one small swarm's walk, 1,024 = 256 x 4 and 16,384 =
256 x 64 by default) the walks of every seed run under ``vmap`` (so all their agents
share one queue over the walker's lanes), jitted, after one warm-up call (compile excluded):
once on one JAX CPU device, and once with the seeds shared out over ``--devices`` devices (one
per core by default, each with one XLA thread; ``jax.shard_map``, as the sweep runner shares a
sweep's runs out; the most devices that divide the seeds), each device walking its seeds'
agents in its own queue on its own core. Every case is walked by each of the walker's
implementations of ``--implementations`` (default ``lanes,native``: the XLA lanes, the
reference, and the native kernels, :mod:`jaxswarm.swarm.walking.native`), named in each walk's
:class:`~jaxswarm.swarm.walking.options.WalkerOptions`, in the same process: one row per
implementation (``walker``), their calls taking turns within each repeat so that the machine's
noise falls on them alike, beside the same reference run. Printed, the median over
``--repeats`` runs:

(ACO* finds no path on maze100 in 30 iterations, so its pheromone stays uniform up to a
factor and both memories give the same walks.)

* ``ms``: the walks' wall time on all devices, ``moves``: moves agents made (one agent changing
  node is one move), and ``busy``: the share of the loops' lane-steps that were moves on all
  devices (the rest idled: an agent that stopped waits for its lane's next refill, and the last
  agents' lanes wait for the slowest; the native walker replays the lanes' schedule for its
  ``lane_steps``, so both rows show the lanes' share),
* ``M moves/s 1 / all``: moves / wall time on one device and on all devices,
* ``ref 1 / all``: the scalar reference's moves/s on one core and on all cores
  (``benchmarks/scalar/walk.c``, built here with ``cc -O3 -march=native -ffp-contract=off
  -fopenmp``, agents shared out over threads), and ``share``: ours on all devices as a share of
  the reference on all cores (``1 / 1``: one device against one core). The reference writes
  what the walker returns, in its layout (the log of moves, each agent's first block, visited
  set, moves, length, position, arrival and stop, the blocks journaled as agents finish and
  laid out agent by agent at the end, as the walker does), and draws the walker's uniforms, so
  it walks the same paths: ``same`` counts the agents whose outputs (their blocks of the log
  included) are all identical (a last-bit difference between C's ``expf`` and XLA's ``exp``
  may send an agent elsewhere at a tie of cumulative weights), and ``as lanes``: the agents
  whose outputs (blocks included) are all identical to the lanes' walk of the same case (``-``
  on the lanes' row, or when ``lanes`` is not measured),
* ``MiB`` and ``x2``: the compiled walk's own memory (its outputs and temporary buffers, from
  XLA's memory analysis; the map, the table and the keys excluded) at the default step budget
  and at twice that budget: what a longer possible path costs (the log's room is set by the
  map for a large walk, :func:`jaxswarm.swarm.walking.log.room_blocks`, not by the budget),
* ``compile s``: the seconds ``lower(...).compile()`` of the one-device walk program took (the
  persistent compilation cache is switched off, so every program is compiled; the native
  kernels' library is built or loaded before the first).

Water drops (``iwd``) read their soil at every step through the walker's hook, so the table
alone does not give their walk and the scalar reference does not apply: a second table times
IWD's walks (soil at its start) beside ACO*'s (pheromone at its start) on the same maps and
layouts, on all devices: ``iwd`` as the swarm walks by default (the soil read during the walk,
the arrived drops' updates after it, :func:`jaxswarm.swarm.iwd.iwd.drop_walk`) and ``iwd ww`` with
``local_updates="while_walking"`` (every drop writes the soil as it moves), each as a share of
ACO*'s moves per second (``/ aco``: what the hook costs), one row per implementation
(``walker``), and ``as lanes``: ``yes`` when every leaf of the three walks equals the lanes'.
Each is timed as its swarm's iteration walks, its per-walk table built in the timed call (IWD's
goal term, ACO*'s transition rule), and the three of every implementation take turns within
each repeat, so that the machine's noise falls on them alike.

Run from the repository root::

    python benchmarks/walk.py
    python benchmarks/walk.py --maps maze100 --layouts 256x1,256x16 --repeats 3 --swarms rfd_graded
    python benchmarks/walk.py --devices 1   # every walk on one device
    python benchmarks/walk.py --implementations native   # the native walker alone
    python benchmarks/walk.py --maps maze20 --layouts 16x2 --repeats 1 --converge 2   # quick
"""
from __future__ import annotations

import argparse
import ctypes
import functools
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, PartitionSpec as P

from jaxswarm.maps.named import PAPER, map_kind
from jaxswarm.runtime.cpu import configure
from jaxswarm.studies.problems import movingai_folder, named_problem, scenario_problem
from jaxswarm.swarm import aco, make, rfd, run
from jaxswarm.swarm.core import Task
from jaxswarm.swarm.iwd.iwd import drop_walk
from jaxswarm.swarm.walking import Walk, step_budget, walk
from jaxswarm.swarm.walking.log import BLOCK, room_blocks
from jaxswarm.swarm.walking.native import check_implementations
from jaxswarm.swarm.walking.options import IMPLEMENTATIONS, WalkerOptions
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import slot_offsets

SCALAR_SOURCE = Path(__file__).parent / "scalar" / "walk.c"

TRANSITION_RULES = {
    "rfd_graded": (rfd.graded_transition, lambda state: state.altitude),
    "aco_star": (functools.partial(aco.transition_rule, goal_distance=True),
                 lambda state: state.pheromone),
}
"""The walks measured: each swarm's transition table of its memory, and its memory."""

PER_AGENT = ("visited", "moves", "length", "position", "arrived", "stuck")
"""The walker's per-agent outputs (:class:`~jaxswarm.swarm.walking.Walk` fields) the reference
writes."""

OUTPUTS = ("nodes", "slots", "offset") + PER_AGENT + ("journal_nodes", "journal_slots",
                                                        "journaled")
"""The buffers of the reference's ``Outputs`` struct, in its order: the log
(:class:`~jaxswarm.swarm.walking.log.MoveLog`'s ``nodes``, ``slots``, ``offset``), the
per-agent outputs and the journal's scratch."""

MIB = 2 ** 20


class _Outputs(ctypes.Structure):
    _fields_ = [(name, ctypes.c_void_p) for name in OUTPUTS]


def machine() -> str:
    return (f"{platform.platform()} | {os.cpu_count()} CPUs | python "
            f"{platform.python_version()} | jax {jax.__version__} ({jax.default_backend()})")


def load_problem(name: str) -> tuple[Graph, Task]:
    """A paper map with its own start and goal, or a Moving AI MAPF map by name with the
    mid-length row of its even scenario file."""
    problem = (named_problem(name) if map_kind(name) == PAPER
               else scenario_problem(movingai_folder(), name))
    return problem.graph, problem.task


def build_scalar(directory: str) -> ctypes.CDLL:
    """The scalar reference, compiled into ``directory``; exits naming the compiler's error."""
    library = Path(directory) / "walk.so"
    command = [os.environ.get("CC", "cc"), "-O3", "-march=native", "-ffp-contract=off",
               "-fopenmp", "-shared", "-fPIC", str(SCALAR_SOURCE), "-o", str(library), "-lm"]
    try:
        subprocess.run(command, check=True, capture_output=True, text=True)
    except (OSError, subprocess.CalledProcessError) as error:
        detail = getattr(error, "stderr", "") or error
        sys.exit(f"cannot build the scalar reference with {' '.join(command)}: {detail}")
    scalar = ctypes.CDLL(str(library))
    pointer, i32, u32 = ctypes.c_void_p, ctypes.c_int32, ctypes.c_uint32
    scalar.walk_all.argtypes = [pointer, i32, i32, pointer, i32, i32, i32, i32, u32, u32,
                                ctypes.c_int64, _Outputs]
    scalar.walk_all.restype = ctypes.c_int64
    scalar.set_threads.argtypes = [i32]
    return scalar


def seed_words(keys: jax.Array) -> np.ndarray:
    """u32[S, 2]: the walker's per-walk seeds, two words drawn from each walk's key."""
    return np.asarray(jax.vmap(lambda key: jax.random.bits(key, (1, 2), jnp.uint32))(keys))[:, 0]


def log_room(graph: Graph, agents: int, steps: int) -> int:
    """Blocks of the log of a walk of ``agents`` agents with budget ``steps``, as the walker
    sizes it by default."""
    return room_blocks(agents, steps, None, step_budget(graph, None))


def scalar_outputs(graph: Graph, seeds: int, agents: int, steps: int) -> dict[str, np.ndarray]:
    """The reference's buffers for ``seeds`` walks of ``agents`` agents, each output as the
    walker lays it out (the log per seed, the rest per agent), and one journal (scratch)."""
    words = (graph.num_nodes + 31) // 32
    room = log_room(graph, agents, steps)
    count = seeds * agents
    return dict(nodes=np.empty((seeds, room, BLOCK), np.int32),
                slots=np.empty((seeds, room, BLOCK), np.int8),
                offset=np.empty((seeds, agents), np.int32),
                visited=np.empty((count, words), np.uint32),
                moves=np.empty(count, np.int32), length=np.empty(count, np.float32),
                position=np.empty(count, np.int32), arrived=np.empty(count, np.bool_),
                stuck=np.empty(count, np.bool_),
                journal_nodes=np.empty((room, BLOCK), np.int32),
                journal_slots=np.empty((room, BLOCK), np.int8),
                journaled=np.empty(agents, np.int32))


def scalar_walks(scalar, graph: Graph, task: Task, table: np.ndarray, words: np.ndarray,
                 out: dict[str, np.ndarray], agents: int, steps: int) -> int:
    """Every seed's ``agents`` walks by the reference into ``out`` (visited sets reset first as
    the walker's start); returns the moves made. Exits when the log had no room (the walker
    would have made the run again with more)."""
    out["visited"].fill(0)
    offsets = np.ascontiguousarray(np.asarray(slot_offsets(graph), np.int32))
    room = out["nodes"].shape[1]
    total = 0
    for s, (word_0, word_1) in enumerate(words):
        rows = slice(s * agents, (s + 1) * agents)
        buffers = {name: out[name][s] for name in ("nodes", "slots", "offset")}
        buffers.update({name: out[name][rows] for name in PER_AGENT})
        buffers.update({name: out[name] for name in ("journal_nodes", "journal_slots",
                                                     "journaled")})
        fields = _Outputs(*(buffers[name].ctypes.data for name in OUTPUTS))
        moves = scalar.walk_all(table.ctypes.data, graph.num_nodes, graph.max_degree,
                                offsets.ctypes.data, int(task.start), int(task.goal), agents,
                                steps, int(word_0), int(word_1), room, fields)
        if moves < 0:
            sys.exit(f"the reference's log of {room} blocks had no room for seed {s}'s moves")
        total += moves
    return total


def same_agents(result: Walk, out: dict[str, np.ndarray]) -> int:
    """How many agents have every output of the walker's ``result`` (its log's offset and
    blocks included) equal to the reference's."""
    agree = None
    for name in PER_AGENT:
        ours = np.asarray(getattr(result, name))
        ours = ours.reshape((-1,) + ours.shape[2:])
        equal = np.all((ours == out[name]).reshape(len(ours), -1), axis=1)
        agree = equal if agree is None else agree & equal
    offset = np.asarray(result.log.offset)
    agree &= (offset == out["offset"]).reshape(-1)
    equal_blocks = np.all(np.asarray(result.log.nodes) == out["nodes"], axis=2) & np.all(
        np.asarray(result.log.slots) == out["slots"], axis=2)  # [seeds, room]
    for s, (starts, equal) in enumerate(zip(out["offset"], equal_blocks)):
        agents = len(starts)
        owner = np.searchsorted(starts, np.arange(len(equal)), side="right") - 1
        owned = np.arange(len(equal)) - starts[owner] < (
            out["moves"][s * agents + owner] + BLOCK - 1) // BLOCK
        wrong = np.zeros(agents, bool)
        np.logical_or.at(wrong, owner[owned & ~equal], True)
        agree[s * agents:(s + 1) * agents] &= ~wrong
    return int(agree.sum())


def memories(swarm_name: str, graph, task, drops: int, converge: int) -> dict:
    """The swarm's memory at its start and after ``converge`` iterations of a run (key 0)."""
    swarm = make(swarm_name, num_agents=drops)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    later, _ = run(swarm, jax.random.key(0), graph, task, params, iterations=converge)
    _, memory = TRANSITION_RULES[swarm_name]
    return {"initial": memory(state), "converged": memory(later)}


def device_count(seeds: int) -> int:
    """The most JAX devices, at most ``len(jax.devices())``, that share ``seeds`` out evenly."""
    return max(d for d in range(1, len(jax.devices()) + 1) if seeds % d == 0)


def over_devices(walks, devices: int):
    """``walks(keys key[S], *shared)`` (a ``vmap`` over the keys), jitted, its keys shared out
    over the first ``devices`` JAX devices (``jax.shard_map``), ``shared`` on every device."""
    mesh = Mesh(np.array(jax.devices()[:devices]), ("seeds",))

    def sharded(keys, *shared):
        return jax.shard_map(walks, mesh=mesh, in_specs=(P("seeds"),) + (P(),) * len(shared),
                             out_specs=P("seeds"), check_vma=False)(keys, *shared)

    return jax.jit(sharded)


def batched_walks(drops: int, steps: int, devices: int = 1, implementation: str | None = None):
    """``(keys key[S], table f32[N, K], graph, task) -> Walk``: S seeds' walks under ``vmap``
    on ``devices`` devices (:func:`over_devices`), jitted (the map an argument, not constants
    for XLA to fold), walked by the walker's ``implementation`` (None: the environment's
    choice, :func:`jaxswarm.swarm.walking.native.implementation`)."""
    walker = WalkerOptions(implementation=implementation)
    return over_devices(lambda keys, table, graph, task: jax.vmap(lambda key: walk(
        key, graph, table, task.start, task.goal, num_agents=drops, max_steps=steps,
        walker=walker))(keys), devices)


def busy_share(result: Walk, devices: int) -> float:
    """The share of the lane-steps of ``result``'s loops (one per device, each of its runs
    reporting its loop's count) that moved an agent."""
    lane_steps = np.asarray(result.lane_steps).reshape(devices, -1)[:, 0]
    return int(result.moves.sum()) / int(lane_steps.sum())


def own_bytes(compiled) -> int:
    """Bytes a compiled walk holds beyond its arguments: its outputs and temporary buffers,
    from XLA's memory analysis."""
    analysis = compiled.memory_analysis()
    return analysis.output_size_in_bytes + analysis.temp_size_in_bytes


def walk_outputs(result: Walk) -> dict[str, np.ndarray]:
    """The walker's ``result`` laid out as the reference writes its outputs
    (:func:`scalar_outputs`), so that :func:`same_agents` compares another walk with it."""
    out = {name: np.asarray(getattr(result, name)) for name in PER_AGENT}
    out = {name: value.reshape((-1,) + value.shape[2:]) for name, value in out.items()}
    return dict(out, nodes=np.asarray(result.log.nodes), slots=np.asarray(result.log.slots),
                offset=np.asarray(result.log.offset))


def compiled_walks(args: tuple, drops: int, steps: int, implementations: list[str],
                   devices: int = 1) -> dict:
    """``{implementation: (compiled walks, compile seconds)}``: :func:`batched_walks` of each
    implementation lowered for ``args`` and compiled, timed."""
    programs = {}
    for implementation in implementations:
        began = time.perf_counter()
        compiled = batched_walks(drops, steps, devices, implementation).lower(*args).compile()
        programs[implementation] = (compiled, time.perf_counter() - began)
    return programs


def reference_rates(scalar, graph, task, table, keys, drops: int, steps: int,
                    repeats: int) -> tuple[dict, dict[str, np.ndarray]]:
    """``({threads: moves/s}, outputs)``: the reference's median rate on one core and on all
    cores over ``repeats`` runs, and what it wrote (:func:`scalar_outputs`)."""
    words = seed_words(keys)
    flat_table = np.ascontiguousarray(np.asarray(table, np.float32))
    out = scalar_outputs(graph, len(keys), drops, steps)
    rates = {}
    for threads in (1, os.cpu_count()):
        scalar.set_threads(threads)
        walls = []
        for _ in range(repeats):
            began = time.perf_counter()
            scalar_moves = scalar_walks(scalar, graph, task, flat_table, words, out, drops, steps)
            walls.append(time.perf_counter() - began)
        rates[threads] = scalar_moves / statistics.median(walls)
    return rates, out


def measure(scalar, swarm_name: str, graph, task, memory, drops: int, seeds: int,
            repeats: int, implementations: list[str]) -> dict:
    """``{implementation: row}``: each implementation's walks of one case (one row of the
    table, see the module docstring), timed in turn, beside the reference's."""
    params = make(swarm_name, num_agents=drops).default_params
    rule, _ = TRANSITION_RULES[swarm_name]
    table = rule(graph, task, memory, params)
    steps = step_budget(graph, None)
    keys = jax.random.split(jax.random.key(1), seeds)
    args = (keys, table, graph, task)
    ones = compiled_walks(args, drops, steps, implementations)  # timed and measured
    one_device = timed_in_turn({name: functools.partial(walks, *args)
                                for name, (walks, _) in ones.items()}, repeats)
    longer = compiled_walks(args, drops, 2 * steps, implementations)
    devices = device_count(seeds)
    all_devices = timed_in_turn({name: functools.partial(walks, *args) for name, (walks, _)
                                 in compiled_walks(args, drops, steps, implementations,
                                                   devices).items()}, repeats)
    reference, out = reference_rates(scalar, graph, task, table, keys, drops, steps, repeats)
    lanes = walk_outputs(all_devices["lanes"][1]) if "lanes" in all_devices else None
    rows = {}
    for name, (seconds, result) in all_devices.items():
        moves = int(result.moves.sum())
        rows[name] = dict(
            agents=drops * seeds, seconds=seconds, moves=moves, busy=busy_share(result, devices),
            one_device=moves / one_device[name][0], rate=moves / seconds,
            one_core=reference[1], all_cores=reference[os.cpu_count()],
            same=same_agents(result, out),
            as_lanes=None if lanes is None or name == "lanes" else same_agents(result, lanes),
            memory=own_bytes(ones[name][0]), longer=own_bytes(longer[name][0]),
            compile=ones[name][1])
    return rows


def drop_calls(graph, task, drops: int, seeds: int, implementation: str) -> dict:
    """``{name: call()}``: one iteration's walks of IWD (as it walks by default, and with
    ``while_walking`` updates) and of ACO*, each as its swarm makes them (its per-walk table
    included: IWD's goal term, ACO*'s transition rule), from each swarm's start, same keys and
    layout, walked by ``implementation``, on all the devices that share the seeds out."""
    walker = WalkerOptions(implementation=implementation)
    keys = jax.random.split(jax.random.key(1), seeds)
    iwd_swarm = make("iwd", num_agents=drops, walker=walker)
    aco_swarm = make("aco_star", num_agents=drops, walker=walker)
    iwd_params, aco_params = iwd_swarm.default_params, aco_swarm.default_params
    soil = iwd_swarm.init(jax.random.key(0), graph, task, iwd_params).soil
    pheromone = aco_swarm.init(jax.random.key(0), graph, task, aco_params).pheromone
    devices = device_count(seeds)
    steps = step_budget(graph, None)

    def drop_walks(local_updates):
        walks = over_devices(lambda keys, graph, task, soil: jax.vmap(lambda key: drop_walk(
            key, graph, task, soil, iwd_params, num_agents=drops, max_steps=None,
            local_updates=local_updates, walker=walker))(keys), devices)
        return lambda: walks(keys, graph, task, soil)

    def ant_walk(key, graph, task, pheromone):
        table = aco.transition_rule(graph, task, pheromone, aco_params, goal_distance=True)
        return walk(key, graph, table, task.start, task.goal, num_agents=drops, max_steps=steps,
                    walker=walker)

    ant_walks = over_devices(lambda keys, graph, task, pheromone: jax.vmap(
        lambda key: ant_walk(key, graph, task, pheromone))(keys), devices)
    return {"iwd": drop_walks("arrived"), "iwd ww": drop_walks("while_walking"),
            "aco_star": lambda: ant_walks(keys, graph, task, pheromone)}


def measure_drops(graph, task, drops: int, seeds: int, repeats: int,
                  implementations: list[str]) -> dict:
    """``{implementation: ({name: (seconds, moves)}, same as lanes)}`` of the walks of
    :func:`drop_calls`, every implementation's calls taking turns, one run each per round
    (:func:`timed_in_turn`), so that the machine's noise falls on all of them alike; ``same as
    lanes``: every leaf of the three walks equals the lanes' (None for the lanes, or without
    them)."""
    calls = {(implementation, name): call for implementation in implementations
             for name, call in drop_calls(graph, task, drops, seeds, implementation).items()}
    timings = timed_in_turn(calls, repeats)
    rows = {}
    for implementation in implementations:
        mine = {name: timings[implementation, name] for name in ("iwd", "iwd ww", "aco_star")}
        same = None if "lanes" not in implementations or implementation == "lanes" else all(
            same_leaves(result, timings["lanes", name][1]) for name, (_, result) in mine.items())
        rows[implementation] = ({name: (seconds, int(result.moves.sum()))
                                 for name, (seconds, result) in mine.items()}, same)
    return rows


def same_leaves(one, other) -> bool:
    """Whether every leaf of two pytrees has the same shape, dtype and bytes (NaNs included)."""
    ones, others = jax.tree_util.tree_leaves(one), jax.tree_util.tree_leaves(other)
    return len(ones) == len(others) and all(
        a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()
        for a, b in ((np.asarray(a), np.asarray(b)) for a, b in zip(ones, others)))


def timed_in_turn(calls: dict, repeats: int) -> dict:
    """``{name: (median seconds, result)}`` of each of ``calls`` (``{name: call()}``) over
    ``repeats`` rounds after a warm-up, the calls taking turns within each round."""
    results = {name: jax.block_until_ready(call()) for name, call in calls.items()}
    times = {name: [] for name in calls}
    for _ in range(repeats):
        for name, call in calls.items():
            began = time.perf_counter()
            results[name] = jax.block_until_ready(call())
            times[name].append(time.perf_counter() - began)
    return {name: (statistics.median(times[name]), results[name]) for name in calls}


def chosen_implementations(text: str, parser: argparse.ArgumentParser) -> list[str]:
    """The walker's implementations ``--implementations`` names, checked
    (:func:`~jaxswarm.swarm.walking.native.check_implementations`: the native kernels built or
    loaded, so that no compile time below includes that)."""
    try:
        return check_implementations(text.split(","))
    except ValueError as error:
        parser.error(f"--implementations: {error}")


def walk_table(problems: dict, layouts: list, args, implementations: list[str]) -> None:
    """Print the walker's table (see the module docstring)."""
    print(f"{'map':13} {'swarm':10} {'memory':9} {'walker':6} {'agents':>7} {'ms':>8} "
          f"{'moves':>9} {'busy':>5} {'M moves/s 1 / all':>17} {'ref 1 / all':>12} "
          f"{'share':>6} {'1 / 1':>6} {'same':>12} {'as lanes':>12} {'MiB':>7} {'x2':>7} "
          f"{'compile s':>9}")
    with tempfile.TemporaryDirectory() as directory:
        scalar = build_scalar(directory)
        for map_name, (graph, task) in problems.items():
            for swarm_name in args.swarms.split(","):
                drops_most = max(drops for drops, _ in layouts)
                states = memories(swarm_name, graph, task, drops_most, args.converge)
                for memory_name, memory in states.items():
                    for drops, seeds in layouts:
                        rows = measure(scalar, swarm_name, graph, task, memory, drops, seeds,
                                       args.repeats, implementations)
                        for name, r in rows.items():
                            print(f"{map_name:13} {swarm_name:10} {memory_name:9} {name:6} "
                                  + walk_row(r), flush=True)


def walk_row(r: dict) -> str:
    """One implementation's columns of the walker's table, from ``agents`` on."""
    as_lanes = "-" if r["as_lanes"] is None else f"{r['as_lanes']}/{r['agents']}"
    return (f"{r['agents']:>7} {1e3 * r['seconds']:>8.1f} {r['moves']:>9} {r['busy']:>5.2f} "
            f"{r['one_device'] / 1e6:>9.1f} / {r['rate'] / 1e6:<5.1f} "
            f"{r['one_core'] / 1e6:>5.1f} / {r['all_cores'] / 1e6:<5.1f} "
            f"{r['rate'] / r['all_cores']:>6.2f} {r['one_device'] / r['one_core']:>6.2f} "
            f"{r['same']:>6}/{r['agents']:<5} {as_lanes:>12} {r['memory'] / MIB:>7.1f} "
            f"{r['longer'] / MIB:>7.1f} {r['compile']:>9.2f}")


def drop_table(problems: dict, layouts: list, repeats: int, implementations: list[str]) -> None:
    """Print the water drops' table (see the module docstring)."""
    print("\nwater drops (iwd, soil hook) beside ACO*, from their initial memory: M moves/s")
    print(f"{'map':13} {'agents':>7} {'walker':6} {'iwd':>7} {'iwd ww':>7} {'aco':>7} "
          f"{'iwd / aco':>9} {'ww / aco':>8} {'as lanes':>8}")
    for map_name, (graph, task) in problems.items():
        for drops, seeds in layouts:
            rows = measure_drops(graph, task, drops, seeds, repeats, implementations)
            for name, (timings, same) in rows.items():
                rates = {walks: moves / seconds / 1e6
                         for walks, (seconds, moves) in timings.items()}
                as_lanes = "-" if same is None else ("yes" if same else "NO")
                print(f"{map_name:13} {drops * seeds:>7} {name:6} {rates['iwd']:>7.2f} "
                      f"{rates['iwd ww']:>7.2f} {rates['aco_star']:>7.2f} "
                      f"{rates['iwd'] / rates['aco_star']:>9.2f} "
                      f"{rates['iwd ww'] / rates['aco_star']:>8.2f} {as_lanes:>8}", flush=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", default="maze100,Berlin_1_256",
                        help="comma-separated paper maps or Moving AI MAPF map names")
    parser.add_argument("--swarms", default="rfd_graded,aco_star",
                        help=f"comma-separated, from {', '.join(TRANSITION_RULES)}")
    parser.add_argument("--layouts", default="16x1,256x4,256x64", help="comma-separated DROPSxSEEDS")
    parser.add_argument("--converge", type=int, default=30,
                        help="iterations run for the converged memory")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--devices", type=int, default=os.cpu_count(),
                        help="JAX CPU devices, one XLA thread each (default: one per core)")
    parser.add_argument("--implementations", default=",".join(IMPLEMENTATIONS),
                        help=f"comma-separated walker implementations, from "
                             f"{', '.join(IMPLEMENTATIONS)}")
    args = parser.parse_args(argv)
    # Before JAX's first computation; compile seconds are measured, so no cached programs.
    jax.config.update("jax_enable_compilation_cache", False)
    configure(devices=args.devices, threads=args.devices)
    implementations = chosen_implementations(args.implementations, parser)
    layouts = [tuple(int(part) for part in layout.split("x"))
               for layout in args.layouts.split(",")]
    problems = {name: load_problem(name) for name in args.maps.split(",")}
    print(f"machine: {machine()}")
    print(f"median of {args.repeats} runs after a warm-up compile; ours ("
          f"{', '.join(implementations)}) on 1 and up to {len(jax.devices())} devices, "
          f"reference: {SCALAR_SOURCE.name} on 1 and {os.cpu_count()} cores")
    walk_table(problems, layouts, args, implementations)
    drop_table(problems, layouts, args.repeats, implementations)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
