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
	libcairo2-dev libpng-dev parallel

.PHONY: all deps configure build demo test bench report clean format

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

format:
	clang-format -i $$(git ls-files '*.h' '*.cpp')

clean:
	rm -rf $(BUILD)
