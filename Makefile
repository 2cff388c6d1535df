# The two commands of the README: `make demo` and `make test`. Both set everything up first
# and are idempotent: a second run re-uses the venv and the build.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.requirements-installed
# The nodes are Python: the messages' C++ interfaces are built only on request (MSGS_CPP=ON).
MSGS_CPP ?= OFF
# tf2_msgs (/tf, /tf_static): the underlay's where it has one (a full Jazzy install sourced,
# or the venv), else the workspace's own copy of the interface, tf2_msgs/ (the wheels on PyPI
# have none). Outside ros2_ws/src, so that a plain colcon build there never shadows the system's.
TF2_MSGS_UNDERLAY := $(firstword $(foreach prefix,$(VENV) $(subst :, ,$(AMENT_PREFIX_PATH)),\
    $(if $(findstring $(CURDIR)/ros2_ws/,$(abspath $(prefix))/),,\
    $(wildcard $(prefix)/share/ament_index/resource_index/packages/tf2_msgs))))
MSGS_PACKAGES := swivel_car_msgs $(if $(TF2_MSGS_UNDERLAY),,tf2_msgs)
BUILT := ros2_ws/install/.swivel_car_built_msgs_cpp_$(MSGS_CPP)$(if \
    $(TF2_MSGS_UNDERLAY),_tf2_msgs_underlay)
IN_WS := scripts/in_ws
PYTEST_ARGS ?=
PYTEST_WORKERS ?= auto

.PHONY: setup build test test-repeat demo figures bench soak clean

setup: $(STAMP)

# pip bootstraps the pinned uv, which installs the rest: on a new machine (no cache) uv took
# 27 s where pip took 142 s. The venv itself comes from python -m venv, which brings the
# setuptools that colcon's symlink install runs.
$(STAMP): requirements.txt
	@echo '== setting up $(VENV) (Python packages, ROS 2 Jazzy wheels)'
	test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --disable-pip-version-check "$$(grep '^uv==' requirements.txt)"
	$(VENV)/bin/uv pip install --quiet --python $(VENV)/bin/python -r requirements.txt
	cp requirements.txt $@

build: $(BUILT)

# The symlink install links each package's Python directory, so editing or adding a module
# needs no build; what colcon installs otherwise (manifests, setup files, interfaces, config,
# launch and resource files) does, and a build is then due. A build that changes nothing
# still takes colcon 11 s.
BUILD_INPUTS := $(shell find swivel_car_* tf2_msgs -type f -not -path '*/__pycache__/*' \( \
    -name package.xml -o -name setup.py -o -name setup.cfg -o -name CMakeLists.txt \
    -o -path '*/msg/*' -o -path '*/srv/*' -o -path '*/action/*' -o -path '*/config/*' \
    -o -path '*/launch/*' -o -path '*/resource/*' \))

# Three jobs side by side, since the interfaces' generators and compilers leave a core mostly
# idle: the interfaces; the Python packages, which need them only at run time (colcon would
# otherwise wait for them); and the byte code of the installed modules the tests import
# (scripts/warm_bytecode.py), which the test workers and their nodes would otherwise each
# compile at once, at the start of make test. The interfaces compile a job per core whatever
# the load average (colcon adds make's -l<cores>): after a busy minute, the load alone made
# them compile one file at a time (53 s instead of 34 s for the package alone).
COLCON_BUILD_ARGS := --symlink-install --event-handlers console_cohesion- summary+

$(BUILT): $(STAMP) $(BUILD_INPUTS) Makefile
	@echo '== building ros2_ws'
	@# A file removed from a package leaves a dangling symlink that fails the symlink install.
	find ros2_ws/build ros2_ws/install -xtype l -delete 2>/dev/null || true
	rm -f ros2_ws/install/.swivel_car_built_*
	$(if $(TF2_MSGS_UNDERLAY),rm -rf ros2_ws/build/tf2_msgs ros2_ws/install/tf2_msgs)
	@# Each colcon marks a new build and install directory at its start: two at once on a fresh
	@# workspace, one read the other's marker while it was being written and refused the build.
	cd ros2_ws && ../$(IN_WS) python -c 'from colcon_core.verb import check_and_mark_build_tool \
	    as build, check_and_mark_install_layout as install; build("build"); \
	    install("install", merge_install=False)'
	cd ros2_ws && { ../$(IN_WS) python ../scripts/warm_bytecode.py & warm_bytecode=$$!; } && \
	{ ../$(IN_WS) colcon --log-base log/python_packages build $(COLCON_BUILD_ARGS) \
	    --packages-ignore swivel_car_msgs & python_packages=$$!; }; \
	MAKEFLAGS=-j$$(nproc) ../$(IN_WS) colcon build $(COLCON_BUILD_ARGS) \
	    --base-paths src ../tf2_msgs --packages-select $(MSGS_PACKAGES) \
	    --cmake-args -DBUILD_TESTING=OFF -DSWIVEL_CAR_MSGS_CPP=$(MSGS_CPP) \
	    -DSWIVEL_CAR_MSGS_UNITY_BUILD=ON; msgs=$$?; \
	wait $$python_packages && wait $$warm_bytecode && exit $$msgs
	touch $@

# Test files run side by side, one pytest-xdist worker more than cores (PYTEST_WORKERS=auto,
# conftest.py says why; PYTEST_WORKERS=0: in one process). Each worker claims its own block of
# ROS domain ids. A file stays on one worker (module fixtures carry a stack from test to test), in
# the order pytest.ini lists them.
# Foxglove's own bag parsers for tests/test_tf.py, from npm, pinned by the lock file (10
# packages, 4 MB: 4 s).
FOXGLOVE_NPM := tests/foxglove/node_modules/.package-lock.json
$(FOXGLOVE_NPM): tests/foxglove/package.json tests/foxglove/package-lock.json
	npm ci --prefix tests/foxglove --no-audit --no-fund --silent
	touch $@

test: build $(FOXGLOVE_NPM)
	@echo '== running every test'
	$(IN_WS) python -m pytest -n $(PYTEST_WORKERS) --dist loadfile --no-loadscope-reorder \
	    $(PYTEST_ARGS)

# The flake hunt: the whole suite RUNS times (HOG=1: one core kept busy meanwhile); prints each
# test that failed and how often.
RUNS ?= 5
HOG ?= 0
test-repeat: build $(FOXGLOVE_NPM)
	$(IN_WS) python scripts/test_repeat.py --runs $(RUNS) --workers $(PYTEST_WORKERS) \
	    $(if $(filter 1,$(HOG)),--hog) $(PYTEST_ARGS)

demo: build
	@echo '== running the demo: the simulated car drives to a step and climbs it'
	$(IN_WS) python scripts/demo.py $(if $(CLOCK),--clock $(CLOCK))

figures: build
	$(IN_WS) python -m swivel_car_model.figures --out docs/figures

# Benchmarks print figures (speed as real-time factors and ratios, accuracy as errors);
# no test ever times anything. The planner's climbs take several minutes.
bench: build
	$(IN_WS) python -m swivel_car_model.benchmark
	$(IN_WS) python -m swivel_car_sim.benchmark
	$(IN_WS) python -m swivel_car_perception.benchmark
	$(IN_WS) python scripts/chain_benchmark.py
	$(IN_WS) python -m swivel_car_control.benchmark
	$(IN_WS) python -m swivel_car_studies.benchmark
	$(IN_WS) python -m swivel_car_studies.campaign_benchmark
	$(IN_WS) python -m swivel_car_studies.climb_benchmark $(CLIMB_BENCH_ARGS)
	$(IN_WS) python -m swivel_car_studies.detected_climb_benchmark

# Ten minutes of driving and climbs through the ROS stack: memory slope and message rates.
soak: build
	$(IN_WS) python scripts/soak.py

clean:
	rm -rf ros2_ws/build ros2_ws/install ros2_ws/log
