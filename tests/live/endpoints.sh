#!/bin/bash
# The gale live JSON API with curl: the token and the Host check on every request, 4xx JSON
# errors for garbage (and the server still up), parameter and ramp literals rewritten in place
# with everything else in the file kept, files outside the scene refused, the SSE events of an
# edit and of a syntax error, the field data's sizes, and the background simulation (its child
# process gone after stop and after the server's shutdown).
source "$(dirname "$0")/server.bash" "$@"
command -v curl >/dev/null || { echo "SKIP: curl is needed (apt-get install curl)" >&2; exit 77; }

SE=$SCENE_DIR/ice_wind.se
TOML=$SCENE_DIR/scene.toml
cp "$SE" "$TMP/se.orig"
cp "$TOML" "$TMP/toml.orig"
start_server "$TOML"

# get PATH [CURL ARGS...]: sets CODE and BODY.
get() {
    local path=$1
    shift
    BODY=$(curl -s -o - -w '\n%{http_code}' "$@" "$BASE$path")
    CODE=${BODY##*$'\n'}
    BODY=${BODY%$'\n'*}
}
tok() { printf '%s' "$1" | grep -q '?' && printf '%s&token=%s' "$1" "$TOKEN" || printf '%s?token=%s' "$1" "$TOKEN"; }
post() { get "$(tok "$1")" -X POST -H 'Content-Type: application/json' --data-binary "$2"; }
json() { printf '%s' "$BODY" | python3 -c "import json,sys; d=json.load(sys.stdin); print(($1))"; }
expect() { [ "$1" = "$2" ] || fail "$3: got '$1', wanted '$2'"; }
is_error_json() { printf '%s' "$BODY" | python3 -c "import json,sys; d=json.load(sys.stdin); assert isinstance(d.get('error'), str) and d['error']" 2>/dev/null || fail "$1: not a JSON {\"error\": ...}: $BODY"; }

# ---- the command line ----
timeout -s TERM 10 "$GALE" live "$TOML" --no-open --port "$PORT" 2>"$TMP/second.err" # (a hang: 124)
rc=$?
expect "$rc" 2 "a second server on the same port"
grep -q "in use" "$TMP/second.err" || fail "the port-in-use message: $(cat "$TMP/second.err")"
"$GALE" live "$TMP/nosuch.toml" --no-open 2>/dev/null
expect "$?" 3 "a missing input"

# ---- the token ----
get /api/state
expect "$CODE" 403 "no token"
is_error_json "no token"
get "/api/state?token=0123456789abcdef0123456789abcdef"
expect "$CODE" 403 "a wrong token"
get "/api/state?token=${TOKEN:0:31}"
expect "$CODE" 403 "a truncated token"
get / 
expect "$CODE" 403 "the page without the token"
get /assets/app.js
expect "$CODE" 403 "an asset without the token"
get /api/state -H "X-Gale-Token: $TOKEN"
expect "$CODE" 200 "the token as X-Gale-Token"
get "$(tok /)"
expect "$CODE" 200 "the page with the token"
printf '%s' "$BODY" | grep -q "three.module.js?token=$TOKEN" || fail "the page's import map carries the token"

# ---- the Host header (DNS rebinding) ----
get "$(tok /api/state)" -H "Host: attacker.example:$PORT"
expect "$CODE" 403 "a foreign Host"
get "$(tok /api/state)" -H "Host: 127.0.0.1:$((PORT + 1))"
expect "$CODE" 403 "another port in Host"
get "$(tok /api/state)" -H "Host: localhost:$PORT"
expect "$CODE" 200 "Host localhost:PORT"

# ---- the state ----
get "$(tok /api/state)"
expect "$CODE" 200 "state"
expect "$(json 'd["ok"]')" True "the scene compiles"
expect "$(json '"|".join(d["files"])')" "$TOML|$SE" "the watched files"
expect "$(json 'len(d["diagnostics"])')" 0 "no diagnostics"
# Each parameter's effective literal, as the files say (line numbers from grep).
scale_line=$(grep -n '^\$turbulenceScale' "$SE" | cut -d: -f1)
params_line=$(grep -n '^params = ' "$TOML" | cut -d: -f1)
expect "$(json '[(p["file"], p["line"], p["value"], p["min"], p["max"]) for p in d["params"] if p["name"] == "turbulenceScale"]')" \
    "[('$SE', $scale_line, 0.5, 0.1, 5.0)]" "turbulenceScale: the .se declaration"
expect "$(json '[(p["file"], p["line"], p["value"], p["min"], p["max"]) for p in d["params"] if p["name"] == "updraft"]')" \
    "[('$TOML', $params_line, 0.15, 0.0, 0.5)]" "updraft: overridden in the scene's params"
expect "$(json 'd["time"]')" 0.0 "time"

# ---- parameter edits in place ----
post /api/param '{"name": "turbulenceScale", "value": 1.25}'
expect "$CODE" 200 "set turbulenceScale"
expect "$(json '[p["value"] for p in d["params"] if p["name"] == "turbulenceScale"]')" "[1.25]" "the reply is the new state"
sed "s/^\$turbulenceScale = 0.5;/\$turbulenceScale = 1.25;/" "$TMP/se.orig" > "$TMP/se.want"
cmp -s "$SE" "$TMP/se.want" || fail "turbulenceScale rewritten in place, the rest byte for byte: $(diff "$TMP/se.want" "$SE")"
post /api/param '{"name": "updraft", "value": 0.3125}'
expect "$CODE" 200 "set updraft"
sed 's/^params = { turbulence = 0.35, updraft = 0.15 }$/params = { turbulence = 0.35, updraft = 0.3125 }/' "$TMP/toml.orig" > "$TMP/toml.want"
cmp -s "$TOML" "$TMP/toml.want" || fail "updraft rewritten in the scene's params: $(diff "$TMP/toml.want" "$TOML")"
ls "$SCENE_DIR" | grep -q tmp && fail "a temporary file was left beside the scene: $(ls "$SCENE_DIR")"

# ---- bad requests: 4xx JSON, and the server stays up ----
for body in 'garbage' '' '[1,2]' '{"name": 5, "value": 1}' '{"name": "updraft"}' '{"name": "updraft", "value": "x"}' \
    '{"name": "updraft", "value": [1, "a"]}' '{"name": "updraft", "value": {"a": 1}}' '{"name": "updraft", "value": 1e999}' \
    '{"name":' '{"name": "updraft", "value": 1}}'; do
    post /api/param "$body"
    case "$CODE" in 4??) ;; *) fail "POST /api/param '$body': HTTP $CODE, wanted 4xx";; esac
    is_error_json "POST /api/param '$body'"
done
post /api/param '{"name": "nosuch", "value": 1}'
expect "$CODE" 422 "an unknown parameter"
printf '%s' "$BODY" | grep -q 'nosuch' || fail "the error names the parameter: $BODY"
post /api/param '{"name": "updraft", "value": [1, 2, 3]}'
expect "$CODE" 422 "a vector for a scalar parameter"
post /api/ramp '{"id": 0, "points": []}'
expect "$CODE" 422 "a ramp id the scene does not have"
head -c 200000 /dev/zero | tr '\0' ' ' > "$TMP/big.json"
get "$(tok /api/param)" -X POST -H 'Content-Type: application/json' --data-binary @"$TMP/big.json"
expect "$CODE" 413 "a 200 kB body"
for q in 'res=abc' 'res=100000' 'axis=3' 't=nan' 'arrows=1.5' 'lines=-1' 'ax=1e999'; do
    get "$(tok "/api/field?$q")"
    expect "$CODE" 400 "GET /api/field?$q"
    is_error_json "GET /api/field?$q"
done
get "$(tok /api/nosuch)"
expect "$CODE" 404 "an unknown endpoint"
is_error_json "an unknown endpoint"
# A request line that is not HTTP, then a header line of 20 kB.
exec 3<>"/dev/tcp/127.0.0.1/$PORT" && { printf 'GARBAGE\r\n\r\n' >&3; timeout 2 cat <&3 >"$TMP/raw1"; exec 3<&-; }
grep -q '^HTTP/1.1 4' "$TMP/raw1" || fail "a garbage request line gets a 4xx: $(head -1 "$TMP/raw1")"
get "$(tok /api/state)" -H "X-Long: $(head -c 20000 /dev/zero | tr '\0' a)"
case "$CODE" in 4??) ;; *) fail "a 20 kB header: HTTP $CODE, wanted 4xx";; esac
get "$(tok /api/state)"
expect "$CODE" 200 "the server is still up after the garbage"

# ---- only the scene's files ----
get "$(tok "/api/file?path=$SE")"
expect "$CODE" 200 "read the expression"
expect "$(json 'd["text"] == open("'"$SE"'").read()')" True "the file's text"
for p in /etc/passwd "$SCENE_DIR/../../etc/passwd" "$SCENE_DIR/README.md" "../../../../etc/passwd" "$SCENE_DIR"; do
    get "$(tok "/api/file?path=$p")"
    expect "$CODE" 403 "reading $p"
    is_error_json "reading $p"
done
get "$(tok /assets/..%2f..%2fCMakeLists.txt)"
case "$CODE" in 4??) ;; *) fail "an asset path with ../: HTTP $CODE";; esac
get "$(tok /assets/server.cpp)"
expect "$CODE" 404 "a file beside the page that is not one of its assets"

# ---- the field's data ----
get "$(tok "/api/field?t=0.5&axis=0&plane=0&res=128&arrows=16&lines=256")"
expect "$CODE" 200 "field"
expect "$(json 'max(d["slice"]["nu"], d["slice"]["nv"]), len(d["slice"]["speed"]) == d["slice"]["nu"] * d["slice"]["nv"]')" "(128, True)" "a 128-sample slice"
expect "$(json 'd["arrows"]["n"], len(d["arrows"]["positions"]), len(d["arrows"]["velocities"])')" "(16, 12288, 12288)" "16^3 arrows"
expect "$(json '0 < len(d["streamlines"]) <= 256 and all(len(l["points"]) == 3 * len(l["speed"]) for l in d["streamlines"])')" True "up to 256 streamlines"
expect "$(json 'd["overlays"]["windicator"]["present"], len(d["overlays"]["gusts"]), d["slice"]["top"] >= d["slice"]["max"] > 0')" "(True, 2, True)" "rigs and legend"
get "$(tok /api/scene)"
expect "$(json '[r["label"] for r in d["rest"]], len(d["rest"][0]["points"]), [c["shape"] for c in d["colliders"]]')" \
    "(['cape'], 1152, ['capsule'])" "the cape's rest mesh (16 x 24 vertices, 3 numbers each) and the capsule"

# ---- colliders at a time ----
get "$(tok "/api/colliders?t=0.5")"
expect "$CODE" 200 "colliders at t = 0.5"
expect "$(json '[(c["name"], c["shape"], c["moving"], "points" in c) for c in d["colliders"]], d["t"]')" \
    "([('body', 'capsule', False, False)], 0.5)" "the ice cape's capsule, not a mesh sequence"
get "$(tok "/api/colliders?t=abc")"
expect "$CODE" 400 "colliders at a time that is not a number"
get "$(tok /api/run)"
expect "$CODE" 404 "no run yet"
is_error_json "no run yet"

# ---- events: an edit, a syntax error, the fix ----
curl -sN "$(printf '%s/api/events?token=%s' "$BASE" "$TOKEN")" > "$TMP/events" &
CURL_PID=$!
sleep 0.3
printf '# a calm wind\n$speed = 2; # 0, 10\n[1, 0, 0] * $speed\n' > "$TMP/new.se"
cp "$TMP/se.orig" "$SE"
for _ in $(seq 100); do grep -q '^event: field' "$TMP/events" && break; sleep 0.05; done
grep -q '^event: field' "$TMP/events" || fail "an edit of the .se gives a field event"
sed 's/dir = norm(getVar("windDir", \[1, 0, 0\]));/dir = norm(getVar("windDir", [1, 0, 0]);/' "$TMP/se.orig" > "$SE"
for _ in $(seq 100); do grep -q '^event: diagnostics' "$TMP/events" && break; sleep 0.05; done
grep -q '^event: diagnostics' "$TMP/events" || fail "a syntax error gives a diagnostics event"
get "$(tok /api/state)"
line=$(grep -n '^dir = norm' "$SE" | cut -d: -f1)
expect "$(json 'd["ok"], [(x["file"], x["line"], x["col"]) for x in d["diagnostics"]][:1]')" "(False, [('$SE', $line, 40)])" "the error at file:line:col"
check_msg=$("$GALE" check "$SE" 2>&1 | head -1)
expect "$(json 'd["diagnostics"][0]["file"] + ":" + str(d["diagnostics"][0]["line"]) + ":" + str(d["diagnostics"][0]["col"]) + ": error: " + d["diagnostics"][0]["message"]')" "$check_msg" "the message gale check prints"
get "$(tok /api/field)"
expect "$CODE" 409 "no field while the input does not compile"
cp "$TMP/se.orig" "$SE"
for _ in $(seq 100); do [ "$(grep -c '^event: field' "$TMP/events")" -ge 2 ] && break; sleep 0.05; done
get "$(tok /api/state)"
expect "$(json 'd["ok"]')" True "fixed again"
kill "$CURL_PID"; wait "$CURL_PID" 2>/dev/null
# A reconnecting EventSource sends Last-Event-ID: the events after it are sent again at once.
first_id=$(grep -m1 '^id: ' "$TMP/events" | cut -d' ' -f2)
timeout 2 curl -sN -H "Last-Event-ID: $first_id" "$(printf '%s/api/events?token=%s' "$BASE" "$TOKEN")" > "$TMP/resumed"
expect "$(grep -c '^id: ' "$TMP/resumed")" "$(($(grep -c '^id: ' "$TMP/events") - 1))" "Last-Event-ID $first_id resumes after it"
get "$(tok /api/state)"
for _ in $(seq 50); do [ "$(json 'd["eventStreams"]')" = 0 ] && break; sleep 0.05; get "$(tok /api/state)"; done
expect "$(json 'd["eventStreams"]')" 0 "the closed streams are freed"

# ---- simulate ----
sed -i 's/^frames = \[1, 72\]/frames = [1, 6]/' "$TOML"
sleep 0.3
post /api/simulate '{"action": "start"}'
expect "$CODE" 200 "start a simulation"
SIM_DIR=$(json 'd["dir"]')
for _ in $(seq 300); do [ -f "$SIM_DIR/cape.0006.obj" ] && break; sleep 0.1; done
get "$(tok "/api/frame?n=6")"
expect "$CODE" 200 "frame 6"
expect "$(json '[o["label"] for o in d["objects"]], len(d["objects"][0]["points"])')" "(['cape'], 1152)" "frame 6's cape"
get "$(tok "/api/frame?n=99")"
expect "$CODE" 404 "a frame not written"
get "$(tok "/api/frame?n=1")"
expect "$(json '[max(abs(x) for x in o["strain"]) for o in d["objects"]], len(d["objects"][0]["strain"]) * 3 == len(d["objects"][0]["points"])')" \
    "([0.0], True)" "frame 1 is the rest shape: no strain, one value per vertex"
for _ in $(seq 50); do get "$(tok /api/run)"; [ "$(json 'd["status"]')" = ok ] && break; sleep 0.1; done
expect "$(json 'd["status"], [f["frame"] for f in d["frames"]], d["overStretch"]')" "('ok', [1, 2, 3, 4, 5, 6], 1.5)" "run.json's frames (over_stretch, the default)"
sed -i 's/^frames = \[1, 6\]/frames = [1, 2000]/' "$TOML"
sleep 0.3
post /api/simulate '{"action": "start"}'
child=$(pgrep -P "$SERVER_PID" | head -1)
[ -n "$child" ] || fail "a long simulation runs"
post /api/simulate '{"action": "stop"}'
expect "$(json 'd["running"]')" False "stopped"
kill -0 "$child" 2>/dev/null && fail "the stopped simulation's process $child is gone"
post /api/simulate '{"action": "start"}'
child=$(pgrep -P "$SERVER_PID" | head -1)
stop_server
[ -n "$child" ] && kill -0 "$child" 2>/dev/null && { fail "the server's shutdown ends its simulation $child"; kill "$child"; }
grep -q 'gale live: stopped' "$SERVER_ERR" || fail "the server stops cleanly on SIGTERM: $(cat "$SERVER_ERR")"
[ -e "$(dirname "$SIM_DIR")" ] && fail "the server's simulation folder $(dirname "$SIM_DIR") is removed when it stops"

# ---- a lone .se with a ramp ----
cat > "$TMP/ramp.se" <<'SE'
# a ramped breeze
$gain = 2;   # 0, 10  integer slider
s = curve($P[0] * 0.25, 0,0,4, 0.5,1,4, 1,0,4);   # keep this comment
[1, 0, 0] * ($gain + 3 * s)
SE
cp "$TMP/ramp.se" "$TMP/ramp.orig"
start_server "$TMP/ramp.se"
get "$(tok /api/state)"
expect "$(json '[(r["function"], r["line"], r["col"], [(p["position"], p["value"], p["interp"]) for p in r["points"]]) for r in d["ramps"]]')" \
    "[('curve', 3, 5, [(0.0, 0.0, 4), (0.5, 1.0, 4), (1.0, 0.0, 4)])]" "the ramp's control points"
expect "$(json '[(p["name"], p["integer"]) for p in d["params"]]')" "[('gain', True)]" "an integer slider"
post /api/ramp '{"id": 0, "points": [{"position": 0, "value": 0.25, "interp": 1}, {"position": 0.75, "value": -1.5, "interp": 2}]}'
expect "$CODE" 200 "set the ramp"
expect "$(sed -n 3p "$TMP/ramp.se")" 's = curve($P[0] * 0.25, 0,0.25,1, 0.75,-1.5,2);   # keep this comment' "the ramp rewritten in place"
expect "$(json '[len(r["points"]) for r in d["ramps"]]')" "[2]" "the new state's ramp"
post /api/ramp '{"id": 0, "points": [{"position": 0, "value": [1, 2, 3], "interp": 1}]}'
expect "$CODE" 422 "a colour value in a curve()"
post /api/ramp '{"id": 0, "points": [{"position": 0, "value": 1, "interp": 9}]}'
expect "$CODE" 422 "an interpolation code 9"
post /api/simulate '{"action": "start"}'
expect "$CODE" 409 "nothing to simulate for a .se"
stop_server

[ "$FAILURES" = 0 ] || { echo "$FAILURES failure(s)" >&2; exit 1; }
echo "gale live endpoints: all checks passed"
