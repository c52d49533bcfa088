# hsr: the two commands are `make demo` and `make test`. See README.md.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=
# Unity builds (CMakeLists.txt HSR_UNITY_BUILD): about half the CPU time of a clean build; the demo's library
# objects are the test build's too, so `make test` after `make demo` compiles only what the demo did not.
UNITY ?= -DHSR_UNITY_BUILD=ON
DEMO_MODEL ?= house
DEMO_DIR ?= $(BUILD_DIR)/demo

.PHONY: all deps configure build demo test bench clean fuzz test-asan

all: build

deps:
	bash scripts/install-deps.sh

# Everything: the CLI, the tests, the benchmarks and the Python module.
configure:
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DHSR_BUILD_TESTS=ON -DHSR_BUILD_BENCH=ON -DHSR_BUILD_PYTHON=ON $(UNITY) $(CMAKE_FLAGS)

build: deps configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

# The front door: only what the demo needs (the packages that build the CLI, and the CLI alone), then a model.
demo:
	bash scripts/install-deps.sh --demo
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release -DHSR_BUILD_TESTS=OFF -DHSR_BUILD_BENCH=OFF -DHSR_BUILD_PYTHON=OFF $(UNITY) $(CMAKE_FLAGS)
	cmake --build $(BUILD_DIR) -j $(JOBS) --target hsr
	bash scripts/demo.sh $(BUILD_DIR) $(DEMO_MODEL) $(DEMO_DIR)

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

bench: build
	bash bench/run.sh

# Reliability (README "Reliability"): the suite under ASan + UBSan, and the libFuzzer targets.
FUZZ_SECONDS ?= 60
test-asan: deps
	bash scripts/test-asan.sh build-asan $(JOBS)

fuzz: deps
	FUZZ_SECONDS=$(FUZZ_SECONDS) JOBS=$(JOBS) bash scripts/fuzz.sh

clean:
	rm -rf $(BUILD_DIR)
