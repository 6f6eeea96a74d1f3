# Two entry points, both self-contained on a fresh machine: `make demo` and `make test`.
# The virtual environment is created and filled on first use; later runs only check a stamp file.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
export MUJOCO_GL ?= egl

.PHONY: demo test lint install clean

install: $(STAMP)

# torch first and pinned: 2.13.0 resolves to the machine's local CPU build; any other version pulls CUDA.
$(STAMP): pyproject.toml Makefile
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check torch==2.13.0
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e ".[dev,baselines,cluster]"
	touch $(STAMP)

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

test: lint
	$(BIN)/python -m pytest -q

demo: $(STAMP)
	$(BIN)/python scripts/generate.py paper --split all --out runs/demo/specs --plot
	$(BIN)/python scripts/generate.py validate runs/demo/specs/*.json
	$(BIN)/python scripts/trial.py --specs runs/demo/specs/paper-test-*.json --sim symbolic --agent oracle \
		--runs 5 --seed 0 --max-actions 30 --out runs/demo/oracle
	$(BIN)/python scripts/trial.py --specs runs/demo/specs/paper-test-*.json --sim symbolic --agent random \
		--runs 5 --seed 0 --max-actions 30 --out runs/demo/random

clean:
	rm -rf $(VENV) runs .pytest_cache .ruff_cache
