#!/usr/bin/env bash
# Seeds the libFuzzer corpora: fuzz/seed.sh OUT_DIR fills OUT_DIR/<harness>/ from the language
# specs, the malformed corpus, the examples and the heredocs of the CLI tests (existing files
# are kept, so a corpus grown by earlier runs stays). fuzz_readers seeds get their selector byte.
set -eu
SRC=$(cd "$(dirname "$0")/.." && pwd)
OUT=${1:?usage: fuzz/seed.sh OUT_DIR}
mkdir -p "$OUT"/fuzz_compile "$OUT"/fuzz_eval "$OUT"/fuzz_scene "$OUT"/fuzz_readers

# put HARNESS FILE [PREFIX_BYTE_OCTAL]: a copy named after its content hash (no duplicates).
put() {
    local dir="$OUT/$1" tmp
    tmp=$(mktemp "$OUT/.seed.XXXXXX")
    if [ $# -ge 3 ]; then printf "\\$3" >"$tmp"; fi
    cat "$2" >>"$tmp"
    mv "$tmp" "$dir/$(sha1sum "$tmp" | cut -c1-40)"
}

cd "$SRC"
for f in $(find tests/lang tests/malformed examples fields/presets -name '*.se' | sort); do
    put fuzz_compile "$f"
    put fuzz_eval "$f"
done
for f in tests/malformed/*; do put fuzz_compile "$f"; done
for f in $(find examples -name '*.toml' | sort); do put fuzz_scene "$f"; done
for f in $(find examples tests -name '*.csv' | sort); do put fuzz_readers "$f" 000; put fuzz_readers "$f" 005; done
for f in $(find examples tests -name '*.ply' | sort); do put fuzz_readers "$f" 001; put fuzz_readers "$f" 004; done
for f in $(find examples tests -name '*.obj' | sort); do put fuzz_readers "$f" 002; put fuzz_readers "$f" 003; done

# Heredocs of the CLI tests: scenes (a line opening a [section]) and expressions.
tmpdir=$(mktemp -d)
trap 'rm -rf "$tmpdir"' EXIT
awk -v dir="$tmpdir" '
    /<<-?'"'"'?[A-Z]+'"'"'?[[:space:]]*$/ && !body { body = 1; n++; tag = $0; sub(/.*<<-?'"'"'?/, "", tag); sub(/'"'"'?[[:space:]]*$/, "", tag); next }
    body && $0 == tag { body = 0; next }
    body { print > (dir "/" n) }
' tests/cli/*.sh
for f in "$tmpdir"/*; do
    [ -f "$f" ] || continue
    if grep -Eq '^\[\[?[a-z]' "$f"; then put fuzz_scene "$f"; else put fuzz_compile "$f"; put fuzz_eval "$f"; fi
done

# A few small hand-made files for the readers (ascii and binary PLY with faces, OBJ, CSV).
printf 'x,y,z,strand\n0,0,0,0\n0,-1,0,0\n1,0,0,1\n1,-1,0,1\n' >"$tmpdir/s.csv"
put fuzz_readers "$tmpdir/s.csv" 000; put fuzz_readers "$tmpdir/s.csv" 005
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float lift\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 1\n1 0 0 1\n1 1 0 0.5\n0 1 0 0\n4 0 1 2 3\n' >"$tmpdir/a.ply"
put fuzz_readers "$tmpdir/a.ply" 001; put fuzz_readers "$tmpdir/a.ply" 004
{ printf 'ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n'
  printf '\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\200\77\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\200\77\0\0\0\0\0\0\0\0\3\0\0\0\0\1\0\0\0\2\0\0\0'; } >"$tmpdir/b.ply"
put fuzz_readers "$tmpdir/b.ply" 001; put fuzz_readers "$tmpdir/b.ply" 004
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2 3 4\nf -1 -2 -3\n' >"$tmpdir/q.obj"
put fuzz_readers "$tmpdir/q.obj" 002; put fuzz_readers "$tmpdir/q.obj" 003

# A scene naming the files fuzz_scene keeps beside it (wind.se, lift.se, mesh.obj, strands.csv).
cat >"$tmpdir/local.toml" <<'TOML'
[scene]
fps = 24
frames = [1, 4]
[windicator]
direction = [1, 0, 0]
speed = { keys = [[0, 2], [1, 6]] }
[[gust]]
name = "g"
start = 0.2
strength = 3
[[field]]
name = "main"
expr = "wind.se"
params = { speed = 6 }
scale = 0.5
mask = "smoothstep($P[1], 0, 1)"
[[field]]
source = "[0, 1, 0] * $windSpeed + gust($P)"
[[cloth]]
name = "cape"
mesh = "mesh.obj"
lift = { scale = 0.4, expr = "lift.se" }
drag = 1.1
pins = { vertices = [0, 1] }
[[cloth]]
name = "flag"
grid = { size = [1, 0.5], res = [6, 4] }
[[hair]]
name = "hair"
strands = "strands.csv"
[[collider]]
type = "sphere"
center = [0, -1, 0]
radius = 0.3
[solver]
max_halvings = 4
TOML
put fuzz_scene "$tmpdir/local.toml"

for h in fuzz_compile fuzz_eval fuzz_scene fuzz_readers; do
    echo "gale: seed corpus $h: $(ls "$OUT/$h" | wc -l) files"
done
