# bayesgrasp: `make demo` and `make test` do all the set-up on a fresh Debian machine.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
BENCH_VENV := .venv-bench
PY := $(VENV)/bin/python
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
export CMAKE_BUILD_PARALLEL_LEVEL ?= $(JOBS)

# Debian packages the build needs (checked one by one; only missing ones are installed).
DEB_PACKAGES := build-essential cmake pkg-config python3-dev python3-venv \
  libeigen3-dev libfcl-dev libbullet-dev libqhull-dev nlohmann-json3-dev liblbfgspp-dev \
  libpcl-dev libgtest-dev libbenchmark-dev libopenblas-openmp-dev chromium chromium-driver

# What the package's build reads: bench/'s C++ (its binaries share the build tree), not its scripts or results.
SOURCES := $(shell find cpp python tests/cpp -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' -o -name '*.py' -o -name '*.json' \) 2>/dev/null) \
           $(wildcard bench/*.cpp bench/*.hpp) CMakeLists.txt pyproject.toml

.PHONY: all demo test bench bench-peers deps clean distclean ctest pytest fuzz sanitize readme shipped-cache
all: $(VENV)/.installed

# ---- system packages -------------------------------------------------------------------
build/.deps-ok: Makefile
	@mkdir -p build
	@missing=""; for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo ">> installing Debian packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" -ne 0 ] && SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing; \
	else echo ">> Debian packages present"; fi
	@touch $@
deps: build/.deps-ok

# ---- Python virtual environment ----------------------------------------------------------
$(VENV)/.base: build/.deps-ok Makefile
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q "scikit-build-core>=0.10" "pybind11>=2.12" ninja numpy scipy matplotlib trimesh manifold3d "coacd>=1.0.14,<1.1" tqdm pytest scikit-learn hypothesis "open3d>=0.18" "jsonschema>=4.0" "viser>=1.0" "selenium>=4.20" "ray>=2.9" "yourdfpy>=0.0.56" "pin>=4.1" "fastapi>=0.110" "uvicorn>=0.29" "httpx>=0.24"
	@touch $@

# The package is built by scikit-build-core in build/py (kept between builds, so a second
# build recompiles only what changed); the same tree holds the C++ tests and benchmarks.
$(VENV)/.installed: $(VENV)/.base $(SOURCES)
	$(PY) -m pip install -q --no-build-isolation --no-deps .
	@touch $@

# ---- the two commands --------------------------------------------------------------------
demo: $(VENV)/.installed
	$(VENV)/bin/bayesgrasp demo --out out/demo

# The C++ tests and benchmarks, in the package's build tree (the package itself builds only _core,
# so `make demo` compiles no test or benchmark).
build/py/.cpp-all: $(VENV)/.installed
	cmake --build build/py
	@touch $@

ctest: build/py/.cpp-all
	ctest --test-dir build/py --output-on-failure -j $(JOBS)

pytest: $(VENV)/.installed
	$(VENV)/bin/python -m pytest -q tests/python

test: ctest pytest

# Every README example, in order, on a clean copy of the clone, checked against its text
# (experiments with --runs $(README_RUNS)); on a cold model cache the first run takes hours.
README_RUNS ?= 2
readme: $(VENV)/.installed
	mkdir -p out && $(PY) tests/readme/run_readme.py --runs $(README_RUNS) --report out/readme.json

# The long run of the bindings' property-based fuzzing (make test runs 25 cases per target).
FUZZ_EXAMPLES ?= 1000
fuzz: $(VENV)/.installed
	mkdir -p out && BAYESGRASP_FUZZ_EXAMPLES=$(FUZZ_EXAMPLES) BAYESGRASP_FUZZ_REPORT=out/fuzz.jsonl $(VENV)/bin/python -m pytest -q tests/python/test_fuzz.py

# ---- benchmarks ----------------------------------------------------------------------------
# Peers (GPy, pyswarms, pybullet, scikit-learn) live in their own virtual environment.
$(BENCH_VENV)/.base: build/.deps-ok
	$(PYTHON) -m venv $(BENCH_VENV)
	$(BENCH_VENV)/bin/pip install -q --upgrade pip
	$(BENCH_VENV)/bin/pip install -q -r bench/requirements.txt
	@touch $@

bench: build/py/.cpp-all $(BENCH_VENV)/.base
	BENCH_PY=$(BENCH_VENV)/bin/python BAYESGRASP_PY=$(PY) BUILD_DIR=build/py bash bench/bench_all.sh

# Peer planners (issue 52), each in its own virtual environment, driven by bench/peers/*_driver.py
# (JSON request in, JSON result out; bench/peers/README.md), beside bayesgrasp on the YCB scans by
# bench/peers/protocol.py. PEERS_OBJECTS (comma-separated YCB names; default all 21) and PEERS_RUNS
# (true poses per object under uncertainty; default 10) size the run; PEERS_ARGS adds options
# (e.g. --reuse to continue an interrupted run).
PEER_PBG := .venv-peer-pbg
PEER_CGN := .venv-peer-cgn
PEERS_OUT ?= bench/results/peers_protocol
PEERS_RUNS ?= 10
PEERS_OBJECTS ?=
PEERS_ARGS ?=
$(PEER_PBG)/.installed: bench/peers/requirements-pybullet-grasper.txt | build/.deps-ok
	$(PYTHON) -m venv $(PEER_PBG)
	$(PEER_PBG)/bin/pip install -q --upgrade pip
	$(PEER_PBG)/bin/pip install -q -r bench/peers/requirements-pybullet-grasper.txt
	@touch $@
$(PEER_CGN)/.installed: bench/peers/requirements-cgn.txt bench/peers/requirements-cgn-nodeps.txt | build/.deps-ok
	$(PYTHON) -m venv $(PEER_CGN)
	$(PEER_CGN)/bin/pip install -q --upgrade pip
	$(PEER_CGN)/bin/pip install -q -r bench/peers/requirements-cgn.txt
	$(PEER_CGN)/bin/pip install -q --no-deps -r bench/peers/requirements-cgn-nodeps.txt
	@touch $@

bench-peers: $(VENV)/.installed $(BENCH_VENV)/.base $(PEER_PBG)/.installed $(PEER_CGN)/.installed
	$(PY) bench/peers/protocol.py --out $(PEERS_OUT) --runs $(PEERS_RUNS) \
	  $(if $(PEERS_OBJECTS),--objects $(PEERS_OBJECTS)) $(PEERS_ARGS)

# The package's shipped cache (python/bayesgrasp/data/cache): the demo's, pub2's and the README's
# category and fuse examples' models, task grasps and decompositions, rebuilt from an empty cache
# (bayesgrasp.cache_build, into build/shipped-cache: an interrupted build resumes there; about an
# hour on 2 cores). Found again by their cache keys.
shipped-cache: $(VENV)/.installed
	$(PY) -m bayesgrasp.cache_build --out python/bayesgrasp/data/cache

clean:
	rm -rf build/py out
distclean:
	rm -rf build $(VENV) $(BENCH_VENV)

# The core, bindings and C++ tests under ASan + UBSan in build/asan (kept between runs), then a
# fast Python subset on the sanitized module (tests/sanitize/run.sh; the README gives its time).
sanitize: $(VENV)/.installed
	JOBS=$(JOBS) bash tests/sanitize/run.sh
