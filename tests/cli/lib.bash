# Shared helpers for the CLI test scripts: `source "$(dirname "$0")/lib.bash" "$@"`.
# Sets GALE (the binary), SRC (the source folder) and TMP (a scratch folder removed on exit);
# every failed expectation is reported and makes the script exit 1 at the end.
set -u
GALE=${1:?usage: $0 GALE_BINARY SOURCE_DIR}
SRC=${2:?usage: $0 GALE_BINARY SOURCE_DIR}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/gale_cli_test.XXXXXX")
FAILURES=0
export NO_COLOR=1
trap 'rm -rf "$TMP"' EXIT
cd "$TMP" || exit 1

fail() {
    echo "FAIL: $*" >&2
    FAILURES=$((FAILURES + 1))
}

# run CMD...: runs a command, capturing OUT, ERR and RC.
run() {
    OUT=$("$@" 2>"$TMP/.stderr")
    RC=$?
    ERR=$(cat "$TMP/.stderr")
}

# expect_rc WANT DESCRIPTION: checks RC from the last run.
expect_rc() {
    [ "$RC" = "$1" ] || fail "$2: exit code $RC, wanted $1 (stderr: $ERR)"
}

# expect_eq GOT WANT DESCRIPTION
expect_eq() {
    [ "$1" = "$2" ] || fail "$3: got '$1', wanted '$2'"
}

# expect_match TEXT REGEX DESCRIPTION (grep -E, any line)
expect_match() {
    printf '%s\n' "$1" | grep -Eq -- "$2" || fail "$3: '$1' does not match /$2/"
}

# expect_no_match TEXT REGEX DESCRIPTION
expect_no_match() {
    if printf '%s\n' "$1" | grep -Eq -- "$2"; then fail "$3: '$1' matches /$2/"; fi
}

finish() {
    if [ "$FAILURES" -ne 0 ]; then
        echo "$FAILURES expectation(s) failed" >&2
        exit 1
    fi
    echo "ok"
    exit 0
}

# wait_file FILE [PID]: polls until FILE exists (at most about 15 s), or PID has ended.
wait_file() {
    local i
    for ((i = 0; i < 3000; i++)); do
        [ -e "$1" ] && return 0
        [ -n "${2:-}" ] && ! kill -0 "$2" 2> /dev/null && return 1
        sleep 0.005
    done
    return 1
}

# tiny_scene LAST RES WIND_X: the small scene the wedge, farm and cache tests share: a 0.5 m sheet
# of RES x RES vertices pinned along its top in a swaying breeze, frames 1..LAST, 4 substeps.
tiny_scene() {
    cat <<TOML
[scene]
fps = 24
frames = [1, $1]
substeps = 4

[[field]]
name = "main"
source = "[$3, 0, 2 * sin(6 * \$t)]"

[[cloth]]
name = "c"
grid = { size = [0.5, 0.5], res = [$2, $2], origin = [-0.25, 0.5, 0], axes = "xy" }
density = 0.1
stretch = 500.0
shear = 50.0
lift = 0.3
drag = 1.0
pins = { box = [-1, 0.99, -1, 1, 1.01, 1] }
TOML
}
