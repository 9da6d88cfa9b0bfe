# skgesture: everything installs from nothing (python3 with venv is the only need).
# The pinned CPU build of torch goes in first: an unpinned torch pulls a multi-GB
# CUDA build.

PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
TORCH_SPEC ?= torch==2.13.0
STAMP := $(VENV)/.installed
PYTEST_WORKERS ?= 2

DOCS_STAMP := $(VENV)/.installed-docs
SPHINXOPTS ?= -W --keep-going -q
# make test-min: the declared floors of every dependency (see .ci/floors.py).
VENV_MIN ?= .venv-min
BIN_MIN := $(VENV_MIN)/bin
MIN_STAMP := $(VENV_MIN)/.installed
MIN_EXTRAS ?= tests plot safe dask
LINT_EXTRA := $(wildcard docs/*.py .ci/*.py)

.PHONY: install demo test test-min bench lint docs clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet "$(TORCH_SPEC)"
	$(BIN)/python -m pip install --quiet -e ".[tests,lint,plot,safe]"
	touch $(STAMP)

$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	touch $(DOCS_STAMP)

# The oldest supported versions, in a venv of their own. torch comes first, as in
# .venv: 2.13.0 is the oldest torch with a CPU build here, hence the torch floor.
$(MIN_STAMP): pyproject.toml .ci/floors.py
	rm -rf $(VENV_MIN)
	$(PYTHON) -m venv $(VENV_MIN)
	$(BIN_MIN)/python -m pip install --quiet --upgrade pip
	$(BIN_MIN)/python -m pip install --quiet "$(TORCH_SPEC)"
	$(BIN_MIN)/python .ci/floors.py pyproject.toml $(MIN_EXTRAS) > $(VENV_MIN)/floors.txt
	$(BIN_MIN)/python -m pip install --quiet -c $(VENV_MIN)/floors.txt \
		-e ".[$(shell echo $(MIN_EXTRAS) | tr ' ' ',')]"
	touch $(MIN_STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/python examples/demo.py $(DEMO_ARGS)

test: $(STAMP)
	$(BIN)/python -m pytest -n $(PYTEST_WORKERS) -q tests skgesture

test-min: $(MIN_STAMP)
	$(BIN_MIN)/python -m pip list --format=freeze | grep -i -E \
		"^(numpy|scipy|scikit-learn|joblib|torch|skorch|tqdm)=="
	$(BIN_MIN)/python -m pytest -n $(PYTEST_WORKERS) -q tests skgesture

# HTML into docs/_build/html; sphinx-gallery runs every example (docs/gallery_args.py).
docs: $(DOCS_STAMP)
	$(BIN)/python -m sphinx $(SPHINXOPTS) -b html docs docs/_build/html

# The seglearn peer needs the bench extra; MiniRocket (aeon, the minirocket extra)
# downgrades numpy, so it is left out here and its row is skipped with a note.
bench: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[bench]"
	$(BIN)/python benchmarks/run.py $(BENCH_ARGS)

lint: $(STAMP)
	$(BIN)/ruff check skgesture tests examples benchmarks $(LINT_EXTRA)
	$(BIN)/ruff format --check skgesture tests examples benchmarks $(LINT_EXTRA)
	$(BIN)/flake8 skgesture tests examples benchmarks $(LINT_EXTRA)

clean:
	rm -rf $(VENV) $(VENV_MIN) build dist *.egg-info docs/_build docs/generated \
		docs/auto_examples docs/gen_modules docs/sg_execution_times.rst
