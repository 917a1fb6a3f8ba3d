#!/bin/bash
# Strain colours and live re-simulation in headless chromium (browser_resim.mjs) on
# tests/live/resim: a stretched sheet drawn in strain colours, run.json's frames on the
# timeline, a slider edit during a simulation restarting it with the new value.
# Exit 77 (skipped) where chromium or the npm packages cannot be had.
source "$(dirname "$0")/server.bash" "$@"
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/browser_setup.bash"
DIR=$TMP/resim
cp -r "$HERE/resim" "$DIR"
start_server "$DIR/scene.toml"
mkdir -p "$BUILD/out"
NODE_PATH=$MODULES/node_modules CHROME=$CHROME URL=$URL GALE=$GALE DIR=$DIR SHOT=$BUILD/out/live_resim.png \
    node "$HERE/browser_resim.mjs"
rc=$?
[ $rc = 0 ] || FAILURES=$((FAILURES + 1))
stop_server
[ "$FAILURES" = 0 ] || exit 1
echo "browser re-simulation test passed; screenshot: $BUILD/out/live_resim.png"
