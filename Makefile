# Everything runs in a local virtual environment (.venv) created on first use.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
INSTALLED := $(VENV)/.installed
# Compiled programs (JAX's and numba's) are kept outside the clone, so a second demo or test
# run, the slow checks after the default ones and the scripts and notebooks the tests start reuse
# them (jaxswarm.runtime.cache); CACHE= (empty) runs without.
CACHE ?= $(HOME)/.cache/jaxswarm
PYTEST := JAXSWARM_CACHE=$(CACHE) $(BIN)/python -m pytest -p no:cacheprovider -n 2 --dist loadscope --durations=25

.PHONY: demo test test-slow docs bench performance reproduce reproduce-quick clean

$(INSTALLED): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(INSTALLED)

demo: $(INSTALLED)  ## plan on mosaic50 with every planner, print a table, write out/demo_mosaic50*.png
	JAXSWARM_CACHE=$(CACHE) $(BIN)/jaxswarm demo

test: $(INSTALLED)  ## the default test suite (minutes)
	$(PYTEST)

test-slow: $(INSTALLED)  ## the large-scale checks (every Moving AI scenario row, ...)
	$(PYTEST) -m slow

docs: $(INSTALLED)  ## the API reference from the docstrings (pdoc) into docs/api/ (open docs/api/index.html)
	$(BIN)/python docs/build_api.py docs/api

bench: $(INSTALLED)  ## benchmark scripts (print figures; not tests)
	$(BIN)/python benchmarks/exact.py

performance: $(INSTALLED)  ## run every benchmark and write docs/performance.md (about 35 min on 2 cores)
	$(BIN)/python benchmarks/report.py

# The generated tables of results/ (see results/README.md), one script each; every script writes its
# Markdown, CSV and provenance.json (commit, versions, machine, command) into its folder, and
# sweeps/index_results.py then indexes them in results/README.md. The full run is the scripts'
# paper-size defaults, spelled out: Table 1, the RFD table, the dynamic Tables 2-5 and IWD on all
# nine paper maps with 20 seeds (100 iterations, 256 drops or ants, 50 water drops); the path maps
# 10x10, 20x20 and 40x25 with 10 runs of populations of 50 ants; the robot study on the three
# path-map sizes and the nine paper maps with 20 seeds; the A* study on 1000 grids per size 10..100;
# the MAPF study on every MAPF map and both scenario files with 10 to 1,000 agents, 3 random
# orders and 30 s a planner and instance; every tune spec of tunes/ raced and judged on its
# held-out instances (the tunes' run stores under out/calibration/stores, resumable), and racing
# against random search, the grid and evolution strategies with 5 tuner seeds on the twins of
# tunes/compare/. Measured (jaxswarm 0.4.0 and later, 2 cores AMD EPYC or Intel Xeon shared with
# other work, load 2-6): Table 1 9.4-12 min, RFD table 5.2 min, path maps 0.7 min, dynamic tables
# 63 min, robot study 13-17 min, IWD 1-5 min, IWD_PG's experiments 7-25 min, the bees' tables 20
# min (load 5-8) and inverse problem 10 min, A* study about 5 min alone, the calibrations from
# their stores under a minute (from scratch: the four of 0.8.0 in 21 min); the MAPF study about
# 3.0 hours of one process (0.9.0: run as six parts, two or three side by side, in 1.5 hours; most
# of it planners at their 30 s limit, and the report's scheme, which has none, on 256 x 256 maps;
# sweeps/mapf_study.py --resume joins parts).
RESULTS := results
QUICK_OUT := out/reproduce-quick
TABLE1_FULL := --maps all --seeds 20 --iterations 100 --agents 256
RFD_FULL := --maps all --seeds 20 --iterations 100 --agents 256
PATHMAPS_FULL := --sizes 10x10,20x20,40x25 --runs 10 --ants 50 --max-ants 5000 --patience 20
EXACT_FULL := --sizes 10:100:5 --grids 1000
DYNAMIC_FULL := --maps all --seeds 20 --iterations 100 --patience 30 --agents 256
ROBOT_FULL := --maps all --seeds 20 --blocks 2 --iterations 100 --patience 30 --max-plans 8
IWD_FULL := --maps all --variants all --seeds 20 --movingai-seeds 6 --drops 50 --iterations 100 \
	--patience 30
IWD_PG_FULL := --experiments 1,2,3,4,5,6,7 --runs-smooth 50 --runs 10 --runs-complex 15 \
	--iterations 50 --drops 50
BEES_FULL := --tables 1,2,3,4,5,6,7 --runs 20 --cycle-runs 30
BEES_INVERSE_FULL := --maps map1,map2 --seeds 30 --grid 6x6x6 --pairs 6
MAPF_FULL := --maps all --scenarios random,even --agents 10,20,50,100,200,400,700,1000 --seeds 3 \
	--time-limit 30
CALIBRATION_FULL := --stores out/calibration/stores --compare-specs tunes/compare/aco_star.toml \
	tunes/compare/iwd.toml tunes/compare/max_min_aco.toml tunes/compare/rfd_star.toml
# The sizes of tests/test_rfd_paper_static.py's and tests/test_rfd_static.py's runs of the same
# scripts: the slow tier compiles their programs once for both (JAX's persistent cache).
TABLE1_QUICK := --maps mosaic20 --seeds 2 --iterations 3 --agents 16
RFD_QUICK := --maps maze20 --seeds 2 --iterations 4 --agents 16
PATHMAPS_QUICK := --sizes 10x10 --runs 2 --max-ants 200
EXACT_QUICK := --sizes 10 --grids 2
DYNAMIC_QUICK := --maps alley20 --tables 2 --seeds 1 --iterations 2 --patience 1 --agents 8
ROBOT_QUICK := --maps pathmap10x10 --seeds 1 --iterations 3 --patience 2 --max-plans 4
IWD_QUICK := --maps maze20 --seeds 2 --iterations 3 --patience 2 --drops 8 --movingai none
IWD_PG_QUICK := --experiments 1 --runs-smooth 1 --iterations 2 --drops 8
BEES_QUICK := --tables 6 --runs 1 --cycle-runs 1
BEES_INVERSE_QUICK := --maps map1 --seeds 1 --grid 2x1x1 --pairs 1
MAPF_QUICK := --maps random-32-32-10 --scenarios random --agents 5 --seeds 1 --time-limit 1
CALIBRATION_QUICK := --specs tunes/quick/iwd.toml tunes/quick/aco_star.toml \
	--stores $(QUICK_OUT)/calibration/stores --compare-specs tunes/quick/aco_star.toml \
	--methods race,grid --tuner-seeds 1

reproduce: $(INSTALLED)  ## regenerate every file of results/ (full size: hours on 2 cores, see above)
	$(BIN)/python sweeps/rfd_paper_static.py $(TABLE1_FULL) --out $(RESULTS)/rfd_paper_table1
	$(BIN)/python sweeps/rfd_static.py $(RFD_FULL) --out $(RESULTS)/rfd_static
	$(BIN)/python sweeps/aco_pathmaps.py $(PATHMAPS_FULL) --out $(RESULTS)/aco_pathmaps
	$(BIN)/python sweeps/rfd_paper_dynamic.py $(DYNAMIC_FULL) --out $(RESULTS)/rfd_paper_dynamic
	$(BIN)/python sweeps/robot_study.py $(ROBOT_FULL) --out $(RESULTS)/robot_study
	$(BIN)/python sweeps/iwd_paper_maps.py $(IWD_FULL) --out $(RESULTS)/iwd_paper_maps
	$(BIN)/python sweeps/iwd_pg_experiments.py $(IWD_PG_FULL) --out $(RESULTS)/iwd_pg_experiments
	$(BIN)/python sweeps/bees_tables.py $(BEES_FULL) --out $(RESULTS)/bees_tables
	$(BIN)/python sweeps/bees_inverse.py $(BEES_INVERSE_FULL) --out $(RESULTS)/bees_inverse
	$(BIN)/python sweeps/exact_study.py $(EXACT_FULL) --out $(RESULTS)/exact_study
	$(BIN)/python sweeps/mapf_study.py $(MAPF_FULL) --out $(RESULTS)/mapf_study
	$(BIN)/python sweeps/calibration.py $(CALIBRATION_FULL) --out $(RESULTS)/calibration
	$(BIN)/python sweeps/index_results.py $(RESULTS)

reproduce-quick: $(INSTALLED)  ## the same at a tiny size into out/reproduce-quick (minutes)
	$(BIN)/python sweeps/rfd_paper_static.py $(TABLE1_QUICK) --out $(QUICK_OUT)/rfd_paper_table1
	$(BIN)/python sweeps/rfd_static.py $(RFD_QUICK) --out $(QUICK_OUT)/rfd_static
	$(BIN)/python sweeps/aco_pathmaps.py $(PATHMAPS_QUICK) --out $(QUICK_OUT)/aco_pathmaps
	$(BIN)/python sweeps/rfd_paper_dynamic.py $(DYNAMIC_QUICK) --out $(QUICK_OUT)/rfd_paper_dynamic
	$(BIN)/python sweeps/robot_study.py $(ROBOT_QUICK) --out $(QUICK_OUT)/robot_study
	$(BIN)/python sweeps/iwd_paper_maps.py $(IWD_QUICK) --out $(QUICK_OUT)/iwd_paper_maps
	$(BIN)/python sweeps/iwd_pg_experiments.py $(IWD_PG_QUICK) --out $(QUICK_OUT)/iwd_pg_experiments
	$(BIN)/python sweeps/bees_tables.py $(BEES_QUICK) --out $(QUICK_OUT)/bees_tables
	$(BIN)/python sweeps/bees_inverse.py $(BEES_INVERSE_QUICK) --out $(QUICK_OUT)/bees_inverse
	$(BIN)/python sweeps/exact_study.py $(EXACT_QUICK) --out $(QUICK_OUT)/exact_study
	$(BIN)/python sweeps/mapf_study.py $(MAPF_QUICK) --out $(QUICK_OUT)/mapf_study
	$(BIN)/python sweeps/calibration.py $(CALIBRATION_QUICK) --out $(QUICK_OUT)/calibration
	$(BIN)/python sweeps/index_results.py $(QUICK_OUT)

clean:
	rm -rf $(VENV) out *.egg-info docs/api .import_linter_cache
