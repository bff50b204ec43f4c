# lamina: thin wrapper over CMake. `make demo` and `make test` are the whole set-up.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build test test-unit bench coat-costs demo format clean

all: build

deps:
	@./scripts/deps.sh

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

configure: $(BUILD)/CMakeCache.txt

build: configure
	cmake --build $(BUILD) -j $(JOBS)

test: deps
	$(MAKE) build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-unit: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) -L unit

bench: deps
	$(MAKE) build
	$(BUILD)/lamina_bench

# The production coats' cost per evaluation, which the study's summary quotes
# (data/coat_costs.json; run on a quiet machine, then rebuild).
coat-costs: deps
	$(MAKE) build
	python3 scripts/coat_costs.py $(BUILD)

demo: deps
	$(MAKE) build
	@./scripts/demo.sh $(BUILD)

format:
	clang-format -i $$(git ls-files '*.h' '*.cpp')

clean:
	rm -rf $(BUILD)
