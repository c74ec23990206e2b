# Quick start: `make demo` and `make test` work on a fresh machine with only
# Python >= 3.11, make and a C compiler (the kernels are compiled when the
# package is installed): the virtual environment is created when missing.
# After installing, `python -m substructure._prepare` checks the compiled
# kernels, builds the unit registry's cache and compiles the modules, so that
# the first run is as fast as the next ones (docs/performance.md).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
DOCS_STAMP := $(VENV)/.installed-docs
NOTEBOOKS_STAMP := $(VENV)/.installed-notebooks
LINT_STAMP := $(VENV)/.installed-lint

.PHONY: demo test lint bench examples docs notebooks clean report-check

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): $(BIN)/python pyproject.toml setup.py substructure/_ckernels.c
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	$(BIN)/python -m substructure._prepare
	touch $(STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/substructure demo --out out/demo --overwrite

test: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -n 2 --dist loadfile

# The static checks, run by CI before the tests: ruff (pycodestyle and pyflakes rules), the import
# contracts of the layers (lint-imports; docs/architecture.md, "What CI enforces") and mypy on the
# core layers. Configured in pyproject.toml; the tools are the `lint` extra.
$(LINT_STAMP): $(STAMP) pyproject.toml
	$(BIN)/python -m pip install --quiet -e ".[test,lint]"
	touch $(LINT_STAMP)

lint: $(LINT_STAMP)
	$(BIN)/ruff check .
	$(BIN)/lint-imports
	$(BIN)/mypy

# The report in a real browser: headless chromium renders `substructure report`'s page offline and
# the check finds every figure on the screenshot (docs/report.md). Skipped, with the reason, where
# chromium is not installed; install it with `apt-get install -y chromium` (Debian, Ubuntu).
# The screenshots stay in out/report-check for a person to look at.
report-check: $(STAMP)
	SUBSTRUCTURE_REPORT_CHECK_OUT=out/report-check MPLBACKEND=Agg $(BIN)/python -m pytest -q -rs tests/test_report_browser.py
	@echo "report-check: screenshots in out/report-check (report.png, bare.png)"

bench: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python benchmarks/run.py

examples: $(STAMP)
	for f in examples/[0-9]*.py; do MPLBACKEND=Agg SUBSTRUCTURE_EXAMPLES_OUT=out/examples $(BIN)/python $$f || exit 1; done

# The documentation site: HTML in docs/_build/html (open docs/_build/html/index.html).
# Warnings are errors: an unresolved reference or link, a docstring the numpydoc check
# rejects, or an example that fails, prints nothing or draws nothing fails the build.
# The examples run here (and only here in CI); see docs/writing-docs.md.
$(DOCS_STAMP): $(STAMP) pyproject.toml
	$(BIN)/python -m pip install --quiet -e ".[test,docs]"
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	MPLBACKEND=Agg $(BIN)/python -m sphinx -b html -W --keep-going docs docs/_build/html
	@echo "docs: open docs/_build/html/index.html"

# The examples as Jupyter notebooks (the ones the site offers), each executed on a Python kernel
# in out/notebooks/NN_name/ and checked to show its figures inline; see docs/teaching.md.
# Open them with `.venv/bin/jupyter lab out/notebooks`.
$(NOTEBOOKS_STAMP): $(STAMP) pyproject.toml
	$(BIN)/python -m pip install --quiet -e ".[test,notebooks]"
	touch $(NOTEBOOKS_STAMP)

notebooks: $(NOTEBOOKS_STAMP)
	$(BIN)/python docs/_ext/notebooks.py --out out/notebooks

clean:
	rm -rf $(VENV) out .pytest_cache .mypy_cache .ruff_cache build docs/_build docs/api docs/auto_examples docs/figures substructure/_ckernels*.so
