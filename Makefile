# The two quick-start commands of README.md, on a fresh machine:
#   make demo   installs curvenet in .venv and surfaces the bundled box sketch (box.obj, box.png)
#   make test   installs the test extras in the same .venv and runs the test suite
# PYTHON=python3.12 make test picks another interpreter for the venv.

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
PIP    := $(BIN)/python -m pip install -q

.PHONY: demo test

demo: $(VENV)/.installed
	$(BIN)/curvenet surface examples/data/box_sketch.obj -o box.obj --preview box.png --explain

test: $(VENV)/.installed-test
	$(BIN)/python -m pytest -q

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

# torch==2.13.0 first: its CPU build lies on disk, while an open version range with no
# torch installed pulls a multi-GB CUDA build. The stamps redo an install only when
# pyproject.toml changes.
$(VENV)/.torch: | $(BIN)/python
	$(PIP) torch==2.13.0
	touch $@

$(VENV)/.installed: pyproject.toml $(VENV)/.torch
	$(PIP) -e .
	touch $@

# [cluster] (dask.distributed, pure Python) runs the LocalCluster batch test; [cad]
# (cadquery-ocp with vtk, ~1.1 GB) is left out: tests/curvenet/test_cad.py skips without it.
$(VENV)/.installed-test: pyproject.toml $(VENV)/.torch
	$(PIP) -e '.[test,cluster]'
	touch $@
