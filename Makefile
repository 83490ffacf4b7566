# Two commands do all the set-up on a fresh machine (Python >= 3.10 with venv):
#   make run    create .venv if needed, install oceanmc, run the default scene
#   make test   create .venv if needed, install oceanmc with its test tools, run the tests
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cksum pyproject.toml | cut -d' ' -f1)

.PHONY: run test validate bench clean

# pip byte-compiles what it installs on one core; the dependencies (numpy, scipy, numba, dask,
# matplotlib, ...) are byte-compiled here on every core instead: a fresh venv's install took
# 72 and 83 s against 79 and 97 s on this project's 2-core machine (interleaved, 2026-11-28)
$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-compile -e ".[test]"
	$(BIN)/python -m compileall -q -j 0 "$$($(BIN)/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
	rm -f $(VENV)/.installed-*
	touch $(STAMP)

# oceanmc's own modules byte-compiled (pip does so for the packages it installs, not for an
# editable install): where PYTHONDONTWRITEBYTECODE is set, as on this project's machines,
# Python compiles them from source in every process, 0.2 s of each `oceanmc` command and of
# each of the tests' hundreds of processes (under a second; then only what changed)
BYTECODE := $(BIN)/python -m compileall -q oceanmc

run: $(STAMP)
	$(BYTECODE)
	$(BIN)/oceanmc run configs/default.yaml -o results/default.h5 --overwrite

test: $(STAMP)
	$(BYTECODE)
	$(BIN)/python -m pytest -n auto --dist worksteal

validate: $(STAMP)
	$(BYTECODE)
	$(BIN)/oceanmc validate -o validation

bench: $(STAMP)
	$(BYTECODE)
	$(BIN)/oceanmc bench -o benchmarks

clean:
	rm -rf $(VENV) results .pytest_cache
