# Two commands set everything up on a fresh machine: `make demo` and `make test` (which also builds
# the user guide, `make docs`). Each bootstraps .venv (Python >= 3.12) only when pyproject.toml changed.
SHELL := /bin/bash
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
BENCH_STAMP := $(VENV)/.installed-bench
NP ?= 2
export UCX_TLS ?= self,sm,tcp
export OMP_NUM_THREADS ?= 1
export MPLBACKEND ?= Agg
# pip installs without compiling every installed module to bytecode (--no-compile): that took 43 of
# the install's 77 s on a fresh machine (warm download cache); Python compiles and caches the modules
# a process imports when it first imports them (the suite's first imports: ~10 s more, once).
# Python caches the package's bytecode (__pycache__, ignored by git) even where the environment
# says not to: the suite starts an interpreter per test module, more for the CLI and MPI tests, and
# a process per package module in test_architecture (its imports took 88 s without the cache, 53-60 s
# with it, when each was an interpreter of its own).
unexport PYTHONDONTWRITEBYTECODE

# First interpreter >= 3.12 found: PYTHON=..., then the pyenv-selected `python` (.python-version), then pythonX.Y.
PYTHON ?= $(shell for p in python python3 python3.12 python3.13 python3.14; do \
	  if command -v $$p >/dev/null 2>&1 && $$p -c 'import sys; sys.exit(sys.version_info < (3, 12))' 2>/dev/null; then \
	    command -v $$p; break; fi; done)

.PHONY: venv demo test test-serial test-mpi docs bench report clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	@test -n "$(PYTHON)" || { echo "error: no Python >= 3.12 found (pyenv install 3.12, or make PYTHON=/path/to/python3.12)"; exit 1; }
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q --no-compile -e '.[fem,test,docs]'
	@touch $(STAMP)

demo: $(STAMP) demos/cad/car_brake.step
	$(BIN)/mpiexec -n $(NP) $(BIN)/multiscale run demos/pin_on_disc.toml --overwrite

# The user guide is built as one more job beside the test modules (WITH=docs), then tests/mpi runs.
# The tests' DOLFINx forms are compiled at -O1 (tests/config/dolfinx/dolfinx_jit_options.json; the
# default is -O2): gcc took 0.29 s a form instead of 0.39 s, for the ~380 forms a fresh cache
# compiles; the same IEEE operations (no fast-math; baseline x86-64 has no FMA to contract into).
test test-serial test-mpi: export XDG_CONFIG_HOME := $(CURDIR)/tests/config
test: $(STAMP)
	@$(MAKE) --no-print-directory test-serial WITH=docs
	@$(MAKE) --no-print-directory test-mpi

# The user guide (docs/_build/html): any warning, a broken cross-reference among them, fails it.
docs: $(STAMP)
	$(BIN)/python -m sphinx -b html -E -W --keep-going -n -q docs docs/_build/html

# The long test modules run one pytest process each, the slowest first, JOBS at a time, each
# module's output printed whole when it ends (-O); every module runs (-k), and the failed ones are
# named at the end. The ~45 quick modules (seconds each) share one process, started first: their
# interpreter and imports (~3.4 s a module) took 451 s one by one, 303 s in one process. A shared
# process must not run out of MPI communicators (MPICH's 2048; a model not closed keeps ~35-100):
# the tests' conftest closes every model a module leaves open (docs/architecture.md, "Runs and
# processes").
# WITH: more targets beside.
JOBS ?= 2
ALONE := duty_cycle squeal_effects killed_run coupling macro_thermal faults studies geometry_files architecture \
	macro_run outputs mesh_size
ALONE_TESTS := $(ALONE:%=tests/test_%.py)
QUICK_TESTS := $(filter-out $(ALONE_TESTS),$(sort $(wildcard tests/test_*.py)))
ALONE_RUNS := $(ALONE_TESTS:tests/%.py=run-%)
.PHONY: run-quick $(ALONE_RUNS)

test-serial: $(STAMP) demos/cad/car_brake.step
	@rm -f .test-failed; $(MAKE) --no-print-directory -k -j$(JOBS) -O $(WITH) run-quick $(ALONE_RUNS); status=$$?; \
	  if [ -s .test-failed ]; then echo "failed:$$(tr -d '\n' < .test-failed)"; fi; rm -f .test-failed; exit $$status

run-quick:
	@echo "tests/: $(words $(QUICK_TESTS)) quick modules in one process"; \
	  $(BIN)/python -m pytest -q -p no:cacheprovider $(QUICK_TESTS) || { echo " (quick modules)" >> .test-failed; exit 1; }

$(ALONE_RUNS): run-%:
	@echo "tests/$*.py"; $(BIN)/python -m pytest -q -p no:cacheprovider tests/$*.py || { echo " tests/$*.py" >> .test-failed; exit 1; }

# The CAD demos' STEP files (demos/cad_models.py writes both): the tests load every demo scene.
demos/cad/car_brake.step: demos/cad_models.py $(STAMP)
	$(BIN)/python demos/cad_models.py

test-mpi: $(STAMP)
	@if ls tests/mpi/test_*.py >/dev/null 2>&1; then \
	  $(BIN)/mpiexec -n $(NP) $(BIN)/python -m pytest -q -p no:cacheprovider tests/mpi --override-ini addopts= ; fi

$(BENCH_STAMP): $(STAMP)
	$(BIN)/python -m pip install -q --no-compile -e '.[fem,test,bench]'
	@touch $(BENCH_STAMP)

bench: $(BENCH_STAMP)
	$(BIN)/python benchmarks/run_all.py

# Accuracy-vs-time report of the micro models (docs/accuracy); finished runs are reused
# (studies/accuracy/results/): delete that folder to recompute everything.
report: $(STAMP)
	$(BIN)/multiscale study studies/accuracy/*.toml --report docs/accuracy

clean:
	rm -rf $(VENV) .pytest_cache build *.egg-info docs/_build demos/cad .test-failed
