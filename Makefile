# Two commands do everything on a fresh machine:
#   make demo   installs what is missing, then renders the reference scenes into reports/
#   make test   installs what is missing, then runs the test suite
# (Debian packages need root; the Python side lives in .venv.)

PYTHON      ?= python3
VENV        := .venv
PY          := $(VENV)/bin/python
PIP         := $(VENV)/bin/pip
LENSCOMPARE := $(VENV)/bin/lenscompare
APT_PACKAGES := povray libembree-dev libtbb-dev chromium
NATIVE_SOURCES := $(shell find native -name '*.cpp' -o -name '*.h')

.PHONY: demo test install system-deps bench clean

demo: install
	@mkdir -p reports/renders
	@for scene in reference_scenes/*.toml; do \
	  name=$$(basename $$scene .toml); \
	  for model in pinhole thin; do \
	    $(LENSCOMPARE) render $$scene --model $$model -o reports/renders/$$name.$$model.exr || exit $$?; \
	    $(LENSCOMPARE) preview reports/renders/$$name.$$model.exr -o reports/renders/$$name.$$model.png || exit $$?; \
	  done; \
	done
	@echo "Renders written to reports/renders/ (EXR, with PNG previews)."

test: install
	$(PY) -m pytest -q

bench: install
	$(PY) bench/bench_native.py

install: system-deps $(VENV)/.installed

# Install only what is missing, so a second run costs nothing.
system-deps:
	@missing=""; for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "Installing Debian packages:$$missing"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
	fi

$(VENV)/.installed: pyproject.toml CMakeLists.txt $(NATIVE_SOURCES)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PIP) install -q --disable-pip-version-check scikit-build-core nanobind cmake ninja
	$(PIP) install -q --disable-pip-version-check --no-build-isolation -e '.[test]' -Cbuild-dir=build/dev
	touch $@

clean:
	rm -rf build $(VENV) reports/renders
