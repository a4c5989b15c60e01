# curvefair - the two commands a new user needs:  make demo  /  make test
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(VENV)/bin/pip
# test processes (pytest-xdist): one per core this process may use; `make test JOBS=1` runs in one
JOBS   ?= $(shell nproc 2>/dev/null || echo 1)

.PHONY: demo test docs lint bench bench-quality clean venv venv-test

$(VENV)/.stamp-base: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PIP) install --upgrade --quiet pip
	$(PIP) install --quiet -e .
	touch $@

$(VENV)/.stamp-test: pyproject.toml $(VENV)/.stamp-base
	$(PIP) install --quiet -e ".[test]"
	touch $@

$(VENV)/.stamp-bench: pyproject.toml $(VENV)/.stamp-test
	$(PIP) install --quiet -e ".[bench]"
	touch $@

venv: $(VENV)/.stamp-base

venv-test: $(VENV)/.stamp-test

## demo: fair the bundled example curve, print a before/after summary, write demo_out/report.json
demo: $(VENV)/.stamp-base
	$(PY) examples/demo.py --out demo_out/report.json

## test: the whole test suite, spread over $(JOBS) processes
test: $(VENV)/.stamp-test
	$(PY) -m pytest -q -n $(JOBS) --dist worksteal

## docs: the HTML documentation in docs/_build/html (API reference, formats, benchmarks, the
## gallery of examples/plot_*.py run at build time); any Sphinx warning is an error
docs: $(VENV)/.stamp-test
	$(PY) -m sphinx -W --keep-going -q -b html docs docs/_build/html

## lint: ruff over src and tests, mypy over the package (settings in pyproject.toml)
lint: $(VENV)/.stamp-test
	$(VENV)/bin/ruff check src tests
	$(PY) -m mypy src/curvefair

## bench: speed benchmarks (figures quoted in README.md); sizes as a parameter:
##   make bench SIZES=1e3,1e6   (ONLY=bench_call_cost to run some scripts only)
bench: $(VENV)/.stamp-bench
	$(PY) benchmarks/run_all.py $(if $(SIZES),--sizes $(SIZES)) $(if $(ONLY),--only $(ONLY))

## bench-quality: fairing quality benchmark (all methods and peers); regenerates docs/benchmarks.md
bench-quality: $(VENV)/.stamp-bench
	$(PY) benchmarks/quality/run.py

clean:
	rm -rf $(VENV) demo_out .pytest_cache .hypothesis docs/_build docs/auto_examples
