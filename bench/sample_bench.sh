#!/usr/bin/env bash
# `gale sample` on a 128^3 grid (2,097,152 cells): wall time of the whole command (compile,
# sample on all threads, write) for an analytic field, the breeze example and a scene with
# the wind preset's turbulence and gusts, to .npy, .vdb and .csv. Best of REPEAT runs.
# Usage: bench/sample_bench.sh [GALE_BINARY] [REPEAT]
set -eu
GALE=${1:-build/cli/gale}
REPEAT=${2:-3}
SRC=$(cd "$(dirname "$0")/.." && pwd)
GALE=$(cd "$(dirname "$GALE")" && pwd)/$(basename "$GALE")
TMP=$(mktemp -d "${TMPDIR:-/tmp}/gale_sample_bench.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
cd "$TMP"

cat > gusty.toml <<'TOML'
[scene]
fps = 24

[windicator]
direction = [1, 0, 0.3]
speed = 6.0

[[gust]]
start = 0.5
strength = 5.0

[[field]]
name = "main"
preset = "wind"
params = { turbulence = 0.2, turbulenceScale = 1.5 }
TOML

# best SECONDS of REPEAT runs of a command.
best() {
    local best=""
    for _ in $(seq "$REPEAT"); do
        local t0 t1 dt
        t0=$(date +%s.%N)
        "$@" >/dev/null
        t1=$(date +%s.%N)
        dt=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
        if [ -z "$best" ] || awk -v a="$dt" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$dt; fi
    done
    echo "$best"
}

BOX=-4,-4,-4,4,4,4
printf '%-28s %-6s %10s %12s\n' "field" "format" "seconds" "ns/cell"
run_case() {
    local name=$1 fmt=$2
    shift 2
    local s
    s=$(best "$GALE" sample "$@" --bounds "$BOX" --res 128 -o "out.$fmt")
    printf '%-28s %-6s %10s %12s\n' "$name" "$fmt" "$s" "$(awk -v s="$s" 'BEGIN { printf "%.0f", s * 1e9 / 2097152 }')"
}
for fmt in npy vdb csv; do
    run_case "analytic [x, 2y, -z]" "$fmt" -e '[$P[0], 2*$P[1], -$P[2]]'
done
for fmt in npy vdb; do
    run_case "examples/01_breeze" "$fmt" "$SRC/examples/01_breeze/breeze.se" --time 1
    run_case "scene: wind preset+gust" "$fmt" gusty.toml --time 1
done
echo "threads: $(nproc) hardware; grid 128^3 = 2097152 cells"
