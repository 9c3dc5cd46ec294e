"""Run the notebooks in ``notebooks/`` top to bottom at small sizes and check what they produce.

Each notebook runs in a fresh Jupyter kernel through ``nbclient`` with
``JAXSWARM_NOTEBOOK_SMALL=1``, so it uses fewer seeds, iterations and agents. Its output directory
(``JAXSWARM_NOTEBOOK_OUT``) is pytest's ``tmp_path``. A cell that raises makes ``nbclient`` raise
``CellExecutionError``, which fails the test and shows the cell and its traceback.
The notebooks also check their own results with ``assert``. After a run, the test checks:

* quickstart: the JSON line printed by the cell tagged ``checks``. The three exact planners report
  one finite optimum, no swarm beats it, and a repeated key reproduces its run. Its figures were
  shown inline. Its small sizes are the suite's shared size (``tests/sizes.py``), so its runs
  alone are programs the default tier compiled (JAX's persistent cache, when it ran first).
* dynamic: the JSON line of its ``checks`` cell (three swarms continued after the goal moved, none
  beating the new optimum) and the GIF it wrote under ``tmp_path``.
* tuning: the JSON line of its ``checks`` cell (a race and a random search within their budget,
  each rescored on the held-out map), the race's figure shown inline and its files under
  ``tmp_path``.
* many_agents: the JSON line of its ``checks`` cell (the eight multi-agent planners solve, their
  solutions validate, none beats the lower bound or CBS; LaCAM plans 200 agents), the GIFs it
  wrote under ``tmp_path`` (the crowd's drawing a sample of 100 agents) and the logs of the A*
  report's two examples.
* sweep_analysis: the Parquet store under ``tmp_path``. Read back with pandas, it holds
  maps x combinations x seeds rows, one per run, taken from the spec in ``metadata.json``. No gap
  is below -1e-6. The PNGs of ``plot_sweep`` exist. The figures were shown inline, which
  confirms the notebook's ``%matplotlib inline`` after the import of ``jaxswarm.plot.sweep``;
  that module selects Agg at import.

Which Python runs the kernel: the notebooks must run in the interpreter that runs pytest (the
project's ``.venv``, where jaxswarm is installed). The kernel name ``python3`` would also match a
kernelspec in the user's ``~/.local/share/jupyter`` or the system's ``/usr/share/jupyter``, and
such a spec may point at another Python. So the test writes its own ``python3`` kernelspec, whose
argv starts with ``sys.executable``, into a temporary directory. It then puts that directory on
``JUPYTER_PATH``. jupyter_client searches ``JUPYTER_PATH`` before any other place, and the
variable only lives for the test (monkeypatch). Nothing is installed, and no user or venv files
change. Before a notebook's own cells, the test runs one extra cell, added to the in-memory copy
only. It prints the kernel's ``sys.prefix``, and the test checks that this equals pytest's.

Run time on 2 CPU cores, mostly JAX compiling: from 15 s to two minutes a notebook, so every run
is a slow check; the default tier parses every cell and imports what each imports. Each cell may
take up to ``CELL_TIMEOUT`` seconds.
"""
from __future__ import annotations

import importlib
import json
import math
import os
import sys
from pathlib import Path

import pytest
from repo_scripts import import_what_it_imports



def _extra(module: str):
    """The test extra's ``module``: skipped without it, except in CI, where it must be there."""
    if os.environ.get("CI"):
        return importlib.import_module(module)
    return pytest.importorskip(module)


nbformat = _extra("nbformat")
nbclient = _extra("nbclient")
_extra("ipykernel")
pd = _extra("pandas")

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
CELL_TIMEOUT = 300
SIZE_VARIABLES = ("JAXSWARM_NOTEBOOK_MAP", "JAXSWARM_NOTEBOOK_AGENTS",
                  "JAXSWARM_NOTEBOOK_ITERATIONS", "JAXSWARM_NOTEBOOK_SEEDS")
PROBE = "import sys\nprint(sys.prefix)"


@pytest.fixture
def notebook_env(tmp_path, monkeypatch):
    """Small sizes, output under tmp_path, and a python3 kernelspec pinned to sys.executable."""
    spec_dir = tmp_path / "jupyter" / "kernels" / "python3"
    spec_dir.mkdir(parents=True)
    (spec_dir / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "Python 3 (jaxswarm test)", "language": "python"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    monkeypatch.setenv("JAXSWARM_NOTEBOOK_SMALL", "1")
    out = tmp_path / "out"
    monkeypatch.setenv("JAXSWARM_NOTEBOOK_OUT", str(out))
    for name in SIZE_VARIABLES:  # the small defaults, whatever the caller's shell has set
        monkeypatch.delenv(name, raising=False)
    return out


def execute(name: str):
    """Run notebook ``name`` in a fresh kernel (cwd: the repo root); return the executed copy."""
    nb = nbformat.read(NOTEBOOKS / name, as_version=4)
    nb.cells.insert(0, nbformat.v4.new_code_cell(PROBE))
    client = nbclient.NotebookClient(nb, timeout=CELL_TIMEOUT, kernel_name="python3",
                                     resources={"metadata": {"path": str(ROOT)}})
    client.execute()  # CellExecutionError if any cell raises
    kernel_prefix = stdout(nb.cells[0]).strip()
    assert Path(kernel_prefix).resolve() == Path(sys.prefix).resolve(), (
        f"the kernel ran in {kernel_prefix}, not in pytest's interpreter {sys.prefix}")
    return nb


def stdout(cell) -> str:
    return "".join(o.get("text", "") for o in cell.get("outputs", [])
                   if o.output_type == "stream" and o.name == "stdout")


def count_images(nb) -> int:
    return sum("image/png" in o.get("data", {}) for cell in nb.cells if cell.cell_type == "code"
               for o in cell.get("outputs", []))


def test_notebooks_are_stored_without_outputs():
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        nbformat.validate(nb)
        for cell in nb.cells:
            if cell.cell_type == "code":
                assert not cell.outputs and cell.execution_count is None, (
                    f"{path.name}: clear the outputs before committing")


@pytest.mark.slow  # about 50 s of compiles
def test_quickstart(notebook_env):
    nb = execute("quickstart.ipynb")
    checks = [cell for cell in nb.cells if "checks" in cell.metadata.get("tags", [])]
    assert len(checks) == 1
    result = json.loads(stdout(checks[0]).strip().splitlines()[-1])

    exact = result["exact"]
    assert set(exact) == {"Dijkstra", "A*", "bidirectional A*"}
    optimum = exact["Dijkstra"]
    assert math.isfinite(optimum) and optimum > 0
    for name, cost in exact.items():
        assert cost == pytest.approx(optimum, rel=1e-9), f"{name} disagrees with Dijkstra"
    assert len(result["swarms"]) == 4
    for name, cost in result["swarms"].items():
        assert cost >= optimum * (1 - 1e-5), f"{name} beats the optimum"
    assert result["reproducible"] is True
    assert count_images(nb) >= 6


@pytest.mark.slow  # a sweep's compile, about 25 s
def test_sweep_analysis(notebook_env):
    nb = execute("sweep_analysis.ipynb")
    store = notebook_env / "sweep_analysis"
    spec = json.loads((store / "metadata.json").read_text())["spec"]
    assert spec["seeds"] == [0, 1] and spec["iterations"] == 15, "JAXSWARM_NOTEBOOK_SMALL ignored"

    frame = pd.read_parquet(store / "runs")
    combinations = math.prod(len(values) for values in spec["params"].values())
    assert len(frame) == len(spec["maps"]) * combinations * len(spec["seeds"])
    assert not frame.duplicated(["map", "run"]).any()
    assert set(frame["map"]) == set(spec["maps"])
    assert set(frame["seed"]) == set(spec["seeds"])
    for name, values in spec["params"].items():
        assert sorted(set(frame[name])) == sorted(values)
    assert frame["found"].any()
    # Relative gaps to the float32 optimum; a run without a path has cost and gap inf.
    assert (frame["gap"] >= -1e-6).all(), frame.loc[~(frame["gap"] >= -1e-6), ["map", "run", "gap"]]
    assert (frame.loc[~frame["found"], "success"] == False).all()  # noqa: E712

    for png in ("heatmap_success_alpha_vs_p_base.png", "heatmap_gap_alpha_vs_p_base.png",
                "line_p_base.png", "line_alpha.png"):
        path = store / png
        assert path.is_file(), f"missing {path}"
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert count_images(nb) >= 6  # heat maps, lines, the PNG shown, and one replay per map


@pytest.mark.slow  # about a minute of compiles
def test_dynamic(notebook_env):
    nb = execute("dynamic.ipynb")
    checks = [cell for cell in nb.cells if "checks" in cell.metadata.get("tags", [])]
    assert len(checks) == 1
    result = json.loads(stdout(checks[0]).strip().splitlines()[-1])
    assert set(result["swarms"]) == {"rfd_star", "rfd_graded", "aco_star"}
    gif = Path(result["gif"])
    assert gif.parent == notebook_env and gif.stat().st_size > 0
    assert gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a") and result["frames"] == 16
    assert set(result["robot"]) == {"keep", "wipe", "D* Lite"}
    assert all(walk["reached"] and walk["plans"] >= 2 for walk in result["robot"].values())
    robot_gif = Path(result["robot_gif"])
    assert robot_gif.parent == notebook_env and robot_gif.read_bytes()[:3] == b"GIF"
    assert count_images(nb) >= 2


@pytest.mark.slow  # IWD_PG compiles its local searches: about two minutes
def test_water_drops(notebook_env):
    nb = execute("water_drops.ipynb")
    checks = [cell for cell in nb.cells if "checks" in cell.metadata.get("tags", [])]
    assert len(checks) == 1
    result = json.loads(stdout(checks[0]).strip().splitlines()[-1])
    assert math.isfinite(result["optimum"])
    assert result["iwd_pg"] >= result["optimum"] * (1 - 1e-5)
    assert result["smoothed_not_longer"] and result["scores_in_range"]
    assert set(result["finals"]) == {"IWD_PG", "smoothing alone"}
    assert count_images(nb) >= 4


@pytest.mark.slow  # compiles the vehicle's run and the inverse problem's scorer: about a minute
def test_bees(notebook_env):
    nb = execute("bees.ipynb")
    checks = [cell for cell in nb.cells if "checks" in cell.metadata.get("tags", [])]
    assert len(checks) == 1
    result = json.loads(stdout(checks[0]).strip().splitlines()[-1])
    assert result["inside"] == 0 and math.isfinite(result["optimum"])
    assert result["search_runs"] <= result["grid_runs"]  # optax within the grid's budget
    assert result["grid_best"] > 0 and result["search_best"] > 0
    assert count_images(nb) >= 2


@pytest.mark.parametrize("path", sorted(NOTEBOOKS.glob("*.ipynb")), ids=lambda path: path.name)
def test_every_notebook_cell_parses_and_its_imports_resolve(path):
    """The default tier's twin of the notebook runs (slow tier): a cell that no longer parses or
    imports a name that moved fails here without a kernel."""
    nb = nbformat.read(path, as_version=4)
    for index, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        code = "\n".join(line for line in cell.source.splitlines()
                         if not line.lstrip().startswith(("%", "!")))  # IPython's own lines
        import_what_it_imports(code, f"{path.name} cell {index}")


@pytest.mark.slow  # the multi-agent planners' and the crowd's programs, about 20 s warm
def test_many_agents(notebook_env):
    from PIL import Image

    nb = execute("many_agents.ipynb")
    checks = [cell for cell in nb.cells if "checks" in cell.metadata.get("tags", [])]
    assert len(checks) == 1
    result = json.loads(stdout(checks[0]).strip().splitlines()[-1])
    assert result["agents"] == 20, "JAXSWARM_NOTEBOOK_SMALL ignored"
    planners = result["planners"]
    assert set(planners) == {"report", "prioritized", "cbs", "icbs", "cbsh", "cbsh_tc",
                             "cbsh_rtc", "ecbs", "eecbs", "pibt", "lacam", "lacam_star"}
    bound = result["lower_bound"]
    for name, plan in planners.items():
        assert plan["solved"], f"{name}: {plan['reason']}"
        assert plan["violations"] == 0 and plan["sum_of_costs"] >= bound, name
        assert planners["cbs"]["sum_of_costs"] <= plan["sum_of_costs"], f"{name} beats CBS"
    gif = Path(result["gif"])
    assert gif.parent == notebook_env
    with Image.open(gif) as image:
        assert image.format == "GIF" and image.n_frames == result["frames"]
    animated = planners[result["animated"]]  # the plan of least sum of costs, a frame a step
    assert animated["sum_of_costs"] == planners["cbs"]["sum_of_costs"]
    assert result["frames"] >= animated["makespan"] + 1
    crowd = result["crowd"]
    assert crowd["agents"] == 200 and crowd["solved"]
    assert crowd["sum_of_costs"] >= crowd["lower_bound"]
    with Image.open(crowd["gif"]) as image:
        assert image.n_frames == crowd["frames"]
    examples = result["examples"]
    assert "no collision found" in examples["map1"]["log"]
    assert "can not synchronize, robot 2 move first" in examples["map2"]["log"]
    for example in examples.values():
        assert example["cbs"] <= example["report"]
    assert count_images(nb) >= 2


@pytest.mark.slow  # two tunes of IWD on 20 x 20 maps: one compile, about 30 s
def test_tuning(notebook_env):
    nb = execute("tuning.ipynb")
    checks = [cell for cell in nb.cells if "checks" in cell.metadata.get("tags", [])]
    assert len(checks) == 1
    result = json.loads(stdout(checks[0]).strip().splitlines()[-1])
    assert 0 < result["race_runs"] <= 72 and 0 < result["random_runs"] <= 72  # the small budget
    assert result["races"] >= 1 and len(result["held_out"]) >= 2
    out = Path(result["out"])
    assert out.parent.parent == notebook_env
    for name in ("race.csv", "race.png", "held_out.csv", "best.json"):
        assert (out / name).is_file()
    assert count_images(nb) >= 1
