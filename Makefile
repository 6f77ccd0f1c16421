# Two-command quick start: `make demo` and `make test`. Everything else is here too.
BUILD       ?= build
BUILD_CLANG ?= build-clang
CMAKE_FLAGS ?=
JOBS        ?= $(shell nproc)

.PHONY: all deps configure build build-clang demo test fuzz bench clean

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD)/build.ninja: | deps
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=g++ \
	  -DLASH_CLANG_BUILD_DIR=$(abspath $(BUILD_CLANG)) $(CMAKE_FLAGS)

configure: $(BUILD)/build.ninja

build: deps configure
	cmake --build $(BUILD) -j $(JOBS)

# The clang build: proves -Wall -Wextra -Werror on clang 14, runs the unit suite under UBSan
# (-fsanitize=undefined, any report fatal), builds the fuzz targets and feeds the
# cross-compiler determinism test (same seed -> byte-identical CSV).
build-clang: deps
	@test -f $(BUILD_CLANG)/build.ninja || cmake -S . -B $(BUILD_CLANG) -G Ninja -DCMAKE_BUILD_TYPE=Release \
	  -DCMAKE_CXX_COMPILER=clang++ -DLASH_BUILD_BENCH=OFF -DLASH_BUILD_FUZZ=ON $(CMAKE_FLAGS)
	cmake --build $(BUILD_CLANG) -j $(JOBS)

demo: build
	$(BUILD)/bin/lash demo --out-dir $(BUILD)/demo
	$(BUILD)/bin/lash hil run --duration 5 --out-dir $(BUILD)/demo/hil || $(BUILD)/bin/lash hil run --duration 5 --no-isolate --out-dir $(BUILD)/demo/hil
	gnuplot -e "dir='$(BUILD)/demo/hil'" scripts/plot_hil_run.gp && echo "plot of the HIL run: $(BUILD)/demo/hil/hil_run.png"

test: build build-clang
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)
	ctest --test-dir $(BUILD_CLANG) --output-on-failure -j $(JOBS) -L unit

# Random exploration of every fuzz target, FUZZ_SECONDS each (default 600): docs/fuzzing.md.
fuzz: build-clang
	BUILD_CLANG=$(BUILD_CLANG) bash scripts/fuzz.sh

bench: build
	$(BUILD)/bin/lash_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

clean:
	rm -rf $(BUILD) $(BUILD_CLANG)
