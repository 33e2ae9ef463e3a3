# Top-level entry points. Every target installs what is missing first (scripts/install-deps.sh).
BUILD ?= build
JOBS ?= $(shell nproc)
SCENE ?= scenes/cornell_box.ray
CMAKE_FLAGS ?=

.PHONY: all deps configure build demo test bench install test-sanitize fuzz report clean

all: build

deps:
	@./scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# Renders the default scene with Lightcuts, checks it against brute force at sampled
# pixels, and prints the speed-up and error.
demo: build
	@mkdir -p out
	@./$(BUILD)/lightcuts render $(SCENE) -o out/cornell_box.png --reference-pixels 256 --stats out/cornell_box.json

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	@./scripts/bench.sh

# make install PREFIX=/usr DESTDIR=/tmp/stage: the binary in PREFIX/bin, the man page in
# PREFIX/share/man/man1, the scenes in PREFIX/share/lightcuts, the docs in PREFIX/share/doc/lightcuts;
# DESTDIR (staging, packaging) is prepended to all of them.
PREFIX ?= /usr/local
install: build
	@DESTDIR=$(DESTDIR) cmake --install $(BUILD) --prefix $(PREFIX)

# The suite (and the binary the CLI tests run) under AddressSanitizer, LeakSanitizer and
# UndefinedBehaviorSanitizer (UB aborts). Tests named *Slow* are labelled "slow" and left
# out (scripts/ctest_labels.cmake). See docs/ERRORS.md.
test-sanitize: deps
	@cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLC_SANITIZE=ON -DLC_BUILD_BENCH=OFF >/dev/null
	@cmake --build build-sanitize -j $(JOBS)
	@cd build-sanitize && ASAN_OPTIONS=detect_leaks=1:strict_string_checks=1:check_initialization_order=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j $(JOBS) -LE slow --timeout 900

# libFuzzer: each target (or those in FUZZ_TARGETS) for FUZZ_SECONDS, in build-fuzz.
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?=
fuzz: deps
	@./scripts/fuzz.sh $(FUZZ_SECONDS) $(FUZZ_TARGETS)

# docs/BENCHMARKS.md (written by `make bench`) as one self-contained HTML page, images inlined.
report:
	@./scripts/install-deps.sh python3-markdown
	@/usr/bin/python3 scripts/report.py -i docs/BENCHMARKS.md -o docs/report.html

clean:
	rm -rf $(BUILD) build-sanitize build-fuzz
