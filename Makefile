# The two commands a fresh machine needs: `make demo` and `make test`. Both install exactly the
# versions of uv.lock (runtime and dev extras, with hashes) into .venv, with uv, which make
# first installs, pinned by hash, from tools/uv-requirements.txt.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
UVENV  := .uv
UV     := $(UVENV)/bin/uv
STAMP  := $(VENV)/.installed
# The browser tests open report.html in a headless Chromium from the OS packages.
BROWSER := $(VENV)/.chromium
# uv uses the machine's Python (never downloads one) and keeps the project's environment in .venv
export UV_PYTHON_DOWNLOADS := never
export UV_PROJECT_ENVIRONMENT := $(VENV)

.PHONY: demo test bench clean bytecode lock lock-check fresh-check kernels

$(UV): tools/uv-requirements.txt
	$(PYTHON) -m venv $(UVENV)
	$(UVENV)/bin/python -m pip install --quiet --require-hashes --no-deps -r tools/uv-requirements.txt
	touch $(UV)

# --locked: fails, naming the cause, if uv.lock does not match pyproject.toml
$(STAMP): pyproject.toml uv.lock | $(UV)
	$(UV) sync --locked --extra dev --python $(PYTHON)
	@$(MAKE) --no-print-directory kernels
	touch $(STAMP)

# numba's disk cache of the demo study's kernels, filled once after installing (about 55 s of
# CPU on a quiet machine, 110 s before issue 28's session 6; compiled in two processes;
# docs/validation.md "compile time of the demo's kernels"), so that the first `make demo`
# loads them instead of compiling them in every worker; kernels are keyed by their source, so
# after an edit only what changed compiles again
kernels:
	@$(PY) -m pkmlab.study.warm || echo "note: the kernel cache was not warmed; the first run compiles"

# the lock matches pyproject.toml (run by `make test`, so by CI)
lock-check: | $(UV)
	$(UV) lock --check --python $(PYTHON)

# refresh the lock after changing pyproject.toml (or to take new releases: make lock UPGRADE=1)
lock: | $(UV)
	$(UV) lock --python $(PYTHON) $(if $(UPGRADE),--upgrade)

# bytecode for the editable sources, which an environment with PYTHONDONTWRITEBYTECODE set
# would otherwise compile at every start (about 70 ms of each command); compileall rewrites
# only the files changed since, so every command below refreshes it
bytecode: $(STAMP)
	@$(PY) -m compileall -q src

# Chromium for the browser tests: installed with apt-get when root and absent; otherwise the
# browser tests skip, saying why.
$(BROWSER): | $(STAMP)
	@if command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1; then \
		touch $(BROWSER); \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium \
			&& touch $(BROWSER); \
	else \
		echo "note: no Chromium (apt-get install chromium as root): the browser tests will skip"; \
	fi

demo: bytecode
	$(VENV)/bin/pkmlab run studies/hopkins-6psu-redesign.yaml --jobs 2 --overwrite

# the suite runs in TEST_JOBS processes (pytest-xdist), whole files per process so that module
# fixtures are built once; most of a cold run is numba compiling, which is single-threaded
TEST_JOBS ?= 2
test: lock-check bytecode $(BROWSER)
	$(PY) -m pytest -n $(TEST_JOBS) --dist loadfile --durations=25

bench: bytecode
	$(PY) benchmarks/bench_kinematics.py
	$(PY) benchmarks/bench_workspace.py
	$(PY) benchmarks/bench_dexterity.py
	$(PY) benchmarks/bench_study.py

# A fresh clone of HEAD in a temporary folder runs the README's two commands and reports their
# wall times (FRESH_KEEP=1 keeps the folder). The uv cache is the user's, as on a new machine
# that has installed once; FRESH_COLD=1 gives uv an empty cache.
fresh-check:
	@tools/fresh-check

clean:
	rm -rf $(VENV) $(UVENV) results/*/ .pytest_cache
