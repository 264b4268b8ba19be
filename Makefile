# The projector's build and test entry points. Every target creates the virtual environment
# (.venv, with an editable install of this project) if it is missing.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
JOBS   ?= 2

.PHONY: setup test properties sim verilog resources timing formal bench figures waves lint clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

setup: $(STAMP)

# The suite: Amaranth-simulator unit tests, cocotb tests on the generated Verilog, the formal
# harness's own tests. The formal properties run in make properties (CI runs both).
test: $(STAMP)
	$(PY) -m pytest -n $(JOBS) -q -m "not formal"

# Every formal property at the depth its covers are reached, and each sequencer rule failing a
# claim the sequencer must break (tests/test_formal.py, marked formal); make formal: full depth.
properties: $(STAMP)
	$(PY) -m pytest -n $(JOBS) -q -m formal tests/test_formal.py

# The main job: the system simulation on the default scene (DCLK 400 MHz; DCLK=200 for 200 MHz;
# DMD=dlp9500: the DLP9500's core, four buses;
# FAULTS=stalls|rst|all: the memory stalls at random, the DLPC410 holds RST_ACTIVE longer than
# planned, or both; VIRTUAL=<seconds>|demo: the virtual projector on a TAP device in a network
# namespace of its own, which host software in that namespace can talk to; needs root;
# WINDOW=1: also dump every signal of the core (VCD) from the first frame's last datagram through
# the store to just after its first pulse, with a GTKWave save file grouped by block;
# GROUP_ORDERS=<seconds>: the plan is the constraint solver's, dual reset's groups each in a plane
# order of its own, searched that long).
DCLK ?= 400
DMD ?=
FAULTS ?=
VIRTUAL ?=
WINDOW ?=
GROUP_ORDERS ?=
sim: $(STAMP)
	$(PY) -m flow sim --dclk $(DCLK) $(if $(DMD),--dmd $(DMD)) $(if $(FAULTS),--faults $(FAULTS)) $(if $(VIRTUAL),--virtual $(VIRTUAL)) \
		$(if $(WINDOW),--window) $(if $(GROUP_ORDERS),--group-orders $(GROUP_ORDERS))

# The Spartan-6 ISE trees (Verilog, UCF, ISE scripts) and each block's Verilog, in build/spartan6:
# the Atlys's, the sync master's (sync_master/) and the DLP9500's on the SVEC (dlp9500/), linted.
verilog: $(STAMP)
	$(PY) -m flow verilog

# LUT/FF/BRAM/DSP per block and per board build (Yosys synth_xilinx -family xc6s, JOBS at a time):
# the DLP7000's projector on the Atlys against its XC6SLX45, the DLP9500's on the SVEC against its
# XC6SLX150T.
resources: $(STAMP)
	$(PY) -m flow resources --jobs $(JOBS)

# Logic depth (LUT levels, carry chains) between flip-flops per clock domain of the core.
timing: $(STAMP)
	$(PY) -m flow timing

# Every formal property: k-induction proofs and deep bounded checks (SymbiYosys, Yices).
formal: $(STAMP)
	$(PY) -m flow formal --jobs $(JOBS)

# Every benchmark; writes build/bench.json and prints the figures.
bench: $(STAMP)
	$(PY) -m flow bench

# docs/figures.md from build/bench.json (make bench first): a table per figure prefix, with sources;
# and every figure the README and docs/*.md quote between <!-- figure ... --> markers.
figures: $(STAMP)
	$(PY) -m flow figures

waves: $(STAMP)
	$(PY) -m flow waves

lint: $(STAMP)
	$(PY) -m ruff check spec gateware host flow sim tests

clean:
	rm -rf build results.xml .pytest_cache
