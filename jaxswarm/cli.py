"""The ``jaxswarm`` command.

``jaxswarm demo`` plans on one of the RFD paper's maps (or a Moving AI ``.map`` file) with the
exact planners and the swarm planners, prints a comparison table (length, optimality gap, work,
time) and writes figures of the paths and of the swarms' memory and convergence.

``jaxswarm robot`` walks a robot through a map with hidden blocks (:mod:`jaxswarm.dynamic.robot`):
a swarm and D* Lite re-plan whenever it finds one; it prints what each did and writes a GIF of the
walk.

``jaxswarm mapf MAP SCEN`` plans for the first ``--agents`` agents of a Moving AI MAPF scenario
(:mod:`jaxswarm.multiagent`) with one registered planner (:mod:`jaxswarm.multiagent.registry`:
the A* report's scheme, prioritised planning, the CBS family, PIBT, LaCAM), validates the
solution, prints its sum of costs against the lower bound and writes a GIF of the agents moving;
it exits with status 1 when the planner finds no solution (naming the agent) or its solution
breaks a rule.

``jaxswarm sweep FILE`` runs (or resumes) the parameter sweep a TOML file describes (see
:mod:`jaxswarm.sweep.spec`), writes its results store and figures and prints the best params per
map.

``jaxswarm tune FILE`` searches a swarm's open constants as a TOML file describes (see
:mod:`jaxswarm.tune.spec`: iterated racing, random search, the grid or evolution strategies on
training instances), rescores the best settings beside the swarm's defaults on held-out
instances and prints them; a killed tune resumes from its store.

``jaxswarm replay STORE ROW`` runs one row of a sweep store (or of a table's ``runs.csv``) again,
alone (:mod:`jaxswarm.sweep.replay`), prints the stored and the replayed figures, draws the run and
exits with status 1 when the replay does not reproduce the row bit for bit.
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import jax

from jaxswarm.dynamic.robot import MEMORY, check_world, dstar_robot, hidden_blocks, swarm_robot
from jaxswarm.exact import astar, bidirectional_astar, dijkstra, optimum
from jaxswarm.maps.entry import ResolvedMap, resolve
from jaxswarm.maps.named import named_entry, named_label
from jaxswarm.maps.paper import PAPER_MAPS
from jaxswarm.multiagent import ORDERS, UNREACHABLE, load_instance, lower_bound, validate
from jaxswarm.multiagent import registry as planners
from jaxswarm.multiagent.limits import OptionError
from jaxswarm.runtime.cpu import configure
from jaxswarm.swarm import make, registry, run
from jaxswarm.swarm.walking.native import VARIABLE as WALKER_VARIABLE
from jaxswarm.swarm.walking.native import implementation
from jaxswarm.swarm.walking.options import IMPLEMENTATIONS
from jaxswarm.sweep.spec import DEFAULT_MAX_RUNS
from jaxswarm.tune.spec import HELD_OUT_SETTINGS
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import as_node, path_length

EXACT_PLANNERS = {"Dijkstra": dijkstra, "A*": astar, "bidirectional A*": bidirectional_astar}
def swarm_label(name: str) -> str:
    """A registered swarm's name in tables: its label and whether it is a paper's algorithm as
    written ("paper") or this project's own ("ours")."""
    entry = registry.entry(name)
    return f"{entry.label} ({'paper' if entry.faithful else 'ours'})"


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``jaxswarm`` command; returns the exit status."""
    parser = _parser()
    args = parser.parse_args(argv)
    for option in ("devices", "threads"):
        value = getattr(args, option)
        if value is not None:
            try:
                configure(**{option: value})
            except (ValueError, RuntimeError) as error:
                parser.error(f"--{option}: {error}")
    try:
        command = {"demo": run_demo, "robot": run_robot, "mapf": run_mapf,
                   "sweep": run_sweep_command, "tune": run_tune_command,
                   "replay": run_replay}
        return command[args.command](args)
    except ValueError as error:
        parser.exit(2, f"jaxswarm {args.command}: error: {error}\n")
    except KeyboardInterrupt:
        kept = {"sweep": "chunks", "tune": "batches"}.get(args.command)
        resume = (f"; the finished {kept} are kept: run the same command again to resume"
                  if kept else "")
        parser.exit(130, f"jaxswarm {args.command}: interrupted{resume}\n")


def _parser() -> argparse.ArgumentParser:
    """The ``jaxswarm`` command's arguments: ``--threads`` and a sub-command."""
    parser = argparse.ArgumentParser(prog="jaxswarm", description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int,
                        help="XLA:CPU intra-op threads (default: one per core); 1 is fastest for "
                             "single runs on a few cores, see jaxswarm.runtime.cpu")
    parser.add_argument("--devices", type=int,
                        help="JAX CPU devices (default: JAX's, one): a sweep's or a tune's runs "
                             "are shared out over them, one core each, see jaxswarm.runtime.cpu")
    commands = parser.add_subparsers(dest="command", required=True)
    _add_demo_parser(commands)
    _add_robot_parser(commands)
    _add_mapf_parser(commands)
    _add_sweep_parser(commands)
    _add_tune_parser(commands)
    _add_replay_parser(commands)
    return parser


def _add_demo_parser(subparsers) -> None:
    """The ``demo`` sub-command: plan on one map with every planner."""
    demo = subparsers.add_parser("demo",
                                 help="plan on a real map, print a table, write a figure")
    demo.add_argument("--map", default="mosaic50",
                      help=f"a paper map ({', '.join(PAPER_MAPS)}), a random path map "
                           "pathmapWxH (e.g. pathmap20x20) or a Moving AI .map file")
    demo.add_argument("--start", type=_point, help="x,y (required with a .map file)")
    demo.add_argument("--goal", type=_point, help="x,y (required with a .map file)")
    demo.add_argument("--repeats", type=int, default=5, help="runs per planner (median time)")
    demo.add_argument("--seed", type=int, default=0, help="PRNG seed of the swarm planners")
    demo.add_argument("--drops", type=int,
                      help="agents per swarm iteration (default: each swarm's own, e.g. 256 "
                           "drops, the Max-Min ACO paper's 50 ants)")
    demo.add_argument("--iterations", type=int, default=100, help="swarm iteration budget")
    demo.add_argument("--swarms", type=_swarm_names, default=registry.registered(Graph),
                      help="comma-separated registered swarms that plan on graphs (default: "
                           "all)")
    demo.add_argument("--out", type=Path,
                      help="figure path (default out/demo_MAP.png); each swarm's figure is "
                           "written beside it with the swarm's name appended")


def _add_robot_parser(subparsers) -> None:
    """The ``robot`` sub-command: a robot that finds hidden blocks and re-plans."""
    robot = subparsers.add_parser("robot",
                                  help="a robot that finds hidden blocks and re-plans")
    robot.add_argument("--map", default="maze20",
                       help=f"a paper map ({', '.join(PAPER_MAPS)}), a random path map "
                            "pathmapWxH (e.g. pathmap20x20, seeded by --seed) or a Moving AI "
                            ".map file")
    robot.add_argument("--start", type=_point, help="x,y (required with a .map file)")
    robot.add_argument("--goal", type=_point, help="x,y (required with a .map file)")
    robot.add_argument("--swarm", type=_swarm_names, default=("improved_max_min_aco",),
                       help="the registered swarm that plans (default improved_max_min_aco)")
    robot.add_argument("--memory", choices=MEMORY, default="keep",
                       help="the swarm's memory at a re-plan: kept (adapted) or wiped")
    robot.add_argument("--blocks", type=int, default=2, help="hidden blocks on the robot's way")
    robot.add_argument("--seed", type=int, default=0, help="seed of the blocks and the swarm")
    robot.add_argument("--iterations", type=int, default=100, help="iterations per plan")
    robot.add_argument("--max-plans", type=int, default=16, help="plans at most")
    robot.add_argument("--out", type=Path,
                       help="GIF of the swarm's walk (default out/robot_MAP.gif); a PNG of the "
                            "whole walk is written beside it")


def _add_mapf_parser(subparsers) -> None:
    """The ``mapf`` sub-command: plan for many agents on a Moving AI MAPF map."""
    mapf = subparsers.add_parser("mapf", help="plan for many agents on a Moving AI MAPF map")
    mapf.add_argument("map", type=Path, help="a Moving AI .map file (loaded 4-connected)")
    mapf.add_argument("scen", type=Path, help="a .scen file of the map: its first rows are the "
                                              "agents")
    mapf.add_argument("--agents", type=int, default=10, help="how many agents (default 10)")
    mapf.add_argument("--planner", choices=planners.registered(), default="prioritized",
                      help="; ".join(f"{name}: {planners.entry(name).label}"
                                     for name in planners.registered())
                           + " (default prioritized; see jaxswarm.multiagent.registry)")
    for option, (kind, about) in MAPF_OPTIONS.items():
        owners = _owners(option)
        mapf.add_argument(_flag(option), type=kind, choices=ORDERS if option == "order" else None,
                          help=f"{about} ({', '.join(owners)}; default: the planner's)")
    gif = mapf.add_mutually_exclusive_group()
    gif.add_argument("--gif", type=Path,
                     help="GIF of the agents moving (default out/mapf_MAP_PLANNER.gif)")
    gif.add_argument("--no-gif", action="store_true", help="write no GIF")


def _add_sweep_parser(subparsers) -> None:
    """The ``sweep`` sub-command: run or resume a sweep from a TOML file."""
    sweep = subparsers.add_parser("sweep",
                                  help="run or resume a parameter sweep from a TOML file")
    sweep.add_argument("file", type=Path, help="the sweep spec (TOML)")
    sweep.add_argument("--out", type=Path, help="results directory (default out/sweeps/NAME)")
    sweep.add_argument("--no-progress", action="store_true", help="no progress bar")
    sweep.add_argument("--no-plots", action="store_true", help="write no figures")
    _add_max_runs(sweep, "maps x param combinations x seeds")


def _add_max_runs(command, counted: str) -> None:
    """The ``--max-runs`` option of a command whose spec makes ``counted`` runs."""
    command.add_argument("--max-runs", type=_positive_count, default=DEFAULT_MAX_RUNS,
                         help=f"refuse a spec of more runs than this ({counted}; default "
                              f"{DEFAULT_MAX_RUNS:,}), before anything is built")


def _positive_count(text: str) -> int:
    try:
        count = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if count < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {count}")
    return count


def _add_tune_parser(subparsers) -> None:
    """The ``tune`` sub-command: search a swarm's constants from a TOML file."""
    tune = subparsers.add_parser(
        "tune", help="search a swarm's open constants (iterated racing, random search, grid or "
                     "evolution strategies) and rescore the best on held-out instances",
        description="Search the params a TOML tune spec names (see jaxswarm.tune.spec and "
                    "docs/tuning.md) on its training instances within its budget of runs, then "
                    "rescore the best settings and the swarm's defaults on its held-out "
                    "instances. Writes the runs (resumable), the race's log and figure, "
                    "held_out.csv and best.json.")
    tune.add_argument("file", type=Path, help="the tune spec (TOML)")
    tune.add_argument("--out", type=Path, help="tune directory (default out/tune/NAME)")
    _add_max_runs(tune, f"the budget and up to {HELD_OUT_SETTINGS} settings on each held-out "
                        "instance")


def _add_replay_parser(subparsers) -> None:
    """The ``replay`` sub-command: run one row of a sweep store again, alone."""
    replay = subparsers.add_parser(
        "replay", help="run one row of a sweep store or of a results table again, alone, "
                       "check that it gives the stored figures bit for bit and draw it")
    replay.add_argument("store", type=Path,
                        help="a sweep's results directory, or a results/ folder with runs.csv")
    replay.add_argument("row", type=int,
                        help="the row's position in jaxswarm.sweep.read_results(STORE), or in "
                             "runs.csv, from 0")
    replay.add_argument("--out", type=Path,
                        help="folder of the figure (default out/replay/STORE_NAME)")
    replay.add_argument("--walker", choices=IMPLEMENTATIONS,
                        help="the walker's implementation (as JAXSWARM_WALKER; default: native "
                             "on CPU): both give the same bits")


def run_replay(args: argparse.Namespace) -> int:
    """Replay the row, print stored and replayed figures, write the figure; exit status 1 when
    the replay differs from the row."""
    import matplotlib

    matplotlib.use("Agg")
    from jaxswarm.plot.sweep import plot_replay
    from jaxswarm.sweep.replay import replay_row

    if args.walker:
        os.environ[WALKER_VARIABLE] = args.walker
    replayed = replay_row(args.store, args.row)
    row = replayed.row
    print(f"{args.store} row {args.row}: {replayed.title} (walker: "
          f"{implementation()})")
    for name in replayed.figures:
        mark = "" if f"{name}:" not in " ".join(replayed.differences) else "   <- differs"
        print(f"  {name:<12} stored {row[name]!s:<20} replayed {replayed.figures[name]!s}{mark}")
    out = args.out if args.out is not None else Path("out/replay") / Path(args.store).name
    print(f"wrote {plot_replay(replayed, out / f'row{args.row}.png')}")
    print("reproduced bit for bit" if replayed.reproduced else "the replay differs from the row")
    return 0 if replayed.reproduced else 1


def run_sweep_command(args: argparse.Namespace) -> int:
    """Check the spec (before any compute), run or resume the sweep, plot, print a summary."""
    from jaxswarm.sweep import default_out, load_spec, run_sweep
    from jaxswarm.sweep.runner import check_folder
    from jaxswarm.plot.sweep import plot_sweep, summary

    spec = load_spec(args.file, max_runs=args.max_runs)
    out = args.out if args.out is not None else default_out(spec)
    check_folder(out, "--out")
    print(f"sweep {spec.name}: {spec.algorithm}, {len(spec.maps)} map(s) x "
          f"{spec.num_combinations} param combination(s) x {len(spec.seeds)} seed(s) = "
          f"{spec.num_runs * len(spec.maps)} runs -> {out}")
    frame = run_sweep(spec, out, progress=not args.no_progress)
    swept = list(spec.params)
    if swept and not args.no_plots:
        for path in plot_sweep(frame, swept, out, spec.log_scale):
            print(f"wrote {path}")
    table = summary(frame, ["map", *swept])
    best = table.sort_values(["success", "gap"], ascending=[False, True]).groupby(
        "map", sort=False).head(1)
    print("best params per map (highest success rate, then lowest mean gap):")
    print(best.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    return 0


def run_tune_command(args: argparse.Namespace) -> int:
    """Check the spec (before any compute), run or resume the tune, print the held-out table."""
    import matplotlib

    matplotlib.use("Agg")
    from jaxswarm.sweep.runner import check_folder
    from jaxswarm.tune import default_tune_out, load_tune_spec, tune

    spec = load_tune_spec(args.file, max_runs=args.max_runs)
    out = args.out if args.out is not None else default_tune_out(spec)
    check_folder(out, "--out")
    print(f"tune {spec.name}: {spec.algorithm} by {spec.method}, {len(spec.space.free)} "
          f"param(s), {spec.budget} training runs on {len(spec.training.pairs)} instance(s), "
          f"objective {spec.objective} -> {out}")
    result = tune(spec, out)
    print(f"{result.runs_spent} training runs; on {len(spec.held_out.pairs)} held-out "
          "instance(s), 95 % intervals over the instances:")
    print(result.held_out.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    return 0


def run_demo(args: argparse.Namespace) -> int:
    """Plan with every exact planner, print the table and write the figure."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot as plt

    from jaxswarm.plot.graph import plot_solutions, plot_swarm_run
    from jaxswarm.plot.memory import memory_view

    name, loaded = _load(args)
    graph, start, goal = loaded.world, loaded.start, loaded.goal
    if args.repeats < 1:
        raise ValueError(f"--repeats must be at least 1, got {args.repeats}")
    height, width = graph.shape
    print(f"map {name}: {width}x{height}, {int(graph.free.sum())} free cells, "
          f"start {start} -> goal {goal}")
    rows, solutions, traces = [], {}, {}
    for label, planner in EXACT_PLANNERS.items():
        runs = [planner(graph, start, goal) for _ in range(args.repeats)]
        solution = solutions[label] = runs[0]
        milliseconds = statistics.median(run.stats.wall_time for run in runs) * 1e3
        rows.append((label, solution.cost, solution.stats.expanded, "-", f"{milliseconds:.2f}"))
    for name_in_registry in args.swarms:
        label = swarm_label(name_in_registry)
        config = {} if args.drops is None else dict(num_agents=args.drops)
        swarm = make(name_in_registry, **config)
        state, trace, milliseconds = _run_swarm(swarm, graph, loaded.task, args)
        solution = solutions[label] = swarm.best(state)
        traces[label] = (swarm, state, trace)
        rows.append((label, solution.cost, "-", int(trace.iterations), f"{milliseconds:.2f}"))
    # Gaps compare every path measured one way (float32, moves counted by kind), never below 0.
    reference = loaded.optimum()
    print(_table(("planner", "length", "gap", "expanded", "iterations", "time [ms]"),
                 [(label, _fmt(cost), _gap(float(path_length(graph, solutions[label].path)),
                                           reference), *rest)
                  for label, cost, *rest in rows]))
    field = float(optimum(graph, as_node(graph, start), as_node(graph, goal)))
    print(f"optimum from the batched JAX distance field (float32): {_fmt(field)}")
    print("(paper): the paper's algorithm as written; (ours): jaxswarm's own algorithm\n"
          "no path: no agent reached the goal within the iterations")
    figure = args.out if args.out is not None else Path("out") / f"demo_{name}.png"
    fig = plot_solutions(graph, solutions, start=start, goal=goal, path=figure,
                         title=f"{name}: exact and swarm planners")
    plt.close(fig)
    print(f"figure written to {figure}")
    for label, (swarm, state, trace) in traces.items():
        out = figure.with_name(f"{figure.stem}_{swarm.name}{figure.suffix}")
        view = memory_view(swarm)
        fig = plot_swarm_run(graph, view.of(state), solutions[label], trace, start=start,
                             goal=goal, optimum=reference, field_label=view.label,
                             title=f"{name}: {label}", path=out)
        plt.close(fig)
        print(f"figure written to {out}")
    return 0


def run_robot(args: argparse.Namespace) -> int:
    """Walk the robot with the swarm and with D* Lite, print the table and write the GIF."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot as plt

    from jaxswarm.plot.robot import animate_robot, plot_robot

    name, loaded = _load(args)
    graph, start, goal = loaded.world, loaded.start, loaded.goal
    for option in ("blocks", "iterations", "max_plans"):
        if getattr(args, option) < 1:
            raise ValueError(f"--{option.replace('_', '-')} must be at least 1, "
                             f"got {getattr(args, option)}")
    hidden = hidden_blocks(graph, start, goal, count=args.blocks, seed=args.seed)
    optimum = check_world(graph, start, goal, hidden, name=name)
    swarm = make(args.swarm[0])
    print(f"map {name}: start {start} -> goal {goal}, {args.blocks} hidden blocks; optimum "
          f"with full knowledge {optimum:.2f}")

    def walk_swarm():
        return jax.block_until_ready(swarm_robot(
            swarm, jax.random.key(args.seed), graph, loaded.task, hidden,
            swarm.default_params, iterations=args.iterations, max_plans=args.max_plans,
            memory=args.memory))

    walk_swarm()  # compile
    began = time.perf_counter()
    walk = walk_swarm()
    seconds = time.perf_counter() - began
    dstar_robot(graph, start, goal, hidden, max_plans=args.max_plans)  # compile the kernels
    exact, exact_seconds = dstar_robot(graph, start, goal, hidden, max_plans=args.max_plans)
    rows = [(f"{swarm_label(swarm.name)}, memory {args.memory}", walk, seconds),
            ("D* Lite (repair)", exact, exact_seconds)]
    print(_table(("planner", "reached", "travelled", "vs optimum", "plans", "time [ms]"),
                 [(label, bool(w.reached), _fmt(w.travelled), _gap(float(w.travelled), optimum),
                   int(w.plans), f"{1e3 * t:.2f}") for label, w, t in rows]))
    figure = args.out if args.out is not None else Path("out") / f"robot_{name}.gif"
    title = f"{name}, {swarm.name}: plan {{plan}}, move {{move}}"
    animate_robot(graph, hidden, walk, figure, start=start, goal=goal, title=title)
    still = figure.with_suffix(".png")
    plt.close(plot_robot(graph, hidden, walk, start=start, goal=goal, path=still,
                         title=f"{name}, {swarm.name}: {float(walk.travelled):.2f}"))
    print(f"figures written to {figure} and {still}")
    return 0


def run_mapf(args: argparse.Namespace) -> int:
    """Load the instance, plan, validate, print the table, write the GIF; 1 when not solved."""
    import matplotlib

    matplotlib.use("Agg")
    from jaxswarm.plot.agents import animate_plan, drawn_agents

    planner = _planner(args)
    if args.agents < 1:
        raise ValueError(f"--agents must be at least 1, got {args.agents}")
    for kind, path in (("MAP", args.map), ("SCEN", args.scen)):
        if not path.is_file():
            raise ValueError(f"{kind} {path}: no such file")
    _check_file_out("--gif", args.gif)
    instance = load_instance(args.map, args.scen, args.agents)
    graph = instance.graph
    height, width = graph.shape
    print(f"map {args.map.stem}: {width}x{height}, {int(graph.free.sum())} free cells, "
          f"{args.agents} agents from {args.scen.name}, planner {args.planner}")
    bound = lower_bound(graph, instance.starts, instance.goals)  # also compiles the hop fields
    planner(graph, instance.starts[:1], instance.goals[:1])  # load the kernels
    began = time.perf_counter()
    plan = planner(graph, instance.starts, instance.goals)
    seconds = time.perf_counter() - began
    violations = (validate(graph, plan.paths, instance.starts, instance.goals, plan.lengths)
                  if plan.solved else [])
    solved = plan.solved and not violations
    cost = plan.sum_of_costs if plan.solved else "-"
    ratio = (f"{plan.sum_of_costs / bound:.3f}" if plan.solved and 0 < bound < UNREACHABLE
             else "-")
    print(_table(("planner", "solved", "sum of costs", "lower bound", "ratio", "makespan",
                  "time [ms]", "violations"),
                 [(plan.planner, plan.solved, cost, bound if bound < UNREACHABLE else "-", ratio,
                   plan.makespan if plan.solved else "-", f"{1e3 * seconds:.1f}",
                   len(violations) if plan.solved else "-")]))
    for violation in violations[:10]:
        print(f"violation: {violation}")
    if not plan.solved:
        print(f"not solved: {plan.reason}")
        return 1
    if not args.no_gif:
        gif = args.gif or Path("out") / f"mapf_{args.map.stem}_{args.planner}.gif"
        frames = animate_plan(graph, plan.paths, gif, title=f"{instance.name}, {plan.planner}: "
                                                            "step {step} of {steps}")
        drawn = drawn_agents(args.agents)
        sample = "" if drawn == args.agents else f"; {drawn} of {args.agents} agents drawn"
        print(f"GIF written to {gif} ({frames} frames{sample})")
    return 0 if solved else 1


MAPF_OPTIONS = {"order": (str, "the priority order"),
                "seed": (int, "the seed of the random order or of the tie-breaks"),
                "time_limit": (float, "give up after this many seconds"),
                "w": (float, "the suboptimality bound"),
                "refine": (float, "lower the sum of costs for this many more seconds after the "
                                  "first solution (LaCAM*'s refinement)")}
"""The planners' options the ``mapf`` command offers: option -> (its type, what it is); each
applies to the registered planners that have it."""


def _owners(option: str) -> list[str]:
    """The registered planners that take ``option``."""
    return [name for name in planners.registered() if option in planners.options(name)]


def _flag(option: str) -> str:
    """The command's argument of a planner's ``option`` (``time_limit``: ``--time-limit``)."""
    return "--" + option.replace("_", "-")


def _planner(args: argparse.Namespace):
    """The chosen planner with its options checked: ``(graph, starts, goals) -> Plan``.

    Raises:
      ValueError: an option of another planner or out of its range, naming the argument.
    """
    given = {option: getattr(args, option) for option in MAPF_OPTIONS
             if getattr(args, option) is not None}
    for option in given:
        if args.planner not in _owners(option):
            raise ValueError(f"{_flag(option)} applies to --planner "
                             f"{' or '.join(_owners(option))}, not {args.planner}")
    try:
        return planners.make_planner(args.planner, **given)
    except OptionError as error:
        raise ValueError(f"{_flag(error.option)} {error.problem}") from None


def _run_swarm(swarm, graph, task, args):
    """Run one swarm planner: compile once, then ``(state, trace, median ms)`` of
    ``args.repeats`` timed runs."""
    key = jax.random.key(args.seed)

    def once():
        return jax.block_until_ready(run(swarm, key, graph, task, swarm.default_params,
                                         iterations=args.iterations, patience=30))

    once()  # compile
    times = []
    for _ in range(args.repeats):
        began = time.perf_counter()
        state, trace = once()
        times.append(time.perf_counter() - began)
    return state, trace, statistics.median(times) * 1e3


def _load(args) -> tuple[str, ResolvedMap]:
    """The label and the resolved map (:func:`jaxswarm.maps.entry.resolve`) of ``demo``'s or
    ``robot``'s ``--map``, ``--seed``, ``--start`` and ``--goal``; ValueError when the start is
    the goal (there is nothing to plan) or ``--out`` names a folder."""
    _check_file_out("--out", args.out)
    entry = named_entry(args.map, seed=args.seed, start=args.start, goal=args.goal)
    loaded = resolve(entry, start=args.start, goal=args.goal)
    if int(loaded.task.start) == int(loaded.task.goal):
        raise ValueError(f"--start {loaded.start} and --goal {loaded.goal} are the same cell: "
                         "there is nothing to plan")
    return named_label(args.map), loaded


def _check_file_out(option: str, path: Path | None) -> None:
    """ValueError when the file ``option`` names to write is a folder (checked before any
    planning, so that no work is lost to a path that cannot be written)."""
    if path is not None and path.is_dir():
        raise ValueError(f"{option} {path} is a folder: name the file to write in it")


def _swarm_names(text: str) -> tuple[str, ...]:
    names = tuple(name.strip() for name in text.split(",") if name.strip())
    graph_swarms = registry.registered(Graph)
    unknown = [name for name in names if name not in graph_swarms]
    if unknown or not names:
        raise argparse.ArgumentTypeError(
            f"unknown swarms {unknown}; registered on graphs: {', '.join(graph_swarms)}"
            if unknown else "name at least one swarm")
    return names


def _point(text: str) -> tuple[int, int]:
    try:
        x, y = (int(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected x,y integers, got {text!r}") from None
    return x, y


def _fmt(value: float) -> str:
    return f"{float(value):.2f}" if value != float("inf") else "no path"


def _gap(cost: float, reference: float) -> str:
    if reference == float("inf") or cost == float("inf"):
        return "-"
    return f"{(float(cost) - reference) / reference:+.2%}"


def _table(header: tuple[str, ...], rows: list[tuple]) -> str:
    cells = [tuple(str(c) for c in header)] + [tuple(str(c) for c in row) for row in rows]
    widths = [max(len(row[i]) for row in cells) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in
                       enumerate(zip(row, widths))) for row in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
