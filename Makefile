# MonoPIC: `make demo` and `make test` work on a fresh machine with Python 3.11 and make.
PY ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
export MUJOCO_GL ?= egl

.PHONY: install demo test lint format clean-venv

install: $(STAMP)

# (Re)install when the project's dependency pins change.
$(STAMP): pyproject.toml requirements.lock
	@test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q -c requirements.lock -e '.[dev]'
	@touch $(STAMP)

demo: $(STAMP)
	@mkdir -p recordings
	$(BIN)/monopic video tests/data/walk_clip.mp4 --variant warning \
		--out recordings/demo.mp4 --csv recordings/demo.csv --rrd recordings/demo.rrd

test: $(STAMP) lint
	$(BIN)/python -m pytest -q

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/lint-imports

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

clean-venv:
	rm -rf $(VENV)

-include Makefile.models
