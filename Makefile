# Two commands on a fresh machine: `make demo` and `make test`.
# Both create or reuse .venv and install everything needed, system libraries included. torch is
# pinned to 2.13.0, which these machines serve as a local CPU build (no CUDA packages are pulled).
PYTHON ?= python3
SIM ?= pybullet
# Mesa EGL for headless rendering: MuJoCo, and the PyBullet video (its camera needs no GL)
SYSDEPS := libegl1 libegl-mesa0 libgl1-mesa-dri libgbm1
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test lint format bench docs sysdeps clean

sysdeps:
	@missing=$$(for p in $(SYSDEPS); do dpkg -s $$p >/dev/null 2>&1 || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  if command -v apt-get >/dev/null 2>&1; then \
	    sudo=$$([ "$$(id -u)" -eq 0 ] || echo sudo); \
	    echo "installing $$missing"; \
	    $$sudo apt-get update -qq && $$sudo apt-get install -y -qq $$missing; \
	  else echo "warning: install the Mesa EGL libraries for MuJoCo rendering: $$missing"; fi; \
	fi

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip

$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install -q torch==2.13.0
	$(PY) -m pip install -q -e '.[dev,ray,docs,rerun]'  # ray: sweep tests; docs: mkdocs; rerun: recordings; no CUDA
	touch $(STAMP)

# the embedded 5-block example from camera images: perception, planning and the simulated Panda
# (SIM=mujoco for MuJoCo)
demo: $(STAMP) sysdeps
	$(VENV)/bin/tamp demo --sim $(SIM)  # = tamp run --observe camera --out out/demo

lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

test: lint sysdeps
	$(VENV)/bin/pytest -q

format: $(STAMP)
	$(VENV)/bin/ruff format .
	$(VENV)/bin/ruff check --fix .

# the documentation site from docs/ (mkdocs.yml) into build/docs; --strict: a warning fails
docs: $(STAMP)
	$(VENV)/bin/mkdocs build --strict

bench: $(STAMP)
	$(VENV)/bin/tamp bench planbench --seeds 3 --out results/planbench

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .ruff_cache
