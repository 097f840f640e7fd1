# contactid: the two commands of the README, and the environment they share.
#   make reproduce  - set up, then run the whole workflow
#   make test       - set up, then run the test suite (unit and workflow integration tests)
#   make test-fast  - set up, then run the unit tests alone (not the workflow nor the slow in-process ones)
#   make lint       - ruff format --check, ruff check, snakefmt --check and snakemake --lint (`ruff format .` and
#                     `snakefmt --no-sort Snakefile workflow/rules` rewrite the code in the project's style)
#   make env        - create .venv/ with the pinned packages (and TeX Live via apt where missing), then make warm-up
#   make warm-up    - write the workflow's bytecode and compile numba's kernels ahead of its first run

VENV := .venv
# Python writes the compiled modules (__pycache__) of the package once; a container that sets
# PYTHONDONTWRITEBYTECODE (this one does) would make every job of the workflow, and every project of the tests,
# compile the package's sources again (0.7 s per job)
unexport PYTHONDONTWRITEBYTECODE
# for the same reason pip installs without compiling every module it unpacks (--no-compile): the first import writes
# the compiled modules of what is used, a fraction of them (make env 56 -> 28 s from pip's cache; the first import of
# the workflow's packages 3 -> 10 s, once); the package's editable install builds with the pinned setuptools of
# requirements.txt instead of fetching one into an isolated build environment (8 -> 4 s)
PY := $(VENV)/bin/python
# the interpreter the environment is made from (PYTHON=... overrides): the distribution's /usr/bin/python3 where it is
# the pins' Python (3.11) and can make a venv, else the first python3 on PATH. On this machine Debian's runs pure Python
# 1.5-1.75x as fast as pyenv's (first on PATH; its default build is configured without --enable-optimizations), and
# the workflow ran in 88 s instead of 101 s (CPU 159 s against 189 s) with bit-identical results
PYTHON ?= $(shell for p in /usr/bin/python3 python3; do \
	$$p -c 'import sys, venv, ensurepip; sys.exit(sys.version_info[:2] != (3, 11))' >/dev/null 2>&1 \
	&& { command -v $$p; exit 0; }; done; echo python3)
CORES ?= 2

.PHONY: env warm-up reproduce test test-fast lint slurm-test clean-results tex

env: $(VENV)/.installed tex

$(VENV)/.installed: requirements.txt pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet --no-compile -r requirements.txt
	$(PY) -m pip install --quiet --no-deps --no-build-isolation -e .
	$(MAKE) --no-print-directory warm-up
	touch $@

# what the workflow's first jobs would otherwise compile, each what no job has yet and several at once (the first run
# took 99 s instead of 76-79 s on this machine): the bytecode of the modules it imports (Snakemake's own, planning the
# default target, and every module of the package with what it imports) and numba's kernels (contactid
# compile-kernels, into .snakemake/numba-cache/<code digest>), on two processes (about 20 s). A plan or a config that
# fails is left to the workflow to report.
warm-up:
	@{ $(VENV)/bin/snakemake --dry-run --quiet >/dev/null 2>&1; $(PY) -m contactid compile-kernels --group rig; } & \
	$(PY) -c "import importlib, pkgutil, contactid; \
	[importlib.import_module(m.name) for m in pkgutil.walk_packages(contactid.__path__, 'contactid.')]; \
	import snakemake.script, matplotlib.pyplot, xarray.backends.netCDF4_, netCDF4" \
	&& $(PY) -m contactid compile-kernels --group contact; status=$$?; wait; exit $$status

tex:
	@if ! command -v latexmk >/dev/null 2>&1; then \
	  echo "installing TeX Live and latexmk with apt-get (about a minute)"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi; \
	  $$SUDO apt-get update -qq && $$SUDO apt-get install -y -qq texlive-latex-base texlive-latex-recommended \
	    texlive-latex-extra latexmk >/dev/null || echo "WARNING: TeX Live could not be installed; the report rule will say how"; \
	fi

reproduce: env
	$(VENV)/bin/snakemake --cores $(CORES)

test: env
	$(PY) -m pytest -q

# the unit tests on $(CORES) worker processes (pytest-xdist; they share no state): 35 s instead of 54 s on this machine
test-fast: env
	$(PY) -m pytest -q -n $(CORES) -m "not workflow and not slow"

# the formatter and the linter (pyproject.toml); `make test` checks both too
lint: env
	$(PY) -m ruff format --check .
	$(PY) -m ruff check .
	$(VENV)/bin/snakefmt --no-sort --check Snakefile workflow/rules
	$(VENV)/bin/snakemake --lint
	$(VENV)/bin/lint-imports
	$(VENV)/bin/pydoclint -q workflow/contactid

# optional (not in CI by default): the noise-study sweep through a local single-node SLURM against -c2 here
slurm-test: env
	.ci/slurm/run

clean-results:
	rm -rf results data/raw data/truth data/imported logs benchmarks/rules .snakemake/metadata
