# Quick start: `make demo` and `make test` work on a fresh machine with only
# Python >= 3.11 and make: the virtual environment is created when missing.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test bench examples clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/substructure demo --out out/demo --overwrite

test: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q

bench: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python benchmarks/run.py

examples: $(STAMP)
	for f in examples/[0-9]*.py; do MPLBACKEND=Agg SUBSTRUCTURE_EXAMPLES_OUT=out/examples $(BIN)/python $$f || exit 1; done

clean:
	rm -rf $(VENV) out .pytest_cache
