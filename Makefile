# Two commands do everything on a fresh machine:
#   make demo   installs what is missing, then writes the comparison report to reports/latest/
#   make test   installs what is missing, then runs the test suite
# (Debian packages need root; the Python side lives in .venv.)

PYTHON      ?= python3
VENV        := .venv
PY          := $(VENV)/bin/python
PIP         := $(VENV)/bin/pip
LENSCOMPARE := $(VENV)/bin/lenscompare
APT_PACKAGES := povray libembree-dev libtbb-dev chromium
NATIVE_SOURCES := $(shell find native -name '*.cpp' -o -name '*.h')
# The editable install maps the package's files when it is made: new modules need a reinstall.
PACKAGE_FILES := $(shell find lenscompare -name '*.py' -o -name '*.dat')

.PHONY: demo test install system-deps bench clean

demo: install
	$(LENSCOMPARE) report -o reports/latest

# Two test workers (pytest-xdist), one per core: 6 min 54 s for the suite here (session 55).
test: install
	$(PY) -m pytest -q -n 2

# Mitsuba's LLVM variant (bench_peers.py) needs Debian's LLVM 19 (its JIT fails with LLVM 15).
LLVM_LIBRARY := /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1

bench: install
	@dpkg -s libllvm19 >/dev/null 2>&1 || (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libllvm19 >/dev/null)
	DRJIT_LIBLLVM_PATH=$(LLVM_LIBRARY) $(PY) bench/bench_peers.py --one-light --empty --time-to-rmse
	$(PY) bench/bench_quads.py
	$(PY) bench/bench_native.py
	$(PY) bench/bench_lens.py
	$(PY) bench/bench_lens_ceiling.py
	$(PY) bench/check_lens_ray_table.py
	$(PY) bench/bench_lens_mirrors.py
	$(PY) bench/bench_povray.py
	$(PY) bench/bench_cost.py
	$(PY) bench/bench_mesh.py
	$(PY) bench/bench_sweep.py
	$(PY) bench/bench_memory.py

install: system-deps $(VENV)/.installed

# Install only what is missing, so a second run costs nothing.
system-deps:
	@missing=""; for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "Installing Debian packages:$$missing"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
	fi

$(VENV)/.installed: pyproject.toml CMakeLists.txt $(NATIVE_SOURCES) $(PACKAGE_FILES)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PIP) install -q --disable-pip-version-check scikit-build-core nanobind cmake ninja
	$(PIP) install -q --disable-pip-version-check --no-build-isolation -e '.[test]' -Cbuild-dir=build/dev
	touch $@

clean:
	rm -rf build $(VENV) reports/latest
