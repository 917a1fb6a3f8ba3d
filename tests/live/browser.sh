#!/bin/bash
# The gale live page in a real headless chromium (Debian's, installed here as root when
# missing), driven by puppeteer-core (tests/live/package-lock.json, installed with npm ci into
# the build tree): browser_test.mjs loads the page and checks what it draws and edits.
# Exit 77 (skipped) where chromium or the npm packages cannot be had.
source "$(dirname "$0")/server.bash" "$@"
HERE=$(cd "$(dirname "$0")" && pwd)

source "$HERE/browser_setup.bash"

start_server "$SCENE_DIR/scene.toml"
mkdir -p "$BUILD/out"
NODE_PATH=$MODULES/node_modules CHROME=$CHROME URL=$URL SCENE_DIR=$SCENE_DIR SHOT=$BUILD/out/live.png \
    node "$HERE/browser_test.mjs"
rc=$?
[ $rc = 0 ] || FAILURES=$((FAILURES + 1))
stop_server
[ "$FAILURES" = 0 ] || exit 1
echo "browser test passed; screenshot: $BUILD/out/live.png"
