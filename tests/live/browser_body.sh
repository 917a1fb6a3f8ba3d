#!/bin/bash
# The walking cape (examples/09_walking_cape) in gale live, in headless chromium
# (browser_body.mjs): started before make_body.py has written body/, the page shows the
# missing folder and clears it within 1 s of the files appearing; the moving body is drawn at
# the frame shown (pixels differ inside its screen box between two times), at rest and while
# a simulation plays. Exit 77 (skipped) where chromium or the npm packages cannot be had.
source "$(dirname "$0")/server.bash" "$@"
HERE=$(cd "$(dirname "$0")" && pwd)
source "$HERE/browser_setup.bash"
command -v python3 >/dev/null || { echo "SKIP: python3 is needed (make_body.py)" >&2; exit 77; }

WALK=$TMP/walk
mkdir -p "$WALK"
cp "$SRC/examples/09_walking_cape/"{scene.toml,shelter.se,make_body.py} "$WALK/"
sed -i 's/^frames = \[1, 48\]/frames = [1, 8]/' "$WALK/scene.toml" # a short simulation
start_server "$WALK/scene.toml"
mkdir -p "$BUILD/out"
NODE_PATH=$MODULES/node_modules CHROME=$CHROME URL=$URL WALK=$WALK SHOT=$BUILD/out/live_body.png \
    node "$HERE/browser_body.mjs"
rc=$?
[ $rc = 0 ] || FAILURES=$((FAILURES + 1))
stop_server
[ "$FAILURES" = 0 ] || exit 1
echo "browser body test passed; screenshot: $BUILD/out/live_body.png"
