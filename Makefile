# The two commands a fresh machine needs: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
# The browser tests open report.html in a headless Chromium from the OS packages.
BROWSER := $(VENV)/.chromium

.PHONY: demo test bench clean bytecode

$(PY):
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

# bytecode for the editable sources, which an environment with PYTHONDONTWRITEBYTECODE set
# would otherwise compile at every start (about 70 ms of each command); compileall rewrites
# only the files changed since, so every command below refreshes it
bytecode: $(STAMP)
	@$(PY) -m compileall -q src

# Chromium for the browser tests: installed with apt-get when root and absent; otherwise the
# browser tests skip, saying why.
$(BROWSER): | $(PY)
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

test: bytecode $(BROWSER)
	$(PY) -m pytest

bench: bytecode
	$(PY) benchmarks/bench_kinematics.py
	$(PY) benchmarks/bench_workspace.py
	$(PY) benchmarks/bench_dexterity.py
	$(PY) benchmarks/bench_study.py

clean:
	rm -rf $(VENV) results/*/ .pytest_cache
