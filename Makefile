# infomarket — developer entry points.  Every target sets up .venv first if needed.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: venv demo lint test test-busy bench clean contracts gas node docs

venv: $(STAMP)

$(STAMP): pyproject.toml Makefile
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e ".[dask,chain,dev,docs,rl,sql,ros]"
	touch $(STAMP)

demo: venv
	$(BIN)/infomarket demo

# The linters, configured in pyproject.toml: ruff on src and tests, then mypy on the public API (the files its
# section names; its cache in .mypy_cache).  CI runs this before the suite; either one's finding fails it.
lint: venv
	$(BIN)/ruff check src tests
	$(BIN)/mypy

# Two processes (CI has 2 cores), tests handed out one by one as a process frees up (worksteal): on a
# fresh clone most of the time is compiling step kernels, and a module that compiles many must not keep one
# process busy while the other idles.  A kernel one process compiled, the other loads from the disk cache;
# tests share kernels where they can (docs/testing.md).  TEST_WORKERS=0 runs them inline.
TEST_WORKERS ?= 2
test: venv
	$(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist worksteal

# The suite on a loaded machine: `make test` while two busy loops hold both cores (tools/busy.py ends the
# loops with it, pass or fail).  No test may depend on the machine's speed; this is where that is proved.
test-busy: venv
	$(BIN)/python tools/busy.py 2 $(MAKE) test

bench: venv
	$(BIN)/infomarket bench

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache build dist site

# The Solidity contract: solc-js pinned in tools/solc; the compiled artifact is committed in the package.
contracts: tools/solc/node_modules
	node tools/solc/compile.js

tools/solc/node_modules: tools/solc/package.json tools/solc/package-lock.json
	cd tools/solc && npm ci --no-audit --no-fund
	touch $@

# Gas with cold storage per transaction (revm, sizes 1-512, small sizes cross-checked on py-evm, the bound at
# 512 distinct sellers for every scheme): docs/gas.md; then the chain model's constants as they must read in
# src/infomarket/ledger/gas.py
# (tests/evm/test_gas_constants.py fails until they do).
gas: venv
	$(BIN)/python -m infomarket.evm.gasreport
	$(BIN)/python -m infomarket.evm.gasreport --constants

# A local JSON-RPC node (Hardhat Network, pinned in tools/node) that the conformance suite runs against.
node: tools/node/node_modules

tools/node/node_modules: tools/node/package.json tools/node/package-lock.json
	cd tools/node && npm ci --no-audit --no-fund
	touch $@

# The documentation site (mkdocs.yml): docs/*.md, the README as its home page, and an API reference drawn
# from the docstrings, built into site/.  --strict: a broken link, anchor or API reference fails the build.
docs: venv
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict
