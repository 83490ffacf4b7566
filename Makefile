# Two commands do all the set-up on a fresh machine (Python >= 3.10 with venv):
#   make run    create .venv if needed, install oceanmc, run the default scene
#   make test   create .venv if needed, install oceanmc with its test tools, run the tests
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cksum pyproject.toml | cut -d' ' -f1)

.PHONY: run test validate bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e ".[test]"
	rm -f $(VENV)/.installed-*
	touch $(STAMP)

run: $(STAMP)
	$(BIN)/oceanmc run configs/default.yaml -o results/default.h5 --overwrite

test: $(STAMP)
	$(BIN)/python -m pytest -n auto

validate: $(STAMP)
	$(BIN)/oceanmc validate -o validation

bench: $(STAMP)
	$(BIN)/oceanmc bench -o benchmarks

clean:
	rm -rf $(VENV) results .pytest_cache
