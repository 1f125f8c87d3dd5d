# Every target creates the virtual environment on first use, so a fresh clone needs
# only Python 3.11 or newer: `make run` and `make test`.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
DECK   ?= decks/artery_inflation.toml
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

test: $(STAMP)
	$(BIN)/python -m pytest -q

# The slow tests (the stability suite among them), then the verification and stability
# studies written into docs/verification/studies/ (their tables and plots are committed).
verify: $(STAMP)
	$(BIN)/python -m pytest -q -m slow
	$(BIN)/shellsim report decks/studies/verification.toml --out docs/verification/studies/verification
	$(BIN)/shellsim report decks/studies/stability.toml --out docs/verification/studies/stability

bench: $(STAMP)
	$(BIN)/shellsim bench

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .hypothesis
