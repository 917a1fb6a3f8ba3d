#!/usr/bin/env bash
# gale against Bullet's soft body on issue 14's gossamer flag (bench/flag_bench.py --only peer):
# installs Debian's libbullet-dev when it is missing (as root; otherwise says how), configures
# BUILD_DIR so that the optional gale_bench_bullet_flag target is found, builds it and gale, and
# runs the comparison (20 and 40 m/s, 3 repeats, about 2 minutes).
#   Usage: bench/peer_bench.sh [BUILD_DIR] [flag_bench.py options, e.g. --repeats 5]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
shift || true
if ! dpkg-query -W -f='${Status}' libbullet-dev 2>/dev/null | grep -q "install ok installed"; then
    if [ "$(id -u)" = 0 ]; then
        DEBIAN_FRONTEND=noninteractive apt-get install -y libbullet-dev >/dev/null
    else
        echo "peer_bench.sh: Debian's libbullet-dev is not installed; run: sudo apt-get install libbullet-dev" >&2
        exit 1
    fi
fi
if [ -f "$BUILD/CMakeCache.txt" ]; then
    cmake -S . -B "$BUILD" >/dev/null 2>&1 || cmake -S . -B "$BUILD"
else
    cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null 2>&1 ||
        cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
cmake --build "$BUILD" --target gale gale_bench_bullet_flag >/dev/null
exec python3 bench/flag_bench.py --build "$BUILD" --only peer "$@"
