# Short names for the README's commands. Every target installs what it needs first (idempotent).
.PHONY: all deps build test e2e test-asan test-debug rt fuzz bench demo latency soak stall-seeds soak-asan feel-check wall-test same-behaviour mutation-check fresh-check package package-check clean help

all: build

help:
	@echo "make demo       install dependencies, build, and run the host simulation on the baked-in hex prism (raster job; outputs in build/demo/latest/)"
	@echo "make test       install dependencies, configure, build and run every test (release preset)"
	@echo "make e2e        the end-to-end tests only, the operator display in headless Chromium among them"
	@echo "make test-asan  the same under AddressSanitizer + UndefinedBehaviorSanitizer (build/asan)"
	@echo "make test-debug the same without optimisation (build/debug)"
	@echo "make build      build only (binaries in build/bin)"
	@echo "make bench      time the engine (query, full cycle) beside brute force, FCL and the previous engine (1f546f3), with callgrind's instruction counts: build/bin/stencil-bench"
	@echo "make rt         build for the real-time x86-64 box (build/rt-x86_64)"
	@echo "make latency    the cycle's wake-up latency beside cyclictest's, under stress-ng (LATENCY_SECONDS=60 per phase)"
	@echo "make soak       a simulated SOAK_HOURS (8) job with SOAK_FAULTS (12) random faults, resumed after each (build/soak)"
	@echo "make stall-seeds the random operator for STALL_HOURS (2) on seeds 1..STALL_SEEDS (20): no stall, no gouge (build/stall-seeds)"
	@echo "make soak-asan  a half-hour slice of it under ASan + UBSan, for leaks (build/soak-asan)"
	@echo "make wall-test  the wall's feel: taps and slides for every hand and coupling, today's rendering beside the new (stencil-wall-test)"
	@echo "make feel-check the demo's job and the e2e job and fault cases again with the wall's feel on and a dynamic hand (FEEL=...; about 15 minutes)"
	@echo "make size-check clang-tidy's function sizes: main() of a program <= 150 lines, runtime, boards and programs' other functions <= 80 (in CI)"
	@echo "make same-behaviour OLD=<commit>  a refactor's proof: OLD's and this tree's deterministic jobs give the same reports and journals"
	@echo "make mutation-check each behaviour in tests/mutations.tsv broken by a one-line change: its test must fail (build/mutation; about 15 minutes)"
	@echo "make package    the Debian package (CPack): build/stencil_<version>_<arch>.deb"
	@echo "make package-check install, use and purge that package in a clean Debian 12 root (mmdebstrap; needs root; about two minutes)"
	@echo "make fresh-check README's two commands in a clean Debian 12 root (mmdebstrap; needs root; about half an hour)"
	@echo "make fuzz       build the libFuzzer targets with clang (build/fuzz) and fuzz each for FUZZ_SECONDS (60)"
	@echo "make clean      remove build/"

deps:
	@bash toolchain/install-deps.sh

build: deps
	cmake --preset release
	cmake --build --preset release

test: build
	ctest --preset release

# The end-to-end tests only (the programs, the fault suite, the operator display in headless Chromium).
e2e: build
	ctest --preset release -L e2e

# The previous engine (commit 1f546f3) is built beside this one for the bench's "previous" rows;
# without the repository's history, or when that build fails, the bench runs without them (the
# stale binary removed, so no row comes from an older harness).
bench: build
	bash toolchain/bench-previous.sh || rm -f build/previous/bin/stencil-bench
	build/bin/stencil-bench

# The main job: the host simulation on the baked-in sample part, a raster job until every reachable
# triangle is touched; its folder under build/demo/ (the last three kept) holds the report, its picture
# and the journal, and build/demo/latest/ is the newest.
demo: build
	build/bin/stencil-sim --fast --pattern raster --until-complete --out-dir build/demo --keep-jobs 3

test-asan: deps
	cmake --preset asan
	cmake --build --preset asan
	ctest --preset asan

test-debug: deps
	cmake --preset debug
	cmake --build --preset debug
	ctest --preset debug

rt: deps
	cmake --preset rt-x86_64
	cmake --build --preset rt-x86_64

# A measurement, not a test: cyclictest, then stencil-sim in real time, each LATENCY_SECONDS (60) on
# CPU 1 with stress-ng on CPU 0 (needs root for SCHED_FIFO).
latency: build
	@bash toolchain/install-deps.sh --latency
	bash toolchain/latency.sh

# A measurement, not a test: one long job with random faults, resumed after each (toolchain/soak.sh).
SOAK_HOURS ?= 8
SOAK_FAULTS ?= 12
SOAK_SEED ?= 1
soak: build
	bash toolchain/soak.sh build/bin/stencil-sim build/soak $(SOAK_HOURS) $(SOAK_FAULTS) $(SOAK_SEED)

# A measurement, not a test: the random operator for STALL_HOURS on STALL_SEEDS seeds, no stall allowed
# (toolchain/stall-seeds.sh).
STALL_SEEDS ?= 20
STALL_HOURS ?= 2
stall-seeds: build
	bash toolchain/stall-seeds.sh build/bin/stencil-sim build/stall-seeds $(STALL_SEEDS) $(STALL_HOURS) 2

soak-asan: deps
	cmake --preset asan
	cmake --build --preset asan --target stencil-sim
	bash toolchain/soak.sh build/asan/bin/stencil-sim build/soak-asan 0.5 4 $(SOAK_SEED)

# The wall's feel (issue 29): the whole table, taps at three speeds and the slides.
wall-test: build
	build/bin/stencil-wall-test --tap-speed 200
	build/bin/stencil-wall-test --tap-speed 1000
	build/bin/stencil-wall-test --tap-speed 2000 --test tap
	build/bin/stencil-wall-test --test speed

# A measurement, not a test: with the wall's feel on and a dynamic hand, the demo's job and the e2e
# job and fault cases must keep their gouge figures (at most 0.005 mm; tests/e2e/sim_cli.sh with
# STENCIL_SIM_FEEL).
FEEL ?= --hand medium --damping 30 --friction 0.5 --speed-limiting penalty
feel-check: build
	build/bin/stencil-sim --fast --pattern raster --until-complete --out-dir build/feel-check --keep-jobs 3 $(FEEL)
	STENCIL_SIM_FEEL="$(FEEL)" ctest --test-dir build -j2 --output-on-failure \
	  -R '^e2e\.sim_(raster_corner|plunge|thinwall|random|reference_job|fault_.*)$$'

# A check .ci/run makes after make test: clang-tidy's readability-function-size over the programs
# (main() at most 150 lines) and the runtime, boards and programs' other files (80 lines a function), with the release configuration's compile_commands.json (toolchain/size-check.sh).
.PHONY: size-check
size-check: deps
	cmake --preset release
	bash toolchain/size-check.sh build

# Each fuzz target runs for FUZZ_SECONDS (two at once, one per core): `make fuzz FUZZ_SECONDS=600` for a long run.
FUZZ_SECONDS ?= 60
fuzz: deps
	cmake --preset fuzz -DSTENCIL_FUZZ_SECONDS=$(FUZZ_SECONDS)
	cmake --build --preset fuzz
	ctest --preset fuzz

# A check for refactors: OLD's stencil-sim (built in a worktree under build/same-behaviour/old) and this
# tree's run make demo's job and sim_cli.sh's cases on the virtual clock; their reports and journals
# must be the same apart from the wall clock (toolchain/same-behaviour.sh).
# A check of the tests, not a test: each row of tests/mutations.tsv breaks one behaviour README names
# with a one-line change to the source, on a copy of the tree; the test named must then fail
# (toolchain/mutation-check.sh; prints the table).
mutation-check: deps
	bash toolchain/mutation-check.sh build/mutation

same-behaviour:
	@test -n "$(OLD)" || { echo "usage: make same-behaviour OLD=<commit>" >&2; exit 2; }
	@$(MAKE) --no-print-directory build
	bash toolchain/same-behaviour.sh $(OLD) build

# The Debian package of the programs, the page, the sample parts and the services (CPack's DEB
# generator; toolchain/cmake/stencil-package.cmake).
package: build
	cmake --build --preset release --target package

# The package in a clean Debian 12 root: installed, used and purged (toolchain/package-check.sh;
# ctest label `package`; needs root and Debian's archive). Not part of make test or CI.
package-check: package
	@bash toolchain/install-deps.sh --fresh-check
	ctest --preset package

# A check, not a test: README's two commands in a clean Debian 12 root made with mmdebstrap, the
# committed HEAD cloned into it (toolchain/fresh-check.sh; needs root). Run it after any change to
# the dependencies, the lock file or install-deps.sh.
fresh-check:
	@bash toolchain/install-deps.sh --fresh-check
	bash toolchain/fresh-check.sh build/fresh-check

clean:
	@# --one-file-system: a fresh-check root killed mid-run may still have the host's /dev, /proc and /sys bound inside it
	rm -rf --one-file-system build
