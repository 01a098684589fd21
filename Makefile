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
	$(BIN)/python -m pip install -q -e '.[fem,test,docs]'
	@touch $(STAMP)

demo: $(STAMP)
	$(BIN)/mpiexec -n $(NP) $(BIN)/multiscale run demos/pin_on_disc.toml --overwrite

test: docs test-serial test-mpi

# The user guide (docs/_build/html): any warning, a broken cross-reference among them, fails it.
docs: $(STAMP)
	$(BIN)/python -m sphinx -b html -E -W --keep-going -n -q docs docs/_build/html

# one pytest process per test module: a model not closed (the tests build most through the API and
# keep them open) stays in memory with ~35-100 MPI communicators of MPICH's 2048 per process, and
# the whole suite in one process ended with exit code 15, MPICH's abort for "Too many
# communicators" (203515151 & 0xff; docs/architecture.md §7)
test-serial: $(STAMP)
	@failed=""; for f in tests/test_*.py; do \
	  $(BIN)/python -m pytest -q -p no:cacheprovider $$f || failed="$$failed $$f"; done; \
	  if [ -n "$$failed" ]; then echo "failed:$$failed"; exit 1; fi

test-mpi: $(STAMP)
	@if ls tests/mpi/test_*.py >/dev/null 2>&1; then \
	  $(BIN)/mpiexec -n $(NP) $(BIN)/python -m pytest -q -p no:cacheprovider tests/mpi --override-ini addopts= ; fi

$(BENCH_STAMP): $(STAMP)
	$(BIN)/python -m pip install -q -e '.[fem,test,bench]'
	@touch $(BENCH_STAMP)

bench: $(BENCH_STAMP)
	$(BIN)/python benchmarks/run_all.py

# Accuracy-vs-time report of the micro models (docs/accuracy); finished runs are reused
# (studies/accuracy/results/): delete that folder to recompute everything.
report: $(STAMP)
	$(BIN)/multiscale study studies/accuracy/*.toml --report docs/accuracy

clean:
	rm -rf $(VENV) .pytest_cache build *.egg-info docs/_build
