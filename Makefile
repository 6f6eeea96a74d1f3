# Two entry points, both self-contained on a fresh machine: `make demo` and `make test`.
# The virtual environment is created and filled on first use; later runs only check a stamp file.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
export MUJOCO_GL ?= egl

.PHONY: demo test test-fast lint install clean

install: $(STAMP)

# Headless rendering: EGL through Mesa (llvmpipe) on the CPU, OSMesa as the fallback (DESIGN.md).
GL_PACKAGES := libegl1 libegl-mesa0 libgl1-mesa-dri libopengl0 libosmesa6

# torch first and pinned: 2.13.0 resolves to the machine's local CPU build; any other version pulls CUDA.
# robosuite only ships the xArm-7 model files: installed without its dependencies and never imported.
$(STAMP): pyproject.toml Makefile
	@dpkg -s $(GL_PACKAGES) >/dev/null 2>&1 || { \
		echo "installing $(GL_PACKAGES)"; \
		if [ "$$(id -u)" = 0 ]; then apt-get update -qq && apt-get install -y -qq $(GL_PACKAGES) >/dev/null; \
		else sudo apt-get update -qq && sudo apt-get install -y -qq $(GL_PACKAGES) >/dev/null; fi; }
	@command -v chromium >/dev/null 2>&1 || { \
		echo "installing chromium (headless browser for tests/scripts/test_report.py)"; \
		if [ "$$(id -u)" = 0 ]; then apt-get update -qq && apt-get install -y -qq chromium >/dev/null; \
		else sudo apt-get update -qq && sudo apt-get install -y -qq chromium >/dev/null; fi; } \
		|| echo "chromium not installed: the browser test will skip"
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check torch==2.13.0
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e ".[dev,baselines,cluster,rl,viz]"
	$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-deps robosuite==1.5.2
	touch $(STAMP)

# pyright's stubs of mujoco (a pybind11 extension, without any), made from the installed mujoco: a stub-only
# package, mujoco-stubs, in the venv's site-packages.
MUJOCO_STUBS := $(VENV)/mujoco-stubs.stamp

$(MUJOCO_STUBS): $(STAMP)
	cd "$$($(BIN)/python -c 'import sysconfig; print(sysconfig.get_path("purelib"))')" && rm -rf mujoco-stubs \
		&& $(CURDIR)/$(BIN)/python -m pybind11_stubgen mujoco --root-suffix=-stubs --output-dir . >/dev/null 2>&1
	touch $@

# The installed layout for pyright (pyproject.toml [tool.pyright]): puzzlebox.<layer> -> <layer>/, as symlinks.
PYRIGHT_ROOT := build/pyright-root/puzzlebox

$(PYRIGHT_ROOT):
	mkdir -p $@
	ln -sfn ../../../puzzlebox/__init__.py $@/__init__.py
	ln -sfn ../../../puzzlebox/lab $@/lab
	for layer in models twin skills learning real scripts; do ln -sfn ../../../$$layer $@/$$layer; done

lint: $(STAMP) $(MUJOCO_STUBS) $(PYRIGHT_ROOT)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/pyright

test: lint
	$(BIN)/python -m pytest -q -n 2 --dist loadgroup --no-loadscope-reorder  # both cores, the longest work first (tests/_schedule.py)

# The edit-test loop: the unit and physics tests, without lint and without the tests recorded at 1 CPU second or
# more (end-to-end trials, experiments: marked slow by tests/_schedule.py). make test stays the whole suite.
test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 --dist loadgroup --no-loadscope-reorder -m "not slow"

# The main job on the built-in default: the paper's boxes, a memory trained in the symbolic simulator on
# the 9 training boxes (one episode each), then an unseen box solved end to end in the MuJoCo twin
# (perception -> memory agent -> mink primitives -> F/T outcomes): runs/demo/results.json + rollout.mp4.
demo: $(STAMP)
	$(BIN)/python scripts/generate.py paper --split all --out runs/demo/specs --plot
	$(BIN)/python scripts/generate.py validate runs/demo/specs/*.json
	rm -f runs/demo/memory.sqlite runs/demo/memory.sqlite.train.json
	$(BIN)/python scripts/train.py --specs runs/demo/specs/paper-train-*.json --episodes 9 \
		--memory runs/demo/memory.sqlite --seed 0
	$(BIN)/python scripts/trial.py --specs runs/demo/specs/paper-test-0.json --sim twin --agent memory \
		--memory runs/demo/memory.sqlite --runs 1 --seed 0 --max-actions 30 --out runs/demo --video --force
	$(BIN)/python scripts/trial.py --specs runs/demo/specs/paper-test-*.json --sim symbolic --agent dual \
		--runs 10 --seed 0 --max-actions 30 --out runs/demo/symbolic-dual --force

clean:
	rm -rf $(VENV) runs .pytest_cache .ruff_cache
