# gale — top-level convenience targets. `make demo` and `make test` work on a fresh
# Debian 12 machine as root: they install the Debian packages that are missing first.

BUILD     ?= build
JOBS      ?= $(shell nproc 2>/dev/null || echo 2)
GALE      := $(BUILD)/cli/gale
DEMO_OUT  := $(BUILD)/demo

# Debian packages the build needs (library -dev packages and tools).
DEB_PACKAGES := g++ cmake ninja-build pkg-config make \
	libeigen3-dev libfftw3-dev libgsl-dev libopenvdb-dev libboost-iostreams-dev \
	libtbb-dev catch2 libcli11-dev libtomlplusplus-dev libtinyobjloader-dev \
	libcairo2-dev libpng-dev parallel \
	pybind11-dev python3-dev python3-numpy python3-pytest python3 \
	libcpp-httplib-dev nlohmann-json3-dev nodejs curl

.PHONY: all deps configure build demo test test-asan test-tsan fuzz bench report clean format

all: build

deps:
	@missing=""; for p in $(DEB_PACKAGES); do \
		dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
		echo "gale: installing missing Debian packages:$$missing"; \
		if [ "$$(id -u)" != 0 ]; then echo "gale: run as root (or install them yourself)"; exit 1; fi; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing; \
	fi
	@# npm (for the gale live page's three.js): part of NodeSource's nodejs, Debian's own package otherwise.
	@command -v npm >/dev/null || { [ "$$(id -u)" = 0 ] && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends npm; } || \
		echo "gale: npm is missing: the gale live page will lack three.js (apt-get install npm)"

configure: deps
	@if [ ! -f $(BUILD)/build.ninja ]; then \
		cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release; \
	fi

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	@mkdir -p $(DEMO_OUT)
	$(GALE) sim examples/03_cape/scene.toml -o $(DEMO_OUT)/cape
	$(GALE) viz examples/03_cape/scene.toml --plane z=0 --bounds -2,-1,2,2.5 --time 1 \
		-o $(DEMO_OUT)/cape_wind.png
	$(GALE) eval examples/01_breeze/breeze.se --points examples/01_breeze/points.ply \
		--time 0.5 -o $(DEMO_OUT)/breeze.ply
	@echo
	@echo "gale demo: simulated examples/03_cape (a cape in gusting wind, 48 frames)"
	@echo "           cape frames: $(DEMO_OUT)/cape/cape.0001.obj ... cape.0048.obj"
	@echo "           run stats:   $(DEMO_OUT)/cape/run.json"
	@echo "           wind slice:  $(DEMO_OUT)/cape_wind.png"
	@echo "           breeze wind on a point set: $(DEMO_OUT)/breeze.ply"

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	$(BUILD)/bench/gale_bench_vm

# Speed against error: runs the benchmarks that exist and writes bench/REPORT.md with plots in
# bench/report/ (matplotlib from Debian, installed when missing and root).
# Debian's python3 (where python3-matplotlib installs), not another one first on PATH.
PYTHON    ?= $(shell test -x /usr/bin/python3 && echo /usr/bin/python3 || echo python3)
report: build
	@$(PYTHON) -c 'import matplotlib' 2>/dev/null || { \
		if [ "$$(id -u)" != 0 ]; then echo "gale: report needs python3-matplotlib (run as root or install it)"; exit 1; fi; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends python3-matplotlib; }
	$(PYTHON) bench/report.py --build $(BUILD) --out bench

# --- Hardening (issue 8) --------------------------------------------------------------------
# See docs/sanitizers.md. Reports go to files (log_path), not only stderr: a test that expects a
# failing exit code would otherwise pass when UBSan halts with exit code 1. Any report file
# left after the run fails the target, whatever ctest says.
ASAN_BUILD ?= build-asan
# ccache only when installed (CI machines start without it).
SAN_LAUNCHER := $(if $(shell command -v ccache 2>/dev/null),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# -O1 -g1 (line tables only: reports still name file and line): the sanitizer build compiles
# 3-5x faster than at -O2 -g, which is most of CI's time, and runs the tests about as fast.
SAN_FLAGS  := -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG"
SAN_CMAKE  := -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo $(SAN_FLAGS) -DGALE_BUILD_BENCH=OFF $(SAN_LAUNCHER)
SAN_SUPP   := $(CURDIR)/tests/sanitizers
# san_check DIR: prints every report under DIR and fails when there is one.
san_check = if [ -n "$$(ls -A $(1) 2>/dev/null)" ]; then cat $(1)/*; \
	echo "gale: sanitizer reports above (files in $(1))"; exit 1; fi
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer; any report fails.
# float-cast-overflow is not part of gcc's `undefined`: casts of NaN/inf/huge values to int.
test-asan: deps
	cmake -S . -B $(ASAN_BUILD) $(SAN_CMAKE) -DGALE_SANITIZE=address,undefined,float-cast-overflow
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	@rm -rf $(ASAN_BUILD)/san-reports && mkdir -p $(ASAN_BUILD)/san-reports
	cd $(ASAN_BUILD) && \
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:log_path=$(abspath $(ASAN_BUILD))/san-reports/asan \
	LSAN_OPTIONS=suppressions=$(SAN_SUPP)/lsan.supp:print_suppressions=0 \
	UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1:log_path=$(abspath $(ASAN_BUILD))/san-reports/ubsan \
		ctest --output-on-failure -j $(JOBS) -LE heavy; rc=$$?; \
	$(call san_check,san-reports); exit $$rc

# ThreadSanitizer over the multi-threaded evaluator and solver tests (only those two are built).
# Debian's libtbb is not instrumented, so TSan cannot see its scheduler's synchronisation and
# flags every parallel_for: the tests run against libtbb.so.12 rebuilt from Debian's onetbb
# source with -fsanitize=thread (tests/sanitizers/tbb_tsan.sh; built once per build folder).
TSAN_BUILD ?= build-tsan
test-tsan: deps
	cmake -S . -B $(TSAN_BUILD) $(SAN_CMAKE) -DGALE_SANITIZE=thread
	cmake --build $(TSAN_BUILD) -j $(JOBS) --target runtime_tests solver_tests
	JOBS=$(JOBS) tests/sanitizers/tbb_tsan.sh $(TSAN_BUILD)/onetbb
	@rm -rf $(TSAN_BUILD)/san-reports && mkdir -p $(TSAN_BUILD)/san-reports
	cd $(TSAN_BUILD) && LD_LIBRARY_PATH=$(abspath $(TSAN_BUILD))/onetbb/lib \
	TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1:suppressions=$(SAN_SUPP)/tsan.supp:log_path=$(abspath $(TSAN_BUILD))/san-reports/tsan \
		ctest --output-on-failure -j $(JOBS) -LE heavy -R '^(runtime|solver)_tests:'; rc=$$?; \
	$(call san_check,san-reports); exit $$rc

# libFuzzer harnesses (clang); each runs FUZZ_SECONDS on its seed corpus.
FUZZ_BUILD   ?= build-fuzz
FUZZ_SECONDS ?= 300
FUZZ_DEB_PACKAGES := clang libclang-rt-14-dev llvm
FUZZ_HARNESSES    := fuzz_compile fuzz_eval fuzz_scene fuzz_readers
FUZZ_LAUNCHER     := $(if $(shell command -v ccache 2>/dev/null),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fuzz: deps
	@missing=""; for p in $(FUZZ_DEB_PACKAGES); do \
		dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
		echo "gale: installing missing Debian packages for fuzzing:$$missing"; \
		if [ "$$(id -u)" != 0 ]; then echo "gale: run as root (or install them yourself)"; exit 1; fi; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing; \
	fi
	CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo $(SAN_FLAGS) -DGALE_FUZZ=ON \
		-DGALE_SANITIZE=address,undefined -DGALE_BUILD_TESTS=OFF -DGALE_BUILD_BENCH=OFF $(FUZZ_LAUNCHER)
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target $(FUZZ_HARNESSES)
	fuzz/seed.sh $(FUZZ_BUILD)/corpus
	fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) $(FUZZ_HARNESSES)

format:
	clang-format -i $$(git ls-files '*.h' '*.cpp')

clean:
	rm -rf $(BUILD)
