# CoReDEM: the two commands of the README quick start, and a few conveniences.
#   make run    install dependencies, build everything, run the default case
#   make test   install dependencies, build everything, run the test suite
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
BUILD_TYPE ?= Release
CMAKE_FLAGS ?=

.PHONY: all deps configure build run test bench format format-check clean

all: build

deps:
	scripts/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(CMAKE_FLAGS)

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

run: build
	scripts/run-default.sh $(BUILD_DIR)

# The whole suite, then scripts/test-summary.py: the counts by label and group, and a failure on
# any failed, unexpectedly skipped or missing test (a group that should run but is not there).
test: build
	@rm -f $(BUILD_DIR)/ctest-junit.xml
	@rc=0; cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) --test-output-size-passed 262144 \
	  --test-output-size-failed 1048576 --output-junit $(abspath $(BUILD_DIR))/ctest-junit.xml \
	  || rc=$$?; \
	/usr/bin/python3 $(CURDIR)/scripts/test-summary.py . ctest-junit.xml || rc=1; exit $$rc

format:
	git ls-files '*.h' '*.cpp' '*.cu' '*.cuh' | xargs clang-format -i

format-check:
	scripts/check-format.sh

clean:
	rm -rf $(BUILD_DIR)
