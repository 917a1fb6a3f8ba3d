# Shared by the gale live browser tests (after server.bash): Debian's chromium (installed here
# as root when missing) and puppeteer-core (package-lock.json, npm ci into the build tree).
# Sets CHROME and MODULES; exits 77 (skipped) where they cannot be had.
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
CHROME=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$CHROME" ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        echo "installing Debian's chromium for the browser test" >&2
        (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium) >&2 || true
        CHROME=$(command -v chromium || true)
    fi
    if [ -z "$CHROME" ]; then
        echo "SKIP: no chromium and it cannot be installed here (apt-get install chromium as root)" >&2
        exit 77
    fi
fi
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
    echo "SKIP: node and npm are needed to drive chromium (apt-get install nodejs npm)" >&2
    exit 77
fi
MODULES=$BUILD/npm
if ! cmp -s "$HERE/package-lock.json" "$MODULES/package-lock.json" || [ ! -d "$MODULES/node_modules/puppeteer-core" ]; then
    mkdir -p "$MODULES"
    cp "$HERE/package.json" "$HERE/package-lock.json" "$MODULES/"
    if ! npm ci --prefix "$MODULES" --no-audit --no-fund --prefer-offline --loglevel=error >&2; then
        rm -f "$MODULES/package-lock.json"
        echo "SKIP: npm ci of puppeteer-core failed (no registry?)" >&2
        exit 77
    fi
fi
if [ ! -f "$BUILD/../../live/web/node_modules/three/build/three.module.js" ]; then
    echo "SKIP: three.js is not installed in the build tree: the build's npm ci step failed (offline?)" >&2
    exit 77
fi

