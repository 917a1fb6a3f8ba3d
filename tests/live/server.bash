# Shared by the gale live tests: `source server.bash GALE SRC BUILD`. Copies the ice cape example
# into a scratch folder (the tests edit its files), starts `gale live` on it and stops it (by
# pid) on exit. Sets GALE, SRC, BUILD, TMP, SCENE_DIR, URL, TOKEN, PORT, BASE, SERVER_PID and
# SERVER_ERR (the server's stderr).
set -u
GALE=${1:?usage: $0 GALE_BINARY SOURCE_DIR BUILD_DIR}
SRC=${2:?usage: $0 GALE_BINARY SOURCE_DIR BUILD_DIR}
BUILD=${3:?usage: $0 GALE_BINARY SOURCE_DIR BUILD_DIR}
TMP=$(mktemp -d "${TMPDIR:-/tmp}/gale_live_test.XXXXXX")
FAILURES=0
SERVER_PID=
export NO_COLOR=1
stop_server() {
    if [ -n "$SERVER_PID" ] && kill -0 "$SERVER_PID" 2>/dev/null; then
        kill -TERM "$SERVER_PID"
        for _ in $(seq 50); do kill -0 "$SERVER_PID" 2>/dev/null || break; sleep 0.1; done
        kill -0 "$SERVER_PID" 2>/dev/null && { echo "FAIL: the server did not stop on SIGTERM" >&2; kill -KILL "$SERVER_PID"; FAILURES=$((FAILURES + 1)); }
        wait "$SERVER_PID" 2>/dev/null
    fi
    SERVER_PID=
}
trap 'stop_server; rm -rf "$TMP"' EXIT

fail() {
    echo "FAIL: $*" >&2
    FAILURES=$((FAILURES + 1))
}

SCENE_DIR=$TMP/ice
cp -r "$SRC/examples/05_ice_cape" "$SCENE_DIR"
rm -f "$SCENE_DIR"/*.png

# start_server INPUT: starts gale live and waits for its URL line.
SERVERS=0
start_server() {
    # A new stderr file per server: a reused one could still show the last server's URL.
    SERVERS=$((SERVERS + 1))
    SERVER_ERR=$TMP/server$SERVERS.err
    : >"$SERVER_ERR"
    "$GALE" live "$1" --no-open --port 0 2>"$SERVER_ERR" &
    SERVER_PID=$!
    URL=
    for _ in $(seq 200); do
        URL=$(grep -o 'http://127.0.0.1:[0-9]*/?token=[0-9a-f]*' "$SERVER_ERR" 2>/dev/null | head -1)
        [ -n "$URL" ] && break
        kill -0 "$SERVER_PID" 2>/dev/null || break
        sleep 0.05
    done
    if [ -z "$URL" ]; then
        echo "FAIL: gale live printed no URL: $(cat "$SERVER_ERR")" >&2
        exit 1
    fi
    TOKEN=${URL##*token=}
    BASE=${URL%%/?token=*}
    PORT=${BASE##*:}
}
