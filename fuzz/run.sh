#!/usr/bin/env bash
# Runs the libFuzzer harnesses for a bounded time: fuzz/run.sh BUILD_DIR SECONDS [HARNESS...].
# Each harness fuzzes BUILD_DIR/corpus/<harness> (grown in place) for SECONDS, two at a time;
# crash, leak and timeout inputs land in BUILD_DIR/fuzz-artifacts/. Exit 1 if any harness failed.
# FUZZ_SEED=N fixes libFuzzer's random seed (CI does, so a submission's run is reproducible).
set -u
BUILD=${1:?usage: fuzz/run.sh BUILD_DIR SECONDS [HARNESS...]}
SECONDS_EACH=${2:?usage: fuzz/run.sh BUILD_DIR SECONDS [HARNESS...]}
shift 2
HARNESSES=${*:-fuzz_compile fuzz_eval fuzz_scene fuzz_readers}
SRC=$(cd "$(dirname "$0")/.." && pwd)
PARALLEL=${FUZZ_PARALLEL:-2}
ART="$BUILD/fuzz-artifacts"
mkdir -p "$ART"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}

dict_for() {
    case "$1" in
    fuzz_compile | fuzz_eval) echo "-dict=$SRC/fuzz/gale.dict" ;;
    fuzz_scene) echo "-dict=$SRC/fuzz/scene.dict" ;;
    esac
}

run_one() {
    local h=$1
    mkdir -p "$BUILD/corpus/$h"
    # shellcheck disable=SC2046
    "$BUILD/fuzz/$h" "$BUILD/corpus/$h" $(dict_for "$h") -max_total_time="$SECONDS_EACH" \
        ${FUZZ_SEED:+-seed=$FUZZ_SEED} -timeout=10 -rss_limit_mb=2048 -max_len=8192 -print_final_stats=1 \
        -artifact_prefix="$ART/$h-" >"$BUILD/fuzz-$h.log" 2>&1
    echo $? >"$BUILD/fuzz-$h.rc"
}

running=0
for h in $HARNESSES; do
    echo "gale: fuzzing $h for ${SECONDS_EACH}s (log: $BUILD/fuzz-$h.log)"
    run_one "$h" &
    running=$((running + 1))
    if [ "$running" -ge "$PARALLEL" ]; then wait -n; running=$((running - 1)); fi
done
wait

status=0
for h in $HARNESSES; do
    rc=$(cat "$BUILD/fuzz-$h.rc" 2>/dev/null || echo 1)
    runs=$(grep -o "stat::number_of_executed_units: *[0-9]*" "$BUILD/fuzz-$h.log" | tail -1 | grep -o "[0-9]*$" || true)
    echo "gale: $h: exit $rc, ${runs:-?} runs, corpus $(ls "$BUILD/corpus/$h" | wc -l) files"
    if [ "$rc" != 0 ]; then
        status=1
        echo "gale: $h FAILED; the input is in $ART/, the report at the end of $BUILD/fuzz-$h.log:" >&2
        grep -E 'ERROR|SUMMARY|runtime error|fuzz_eval:|Test unit written' "$BUILD/fuzz-$h.log" | head -20 >&2
    fi
done
exit $status
