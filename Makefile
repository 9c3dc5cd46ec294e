# Everything runs in a local virtual environment (.venv) created on first use.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
INSTALLED := $(VENV)/.installed
PYTEST := $(BIN)/python -m pytest -p no:cacheprovider -n 2

.PHONY: demo test test-slow bench clean

$(INSTALLED): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(INSTALLED)

demo: $(INSTALLED)  ## plan on a paper map with every planner, print a table, write out/demo.png
	$(BIN)/jaxswarm demo

test: $(INSTALLED)  ## the default test suite (minutes)
	$(PYTEST)

test-slow: $(INSTALLED)  ## the large-scale checks (every Moving AI scenario row, ...)
	$(PYTEST) -m slow

bench: $(INSTALLED)  ## benchmark scripts (print figures; not tests)
	$(BIN)/python benchmarks/exact.py

clean:
	rm -rf $(VENV) out *.egg-info
