#!/usr/bin/env bash
# Stability of the implicit step (issue 14): substeps, rejected (halved) substeps, Newton
# retries, CG iterations and wall time per frame for the gossamer flag at one substep per frame
# (20 and 40 m/s) and for examples/05_ice_cape, against the same scenes with the retry's work
# done on every substep (newton_iterations = 2) and, as the baseline of the same run, with 8
# fixed substeps (the ice cape: against itself as shipped, and at 16 substeps). Wall times
# include the process start (about 60 ms, about 12% of the instructions of a flag run). Usage: bench/stability_bench.sh [BUILD_DIR]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
GALE=${1:-build}/cli/gale
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
# row LABEL SCENE [--set ...]: runs it and prints one table row (ratios against $BASE_MS).
row() {
    local label=$1 scene=$2
    shift 2
    local start end
    start=$(date +%s%N)
    "$GALE" sim "$scene" -o "$OUT/run" --threads 1 "$@" > /dev/null 2>&1 || echo "  ($label: exit $?)"
    end=$(date +%s%N)
    LAST_US=$(((end - start) / 1000))
    python3 - "$OUT/run/run.json" "$label" "$LAST_US" "${BASE_US:-0}" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); label = sys.argv[2]; us = int(sys.argv[3]); base = int(sys.argv[4])
frames = [f for f in d["frames"] if f["objects"][0]["substeps"] > 0]
t = {k: sum(f["objects"][0][k] for f in frames) for k in
     ["substeps", "rejected_substeps", "newton_retries", "recovered_substeps", "solver_iterations"]}
n = len(frames)
step_ms = 1000 * sum(f["wall_seconds"] for f in frames) / n
ratio = f"{us / base:.2f}" if base else "1.00"
print(f"| {label} | {d['status']} | {t['substeps'] / n:.2f} | {t['rejected_substeps']} | {t['newton_retries']} | "
      f"{t['recovered_substeps']} | {t['solver_iterations'] / n:.0f} | {step_ms:.2f} | {us / 1000 / n:.2f} | {ratio} |")
PY
}
FLAG=bench/scenes/gossamer_flag.toml
echo "| run | status | substeps/frame | rejected | Newton retries | recovered | CG its/frame | step ms/frame | total ms/frame | total vs baseline |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for U in 20 40; do
    BASE_US=0
    wind=(--set "field.wind.source=\$speed = $U; [\$speed * cos(3 * PI / 180), 0, \$speed * sin(3 * PI / 180)]")
    row "flag $U m/s, 8 substeps (baseline)" "$FLAG" "${wind[@]}" --set scene.substeps=8
    BASE_US=$LAST_US
    row "flag $U m/s, 1 substep (default)" "$FLAG" "${wind[@]}"
    row "flag $U m/s, 1 substep, newton_iterations = 2" "$FLAG" "${wind[@]}" --set cloth.flag.newton_iterations=2
done
ICE=examples/05_ice_cape/scene.toml
BASE_US=0
row "05_ice_cape as shipped (8 substeps)" "$ICE"
BASE_US=$LAST_US
row "05_ice_cape, 16 substeps" "$ICE" --set scene.substeps=16
