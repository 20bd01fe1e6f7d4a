# infomarket — developer entry points.  Every target sets up .venv first if needed.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: venv demo test bench clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e ".[dask,chain,dev]"
	touch $(STAMP)

demo: venv
	$(BIN)/infomarket demo

test: venv
	$(BIN)/python -m pytest -q

bench: venv
	$(BIN)/infomarket bench

clean:
	rm -rf $(VENV) .pytest_cache build dist
