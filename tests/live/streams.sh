#!/bin/bash
# gale live under many open event streams, on loopback (streams.py): 64 /api/events streams
# open, /api/state's median and worst latency under 50 ms, every stream gets an edit's event,
# and the server frees the streams their clients close. Starts its own server, stops it by pid.
source "$(dirname "$0")/server.bash" "$@"
HERE=$(cd "$(dirname "$0")" && pwd)
command -v python3 >/dev/null || { echo "SKIP: python3 is needed" >&2; exit 77; }
start_server "$SCENE_DIR/scene.toml"
BASE=$BASE TOKEN=$TOKEN SE=$SCENE_DIR/ice_wind.se STREAMS=${STREAMS:-64} REQUESTS=${REQUESTS:-40} LIMIT_MS=${LIMIT_MS:-50} \
    timeout 120 python3 "$HERE/streams.py" || FAILURES=$((FAILURES + 1))
stop_server
[ "$FAILURES" = 0 ] || exit 1
echo "gale live streams: all checks passed"
