# Every target creates the virtual environment on first use, so a fresh clone needs
# only Python 3.11 or newer: `make run` and `make test`.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
DECK   ?= decks/tissue/carotid_hgo_pulse.toml
OUT    ?= results
STAMP  := $(VENV)/.installed

.PHONY: run test verify bench clean

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "shellsim needs Python >= 3.11")'
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

run: $(STAMP)
	$(BIN)/shellsim run $(DECK) --out $(OUT)

# The linter, then one test process per core (pytest-xdist); the numba cache is compiled
# once, before them.
test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/python -m pytest -q -n auto

# The slow tests, then the verification and stability studies (the stability checks
# live in the study: its exit code) written into docs/verification/studies/ and their
# tables into docs/verification.md (all committed).
verify: $(STAMP)
	$(BIN)/python -m pytest -q -m slow
	$(BIN)/shellsim report decks/studies/verification.toml --out docs/verification/studies/verification --embed docs/verification.md
	$(BIN)/shellsim report decks/studies/stability.toml --out docs/verification/studies/stability --embed docs/verification.md

bench: $(STAMP)
	$(BIN)/shellsim bench

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .hypothesis
