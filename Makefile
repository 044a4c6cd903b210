# Two commands set up and run everything: `make demo` and `make test`.
# Both create (or refresh) the repo-local environment .venv/ first.
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.rkfx-installed
DEMO   ?= mandel

.PHONY: demo test test-slow test-mpi bench labs report env clean

demo: $(STAMP)
	$(PY) -m rkfx.cases.$(DEMO)

test: $(STAMP)
	$(PY) -m pytest -m "not slow"

# Longer verification studies (convergence on finer node sets, MPI runs).
test-slow: $(STAMP)
	$(PY) -m pytest -m slow

bench: $(STAMP)
	$(PY) bench/core_build.py

# The teaching labs (docs/labs/*.py, jupytext percent scripts) as notebooks in build/labs/.
# The notebooks are generated, never committed; the .py files are the source.
LABS := $(wildcard docs/labs/*.py)
labs: $(STAMP)
	@mkdir -p build/labs
	@for lab in $(LABS); do \
	  $(PY) -m jupytext --to ipynb --output build/labs/$$(basename $$lab .py).ipynb $$lab || exit 1; \
	done
	@echo "notebooks in build/labs/ (open with: jupyter lab build/labs)"

# Every case at its --quick sizes, the seed's claims checked, one page: results/report/index.html.
report: $(STAMP)
	$(PY) -m rkfx.report --quick --out results/report

env: $(STAMP)

# The last step puts tools/rkfx-mpi.pth and its module into site-packages, so that plain
# `import dolfinx` finds the mpich wheel's libmpi (why and how: tools/rkfx_mpi_first.py).
$(STAMP): pyproject.toml tools/find-python tools/rkfx-mpi.pth tools/rkfx_mpi_first.py
	@test -x $(PY) || { base=$$(tools/find-python) && "$$base" -m venv $(VENV); }
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[all]"
	site=$$($(PY) -c 'import sysconfig; print(sysconfig.get_path("purelib"))') && \
	  cp tools/rkfx-mpi.pth "$$site/rkfx-mpi.pth" && \
	  cp tools/rkfx_mpi_first.py "$$site/_rkfx_mpi_first.py" && \
	  $(PY) -m compileall -q "$$site/_rkfx_mpi_first.py"
	@touch $(STAMP)

clean:
	rm -rf $(VENV) results .pytest_cache build lab_output
