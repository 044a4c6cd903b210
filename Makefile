# Two commands set up and run everything: `make demo` and `make test`.
# Both create (or refresh) the repo-local environment .venv/ first.
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.rkfx-installed
DEMO   ?= mandel

.PHONY: demo test test-slow test-mpi bench env clean

demo: $(STAMP)
	$(PY) -m rkfx.cases.$(DEMO)

test: $(STAMP)
	$(PY) -m pytest -m "not slow"

# Longer verification studies (convergence on finer node sets, MPI runs).
test-slow: $(STAMP)
	$(PY) -m pytest -m slow

bench: $(STAMP)
	$(PY) bench/core_build.py

env: $(STAMP)

$(STAMP): pyproject.toml tools/find-python
	@test -x $(PY) || { base=$$(tools/find-python) && "$$base" -m venv $(VENV); }
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[all]"
	@touch $(STAMP)

clean:
	rm -rf $(VENV) results .pytest_cache
