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
	libcairo2-dev libpng-dev

.PHONY: all deps configure build demo test bench clean format

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

configure: deps
	@if [ ! -f $(BUILD)/build.ninja ]; then \
		cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release; \
	fi

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	@mkdir -p $(DEMO_OUT)
	$(GALE) eval examples/01_breeze/breeze.se --points examples/01_breeze/points.ply \
		--time 0.5 -o $(DEMO_OUT)/breeze.ply
	$(GALE) eval examples/01_breeze/breeze.se --points examples/01_breeze/points.ply \
		--time 0.5 -o $(DEMO_OUT)/breeze.csv
	@echo
	@echo "gale demo: evaluated examples/01_breeze/breeze.se on examples/01_breeze/points.ply"
	@echo "           output: $(DEMO_OUT)/breeze.ply (and $(DEMO_OUT)/breeze.csv)"

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

bench: build
	$(BUILD)/bench/gale_bench_vm

format:
	clang-format -i $$(git ls-files '*.h' '*.cpp')

clean:
	rm -rf $(BUILD)
