# MonoPIC: `make demo` and `make test` work on a fresh machine with Python 3.11 and make.
PY ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
export MUJOCO_GL ?= egl

.PHONY: install demo test lint format clean-venv realism ncap

install: $(STAMP)

# (Re)install when the project's dependency pins change.
$(STAMP): pyproject.toml requirements.lock
	@test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q -c requirements.lock -e '.[dev,ray,ncap,openvino,tracking,crowd]'
	# JuPedSim (crowds) without its viewer's PySide6 and VTK: pyproject.toml's `crowd` says why.
	$(BIN)/python -m pip install -q --no-deps -c requirements.lock jupedsim
	@touch $(STAMP)

# The pipeline on the shipped clip, then the default sweep of every case and family
# through the simulator, its report and headline table (about 10 minutes on 2 cores).
demo: $(STAMP)
	@mkdir -p recordings
	$(BIN)/monopic video tests/data/walk_clip.mp4 --variant warning \
		--out recordings/demo.mp4 --csv recordings/demo.csv --rrd recordings/demo.rrd
	$(BIN)/monopic sweep scenarios/sweeps/demo.toml --out recordings/demo.jsonl --restart
	$(BIN)/monopic report recordings/demo.jsonl --out recordings/demo_report
	$(BIN)/monopic ncap --quick --restart --out recordings/ncap-quick

# The Euro NCAP 2026 pedestrian grid, thin (--quick, a few minutes on 2 cores), scored by
# the official rating calculator (extra [ncap]): recordings/ncap-quick/report.md.
# The full grid: `.venv/bin/monopic ncap --workers 2 --out recordings/ncap-full` (resumable).
ncap: $(STAMP)
	$(BIN)/monopic ncap --quick --out recordings/ncap-quick

# The suite on every core (pytest-xdist): about 9 minutes on 2 cores, 14 on one.
test: $(STAMP) lint
	$(BIN)/python -m pytest -q -n auto

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/lint-imports

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

# Simulated walkers beside real ones (docs/realism/report.md): free walks and the medium
# sweep's families, human and rail, and crowds at each real scene's density (JuPedSim;
# scenarios/sweeps/crowd-hotel.toml, crowd-zara.toml), against the ETH/UCY scenes shipped
# beside the project (read at run time, never copied in): per walker (speed, acceleration,
# turning, constant-velocity error) and per crowd (density, nearest person, groups, speed
# spread), with people-pavement's scripted bystanders beside them. A few minutes.
REAL_TRACKS ?= ../shared/data/eth-ucy-calibration
CROWDS := scenarios/sweeps/crowd-hotel.toml scenarios/sweeps/crowd-zara.toml
realism: $(STAMP)
	$(BIN)/monopic realism scenarios/sweeps/walks.toml scenarios/sweeps/walks-rail.toml \
		scenarios/sweeps/medium-human.toml scenarios/sweeps/medium.toml \
		--crowds $(CROWDS) scenarios/sweeps/people-pavement.toml \
		--real $(REAL_TRACKS)/*.txt --out docs/realism --judge walks

clean-venv:
	rm -rf $(VENV)

-include Makefile.models
-include bench/Makefile.bench
