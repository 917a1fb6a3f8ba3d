# Shared checks for tests/cli/self_collision_*.sh (sourced after lib.bash): the independent
# intersection counter (count_intersections.py, numpy) on a run's OBJ frames and gale's own
# report in run.json.
PY=$(test -x /usr/bin/python3 && echo /usr/bin/python3 || echo python3)
"$PY" -c 'import numpy' 2> /dev/null || { echo "SKIP: python3 with numpy is not installed (make deps installs python3-numpy)"; exit 0; }
COUNTER="$SRC/tests/cli/count_intersections.py"

# count_pairs DIR OBJECT: the independent counter over every frame DIR/OBJECT.*.obj; sets PAIRS
# (intersecting triangle pairs summed over the frames, "error" when it could not count) and
# HIT_FRAMES (frames with any).
count_pairs() {
    local summary
    PAIRS=error HIT_FRAMES=error
    summary=$("$PY" "$COUNTER" "$1/$2".*.obj | tail -n 1) || return
    [[ $summary =~ ^frames\ with\ intersections:\ ([0-9]+)\ of\ [0-9]+,\ pairs\ in\ all:\ ([0-9]+)$ ]] || return
    HIT_FRAMES=${BASH_REMATCH[1]} PAIRS=${BASH_REMATCH[2]}
}

# expect_clean DIR OBJECT WHAT: every frame free of intersections by the independent counter,
# gale's self_intersections 0 on every frame, no self-collision pass left anything unresolved
# and no frame failed; frames with halved substeps are printed as a note.
expect_clean() {
    local report
    [ -s "$1/run.json" ] || { fail "$3: no $1/run.json (the run did not finish)"; return; }
    count_pairs "$1" "$2"
    [ "$PAIRS" = 0 ] || fail "$3: $PAIRS intersecting triangle pairs in $HIT_FRAMES frames (count_intersections.py $1/$2.*.obj)"
    report=$("$PY" - "$1/run.json" "$2" <<'PYEOF'
import json, sys
run = json.load(open(sys.argv[1]))
bad = []
halved = rejected = deepest = 0
if run.get('status') != 'ok':
    bad.append('status ' + str(run.get('status')))
for f in run['frames']:
    sc = f.get('self_collision')
    if f['frame'] > run['frames'][0]['frame'] and sc is None:
        bad.append(f"frame {f['frame']}: no self_collision report")
    if sc and sc['unresolved']:
        bad.append(f"frame {f['frame']}: unresolved {sc['unresolved']}")
    for o in f['objects']:
        if o['name'] != sys.argv[2]:
            continue
        if o.get('self_intersections', 0) != 0:
            bad.append(f"frame {f['frame']}: self_intersections {o['self_intersections']}")
        if 'self_intersections' not in o and f['frame'] > run['frames'][0]['frame']:
            bad.append(f"frame {f['frame']}: no self_intersections")
        if o['failed']:
            bad.append(f"frame {f['frame']}: failed")
        rejected += o['rejected_substeps']
        deepest = max(deepest, o['deepest_halving'])
        halved += o['deepest_halving'] > 0
print('; '.join(bad[:5]) + (f' (+{len(bad) - 5} more)' if len(bad) > 5 else ''))
print(f'{halved} {rejected} {deepest}')
PYEOF
    )
    [ -z "$(head -n 1 <<< "$report")" ] || fail "$3: run.json: $(head -n 1 <<< "$report")"
    # Halved substeps are reported, not failed: the World halves an interval where the pass
    # stretched the cloth (a cost, not a wrong result).
    read -r halved rejected deepest <<< "$(tail -n 1 <<< "$report")"
    [ "${halved:-0}" = 0 ] ||
        echo "NOTE: $3: substeps halved in $halved frames ($rejected rejected, deepest halving $deepest)" >&2
}

# expect_dirty DIR OBJECT WHAT: the same scene without self-collision does pass through itself
# (so expect_clean can fail).
expect_dirty() {
    count_pairs "$1" "$2"
    [ "$PAIRS" != error ] && [ "$PAIRS" -gt 0 ] ||
        fail "$3: $PAIRS intersections without self-collision (the scene does not test anything)"
    echo "$3: $PAIRS pairs in $HIT_FRAMES frames without self-collision" >&2
}
