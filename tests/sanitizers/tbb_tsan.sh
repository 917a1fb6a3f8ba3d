#!/usr/bin/env bash
# Builds Debian's own oneTBB source with -fsanitize=thread into DIR/lib (libtbb.so.12, same ABI
# as libtbb12), for `make test-tsan`: with the stock uninstrumented libtbb, TSan cannot see the
# scheduler's synchronisation and reports every parallel_for as a race. Usage: tbb_tsan.sh DIR
set -euo pipefail
dir=${1:?usage: $0 DIR}
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
if [ -e "$dir/lib/libtbb.so.12" ]; then exit 0; fi

version=$(dpkg-query -W -f='${source:Version}' libtbb12 2>/dev/null || true)
[ -n "$version" ] || { echo "tbb_tsan.sh: libtbb12 is not installed (run make deps)" >&2; exit 1; }

# The source package, fetched with a private apt configuration (deb-src of the installed
# suites), so the machine's apt sources are left alone. No root needed.
apt="$dir/apt"
mkdir -p "$apt/lists/partial" "$apt/src"
: >"$apt/sources.list"
for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] && sed -n 's/^deb \(.*\)$/deb-src \1/p' "$f" >>"$apt/sources.list"
done
for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] && sed 's/^Types:.*/Types: deb-src/' "$f" >"$apt/$(basename "$f")"
done
opts=(-o Dir::Etc::SourceList="$apt/sources.list" -o Dir::Etc::SourceParts="$apt"
      -o Dir::State::Lists="$apt/lists" -o Dir::Cache::pkgcache="" -o Dir::Cache::srcpkgcache=""
      -o APT::Sandbox::User=root)
apt-get "${opts[@]}" update -qq
(cd "$apt/src" && apt-get "${opts[@]}" source -qq --download-only "onetbb=$version")
tar -xf "$apt"/src/onetbb_*.orig.tar.* -C "$apt/src"
src=$(find "$apt/src" -maxdepth 1 -type d -name 'oneTBB-*' | head -n 1)

launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S "$src" -B "$dir/build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTBB_TEST=OFF \
    -DTBB_EXAMPLES=OFF -DTBB_STRICT=OFF -DTBB_SANITIZE=thread -DCMAKE_CXX_FLAGS=-Wno-tsan \
    "${launcher[@]}" >/dev/null
cmake --build "$dir/build" -j "${JOBS:-2}" --target tbb
mkdir -p "$dir/lib"
cp -P "$(find "$dir/build" -name 'libtbb.so.12*' -type f | head -n 1)" "$dir/lib/libtbb.so.12"
