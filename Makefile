# The two commands a fresh machine needs: `make demo` and `make test`.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test bench clean

$(PY):
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/pkmlab run studies/hopkins-6psu-redesign.yaml --jobs 2

test: $(STAMP)
	$(PY) -m pytest

bench: $(STAMP)
	$(PY) benchmarks/bench_kinematics.py
	$(PY) benchmarks/bench_workspace.py
	$(PY) benchmarks/bench_dexterity.py
	$(PY) benchmarks/bench_study.py

clean:
	rm -rf $(VENV) results/*/ .pytest_cache
